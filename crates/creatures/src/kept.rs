//! A brain's or a creature's own state as it runs (an FSM's current state,
//! a network's activations, a timer): what a scene's snapshot keeps beside
//! the world, so that a restored scene steps on to the same bits. Each
//! kind keeps a value of its own type ([`Kept::new`]) and takes it back
//! ([`Kept::get`]); the snapshot never looks inside.

use std::any::Any;
use std::sync::Arc;

/// One brain's or creature's state (see the module).
#[derive(Clone)]
pub struct Kept(Arc<dyn Any + Send + Sync>);

impl Kept {
    /// `state`, kept.
    pub fn new<T: Any + Send + Sync>(state: T) -> Kept {
        Kept(Arc::new(state))
    }

    /// The state kept, if it is a `T`; else an error naming `who` (a
    /// snapshot of another scene).
    pub fn get<T: Any>(&self, who: &str) -> Result<&T, String> {
        self.0.downcast_ref::<T>().ok_or_else(|| {
            format!("{who}: the snapshot holds another kind's state (a snapshot of another scene?)")
        })
    }
}

impl std::fmt::Debug for Kept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Kept(..)")
    }
}

/// [`crate::brain::Brain::load_state`]'s and
/// [`crate::controller::Actor::load_state`]'s answer for a kind that
/// keeps nothing: only nothing is taken back.
pub fn nothing(kept: Option<&Kept>, who: &str) -> Result<(), String> {
    match kept {
        None => Ok(()),
        Some(_) => Err(format!(
            "{who} keeps no state, but the snapshot holds some (a snapshot of another scene?)"
        )),
    }
}

/// The state a kind keeps, required: an error naming `who` when the
/// snapshot holds none or another kind's.
pub fn required<'a, T: Any>(kept: Option<&'a Kept>, who: &str) -> Result<&'a T, String> {
    kept.ok_or_else(|| {
        format!("{who}: the snapshot holds none of its state (a snapshot of another scene?)")
    })?
    .get::<T>(who)
}
