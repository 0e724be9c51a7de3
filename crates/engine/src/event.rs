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
use std::ops::Range;

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
    /// The world's gravity, m/s² (zero without gravity).
    pub gravity: DVec3,
}

/// A piece of a trial step, the particles `first..first + pos.len()`, as
/// the thread that has just integrated it holds it: the end of the trial,
/// to change in place, and the start of the step, to read (see
/// [`DiscreteEvent::settle_piece`]). Every slice but `particles` holds this
/// piece's particles alone: particle `first + k` is `pos[k]`, and
/// `particles`' arrays are indexed by `first + k`.
pub struct TrialPiece<'a> {
    /// Simulated time at the end of the trial step, s.
    pub t: f64,
    /// Length of the trial, s (see [`EventContext::h`]).
    pub h: f64,
    /// The length of the whole step the trial belongs to, s.
    pub step: f64,
    /// The integrator's [`free_flight_shift`](crate::IntegratorKind::free_flight_shift).
    pub flight_shift: f64,
    /// True when the trial cannot be split further: a missed event is then
    /// handled as if it were occurring.
    pub finest: bool,
    /// Index of the piece's first particle.
    pub first: usize,
    /// Positions at the end of the trial step.
    pub pos: &'a mut [DVec3],
    /// Velocities at the end of the trial step.
    pub vel: &'a mut [DVec3],
    /// Positions at the start of the trial step.
    pub start_pos: &'a [DVec3],
    /// Velocities at the start of the trial step.
    pub start_vel: &'a [DVec3],
    /// The whole world's particle properties.
    pub particles: &'a Properties,
    /// The world's gravity, m/s² (zero without gravity).
    pub gravity: DVec3,
}

/// A discrete event: detected after a trial step, handled by changing the
/// state. An event implements [`check`](Self::check) and
/// [`handle`](Self::handle) (and derives `Clone`, so that a world can be
/// cloned whole); the rest has defaults. An event that concerns each
/// particle on its own (a floor, a wall) may also let a large world check
/// and handle it piece by piece on many threads: see [`ByPieces`].
pub trait DiscreteEvent: Send + Sync + CloneEvent + AsAny {
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

    /// The hooks that let a large world check and handle this event piece
    /// by piece; `None`, the default, for events that look at pairs or
    /// must keep records in `check`.
    fn by_pieces(&self) -> Option<&dyn ByPieces> {
        None
    }

    /// [`by_pieces`](Self::by_pieces), mutably (for [`ByPieces::settled`]).
    fn by_pieces_mut(&mut self) -> Option<&mut dyn ByPieces> {
        None
    }
}

/// How an event that concerns each particle on its own is checked and
/// handled by the threads of a large world, each on the piece of particles
/// it has just integrated, still in its cache (one thread reading every
/// particle would pull half the world across cores). Every hook has a
/// default that declines, so an event implements the ones it can.
pub trait ByPieces: Send + Sync {
    /// [`check`](DiscreteEvent::check) for the particles `range` alone,
    /// without keeping records; `None`, the default, if it cannot. The
    /// event's state is then the worst of its pieces', and `check` is not
    /// called. An answer must be the state `check` would give if these were
    /// the only particles.
    fn check_piece(&self, _ctx: &EventContext, _range: Range<usize>) -> Option<EventState> {
        None
    }

    /// True if [`handle_piece`](Self::handle_piece) can stand in for
    /// [`handle`](DiscreteEvent::handle) (after `check_piece`); false, the
    /// default, makes a world that found this event occurring call `check`
    /// and `handle` on one thread.
    fn handles_pieces(&self) -> bool {
        false
    }

    /// `handle` for the particles `first..first + pos.len()` alone (`pos`
    /// and `vel` are theirs; `particles` is the whole world's). Called for
    /// every piece of a trial in which some piece was `Occurring` (or
    /// `Missed`, once the step cannot be split further), so it must leave a
    /// piece in which nothing happened as it is.
    fn handle_piece(
        &self,
        _t: f64,
        _first: usize,
        _pos: &mut [DVec3],
        _vel: &mut [DVec3],
        _particles: &Properties,
    ) {
    }

    /// True if [`settle_piece`](Self::settle_piece) stands in for `check`
    /// and `handle` altogether: then, with the integrators that write a
    /// trial by pieces (symplectic Euler, RK4), the thread that has just
    /// written a piece of the trial checks and handles it at once, and a
    /// large world on many threads needs no pass of its own for this event
    /// (cloth-128 on two threads: docs/PERFORMANCE.md). A world uses it
    /// only when every one of its events settles pieces. False, the default.
    fn settles_pieces(&self) -> bool {
        false
    }

    /// Checks one piece of a trial as `check` would if these were the only
    /// particles, handles it in place as `handle` would if the piece is
    /// `Occurring` (or `Missed` while `piece.finest`), and returns the state
    /// it found. A piece in which nothing happens must be left as it is; a
    /// missed piece of a trial that is not the finest may be left or
    /// handled (the world throws that trial away). The events of a world
    /// settle each piece in the order they were added, each seeing the
    /// piece as the ones before left it. Called from many threads at once:
    /// records of what it did must wait behind a lock until
    /// [`settled`](Self::settled) says whether the world keeps the trial.
    fn settle_piece(&self, _piece: &mut TrialPiece) -> EventState {
        EventState::None
    }

    /// Called on one thread after every trial whose pieces were settled:
    /// `kept` when the world keeps the trial, false when it throws it away
    /// (an event missed in some piece, or a blow-up). An event that keeps
    /// records of what it settled gathers them here, or drops them (the
    /// floor's bounces). Nothing, the default.
    fn settled(&mut self, _kept: bool) {}
}

/// Lets a caller that knows an event's concrete type read it back (the
/// floor's collisions of the last step: [`World::event`](crate::World::event)),
/// or restore it from a snapshot; implemented for every event.
pub trait AsAny {
    /// The event as [`std::any::Any`].
    fn as_any(&self) -> &dyn std::any::Any;
    /// The event as [`std::any::Any`], mutably.
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any;
}

impl<T: DiscreteEvent + 'static> AsAny for T {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
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
