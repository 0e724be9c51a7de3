//! Controllers and actors (thesis §2.3.2.4, §4.2.3).
//!
//! A controller is a creature's brain: once per step, before the world
//! advances, it reads its sensors and sets its actuators. An actor is anything
//! in a scene that acts once per step that way: a creature (a body and its
//! controller) or an environment process, such as a bubble column spawning
//! and recycling its bubbles. Scenes call `act` on every actor before every
//! step.

use animats_engine::World;

/// What a creature reports about itself after a step (for viewers, logs and
/// tests): its controller's state and, where it has one, its energy.
#[derive(Clone, Debug, PartialEq)]
pub struct Status {
    /// The creature's name.
    pub name: String,
    /// The controller's current state (e.g. `flight`).
    pub state: &'static str,
    /// Internal energy in [0, 1], for creatures that have one.
    pub energy: Option<f64>,
    /// Phase of a periodic motion, rad in [0, 2π) (the jellyfish's pulse).
    pub phase: Option<f64>,
}

/// Something in a world that acts once per step: a creature's brain, or an
/// environment process.
pub trait Actor: Send {
    /// Decides and acts for the step of length `dt` about to be taken.
    fn act(&mut self, world: &mut World, dt: f64);
    /// A creature's state now; `None` for things that are not creatures.
    fn status(&self) -> Option<Status> {
        None
    }
    /// Whether `act` may ever change the world: `false` for a creature
    /// whose body is driven only by the scene's controllers (a quadruped
    /// with no demo), which the GPU evaluation can then step.
    fn acts(&self) -> bool {
        true
    }
    /// The actor as itself, for code that reads a built-in kind's state
    /// (the GPU's packer reads a jellyfish's); others need not say.
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }
    /// Its own state as it runs (a timer, a brain's state, a random
    /// stream), for a scene's snapshot; `None` for an actor that keeps
    /// none outside the world.
    fn save_state(&self) -> Option<crate::kept::Kept> {
        None
    }
    /// Takes back an [`Actor::save_state`] of this actor (or of one built
    /// the same way); the error says why not.
    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        crate::kept::nothing(kept, "an actor")
    }
}
