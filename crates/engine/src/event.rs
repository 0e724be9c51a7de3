//! The `DiscreteEvent` interface (thesis §3.1.3): very short-lived events
//! (collisions) that integration with a finite step cannot resolve.
//!
//! After each trial step the world asks every event for its state:
//! - [`EventState::None`]: nothing happened;
//! - [`EventState::Occurring`]: it is happening now and can be handled
//!   ([`DiscreteEvent::handle`] then changes the state);
//! - [`EventState::Missed`]: it happened somewhere inside the step, too long
//!   ago to handle: the world throws the trial away and retakes the step in
//!   shorter pieces.
//!
//! New events plug in with [`World::add_event`](crate::World::add_event); no
//! integrator knows about any particular event.

use crate::particle::Properties;
use glam::DVec3;

/// What an event reports about a trial step. Ordered by severity.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum EventState {
    /// No event during the step.
    #[default]
    None,
    /// An event is occurring now and can be handled.
    Occurring,
    /// An event occurred inside the step: backtrack.
    Missed,
}

/// The trial state an event inspects, and the state it started from.
#[derive(Clone, Copy)]
pub struct EventContext<'a> {
    /// Simulated time at the end of the trial step, s.
    pub t: f64,
    /// Length of the trial (a whole step, or a piece of one after a
    /// backtrack), s.
    pub h: f64,
    /// The length of the whole step the trial belongs to, s: the time
    /// resolution of the simulation, which a piece is not.
    pub step: f64,
    /// The integrator's [`free_flight_shift`](crate::IntegratorKind::free_flight_shift).
    pub flight_shift: f64,
    /// Positions at the end of the trial step.
    pub pos: &'a [DVec3],
    /// Velocities at the end of the trial step.
    pub vel: &'a [DVec3],
    /// Positions at the start of the trial step.
    pub start_pos: &'a [DVec3],
    /// Velocities at the start of the trial step.
    pub start_vel: &'a [DVec3],
    /// The particles' properties.
    pub particles: &'a Properties,
}

/// A discrete event: detected after a trial step, handled by changing the state.
/// Events are `Clone` (derive it), so that a world can be cloned whole.
pub trait DiscreteEvent: Send + CloneEvent {
    /// Inspects the trial state. May remember what it found for `handle`.
    fn check(&mut self, ctx: &EventContext) -> EventState;

    /// Handles the event found by the last `check` (called only after
    /// `Occurring`, or after `Missed` once the step cannot be split further).
    fn handle(&mut self, t: f64, pos: &mut [DVec3], vel: &mut [DVec3], particles: &Properties);

    /// Called once at the start of each step, before any trial; events that
    /// record what happened during a step clear their records here.
    fn begin_step(&mut self) {}

    /// True if handling the event never changes the total energy.
    fn conserves_energy(&self) -> bool {
        false
    }

    /// True if handling the event never adds energy (the floor's impacts).
    fn is_passive(&self) -> bool {
        self.conserves_energy()
    }

    /// A short name for summaries.
    fn name(&self) -> &str {
        "event"
    }

    /// Lets a caller that knows the concrete type read its records back
    /// (e.g. the floor's collisions of the last step).
    fn as_any(&self) -> &dyn std::any::Any;
}

/// Clones a boxed event; implemented for every `DiscreteEvent + Clone`.
pub trait CloneEvent {
    /// A boxed copy.
    fn clone_box(&self) -> Box<dyn DiscreteEvent>;
}

impl<T: DiscreteEvent + Clone + 'static> CloneEvent for T {
    fn clone_box(&self) -> Box<dyn DiscreteEvent> {
        Box::new(self.clone())
    }
}

impl Clone for Box<dyn DiscreteEvent> {
    fn clone(&self) -> Self {
        self.as_ref().clone_box()
    }
}
