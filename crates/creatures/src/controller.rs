//! Controllers and creatures (thesis §2.3.2.4, §4.2.3).
//!
//! A controller is the creature's brain: once per step, before the world
//! advances, it reads its sensors and sets its actuators. A creature is a body
//! built into a world plus its controller; scenes hold creatures and call
//! `control` on each before every step.

use animats_engine::World;

/// Reads sensors and sets actuators once per step.
pub trait Controller {
    /// Decides and acts for the step of length `dt` about to be taken.
    fn control(&mut self, world: &mut World, dt: f64);
}

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
}

/// A body in a world with a brain.
pub trait Creature: Send {
    /// Decides and acts for the next step (see [`Controller::control`]).
    fn control(&mut self, world: &mut World, dt: f64);
    /// Its state now.
    fn status(&self) -> Status;
}
