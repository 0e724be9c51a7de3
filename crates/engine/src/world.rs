//! The world: particles, the forces and events acting on them, a clock, and
//! the step that advances them (thesis §3.1.4, `advance()`).

use crate::error::{ModelError, SimError};
use crate::event::{DiscreteEvent, EventContext, EventState, TrialPiece};
use crate::events::floor_collision::FloorCollision;
use crate::force::{Force, ForceContext, Targets};
use crate::force_set::Forces;
use crate::forces::{
    angle_joint::{AngleJointDef, AngleJointId},
    constant_force::ConstantForceId,
    floor_contact::FloorContact,
    fluid::FluidMedium,
    gravity::Gravity,
    nbody::NBodyGravity,
    spring::{SpringDef, SpringId},
    torque_joint::{TorqueJointDef, TorqueJointId},
};
use crate::integrators::{
    flat, integrate_then, Dynamics, IntegratorKind, Scratch, Settled, Solver, Written, SMALL,
};
use crate::particle::{ParticleDef, ParticleId, Properties, State};
use crate::simd::{chosen, Use};
use glam::DVec3;

/// How many times a step may be halved when an event is missed: pieces are
/// never shorter than `dt / 2^10`.
pub const MAX_BACKTRACK_DEPTH: u32 = 10;

/// A large world on many threads checks its events piece by piece when it
/// has at most this many (each event's answers take three bits of a `u128`).
const PIECE_EVENTS: usize = 42;
/// Those bits: some piece occurring, some piece missed, no answer by pieces.
const OCCURRING: u128 = 1;
const MISSED: u128 = 2;
const UNANSWERED: u128 = 4;

/// What happened during one call of [`World::step`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepReport {
    /// Trial steps thrown away because an event was missed.
    pub backtracks: u32,
    /// Pieces the step was finally taken in (1 without backtracking).
    pub pieces: u32,
    /// Pieces accepted with an event still missed because the piece could not
    /// be split further (the event was then handled as if occurring).
    pub unresolved: u32,
    /// Conjugate-gradient iterations of the implicit integrator, over every
    /// trial (0 for the explicit ones).
    pub solver_iterations: u32,
}

impl StepReport {
    /// A step taken whole, with `solver_iterations`.
    fn whole(solver_iterations: u32) -> StepReport {
        StepReport {
            backtracks: 0,
            pieces: 1,
            unresolved: 0,
            solver_iterations,
        }
    }
}

/// Totals since the world was created.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Stats {
    /// Completed steps.
    pub steps: u64,
    /// Trial steps thrown away (see [`StepReport::backtracks`]).
    pub backtracks: u64,
    /// Missed events handled at the finest piece.
    pub unresolved: u64,
}

/// The largest step an explicit integrator can take with a world's springs
/// ([`World::step_limit`]), and where the stiffest mode is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepLimit {
    /// The step, s.
    pub dt: f64,
    /// The bound on the fastest spring mode, rad/s.
    pub omega: f64,
    /// The particle where that bound is reached.
    pub particle: ParticleId,
    /// The stiffest spring at that particle.
    pub spring: SpringId,
}

/// Kinetic and potential energy of a world, J.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Energy {
    /// Σ ½ m v² over the moving particles.
    pub kinetic: f64,
    /// Sum of every conservative force's potential energy.
    pub potential: f64,
}

impl Energy {
    /// Kinetic plus potential.
    pub fn total(&self) -> f64 {
        self.kinetic + self.potential
    }
}

/// Description of a floor (the plane y = 0): its collision event and its
/// contact force, sharing their targets.
#[derive(Clone, Debug, PartialEq)]
pub struct FloorDef {
    /// Penetration beyond which a collision counts as missed, m.
    pub envelope: f64,
    /// Sliding slower than this is held by static friction, m/s.
    pub static_speed: f64,
    /// Impacts slower than this (at the plane) do not bounce, and a sphere on
    /// the plane moving down slower than this can rest, m/s.
    pub rest_speed: f64,
    /// How close to the plane a sphere must be to rest on it, m.
    pub contact_tolerance: f64,
    /// Whether the floor pushes back and rubs (normal reaction and friction).
    /// Without it the floor only collides.
    pub contact: bool,
    /// The particles the floor acts on.
    pub targets: Targets,
}

impl Default for FloorDef {
    fn default() -> Self {
        FloorDef {
            envelope: 0.01,
            static_speed: 0.01,
            rest_speed: 0.05,
            contact_tolerance: 1e-6,
            contact: true,
            targets: Targets::All,
        }
    }
}

/// A world of particles and the forces and events that act on them.
///
/// ```
/// use animats_engine::{World, ParticleDef, SpringDef, IntegratorKind};
/// use glam::DVec3;
///
/// let mut world = World::new();
/// world.set_gravity(DVec3::new(0.0, -9.8, 0.0));
/// let anchor = world.add_particle(ParticleDef::new(1.0).at(DVec3::Y).fixed())?;
/// let bob = world.add_particle(ParticleDef::new(0.5).at(DVec3::new(0.3, 1.0, 0.0)))?;
/// world.add_spring(SpringDef::new(anchor, bob, 50.0, 0.1))?;
/// world.set_integrator(IntegratorKind::Rk4);
/// for _ in 0..1000 {
///     world.step(0.001)?;
/// }
/// assert!(world.position(bob).y < 1.0); // it swung down
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// A world is a plain value: [`Clone`] copies it whole (user forces and
/// events included), and [`snapshot`](World::snapshot) /
/// [`restore`](World::restore) save and reload its state through serde; a
/// copy or a restored world continues bit for bit as the original would.
#[derive(Clone)]
pub struct World {
    pub(crate) state: State,
    next: State,
    pub(crate) particles: Properties,
    pub(crate) forces: Forces,
    events: Vec<Box<dyn DiscreteEvent>>,
    event_states: Vec<EventState>,
    /// The last trial's events were checked piece by piece, and those
    /// occurring can be handled so (see [`DiscreteEvent::check_piece`]).
    handle_by_pieces: bool,
    /// An event could not answer by pieces: this world's events are
    /// checked on one thread (until another event is added).
    unanswered: bool,
    /// Every event settles pieces ([`DiscreteEvent::settles_pieces`]; true
    /// without events).
    settles: bool,
    /// The last trial was settled piece by piece as it was written: its
    /// events are handled and its finiteness known.
    settled: bool,
    integrator: IntegratorKind,
    solver: Solver,
    scratch: Scratch,
    pub(crate) time: f64,
    pub(crate) time_carry: f64,
    pub(crate) stats: Stats,
    last: StepReport,
}

/// Runs `f` on a thread of the global rayon pool, the caller waiting for
/// it: for a loop of steps of a world whose [`World::steps_on_pool`] is
/// true, so that the loop enters the pool once instead of at every step
/// (cloth-128 from a scene file 5–18 % faster, docs/PERFORMANCE.md). The
/// steps give the same bits either way.
pub fn on_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| f())
}

/// [`on_pool`] when `needed` (a loop's [`World::steps_on_pool`]), else `f`
/// right here: the one place every loop of steps makes that choice.
pub fn on_pool_if<R: Send>(needed: bool, f: impl FnOnce() -> R + Send) -> R {
    if needed {
        on_pool(f)
    } else {
        f()
    }
}

impl Default for World {
    fn default() -> Self {
        World::new()
    }
}

impl World {
    /// An empty world: no gravity, no floor, RK4.
    pub fn new() -> Self {
        World {
            state: State::default(),
            next: State::default(),
            particles: Properties::default(),
            forces: Forces::default(),
            events: Vec::new(),
            event_states: Vec::new(),
            handle_by_pieces: false,
            unanswered: false,
            settles: true,
            settled: false,
            integrator: IntegratorKind::default(),
            solver: Solver::default(),
            scratch: Scratch::default(),
            time: 0.0,
            time_carry: 0.0,
            stats: Stats::default(),
            last: StepReport::default(),
        }
    }

    // ----- particles -------------------------------------------------------

    /// Adds a particle; fixed particles have their velocity set to zero.
    pub fn add_particle(&mut self, def: ParticleDef) -> Result<ParticleId, ModelError> {
        def.validate()?;
        if self.len() >= u32::MAX as usize {
            return Err(ModelError::new("particle", "too many particles"));
        }
        self.particles.push(&def);
        self.state.pos.push(def.position);
        self.state
            .vel
            .push(if def.fixed { DVec3::ZERO } else { def.velocity });
        Ok(ParticleId(self.len() as u32 - 1))
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.state.len()
    }

    /// True when the world has no particles.
    pub fn is_empty(&self) -> bool {
        self.state.is_empty()
    }

    /// Handles of every particle, in order.
    pub fn particle_ids(&self) -> impl Iterator<Item = ParticleId> {
        (0..self.len() as u32).map(ParticleId)
    }

    /// Position of `p`, m.
    pub fn position(&self, p: ParticleId) -> DVec3 {
        self.state.pos[p.index()]
    }

    /// Velocity of `p`, m/s.
    pub fn velocity(&self, p: ParticleId) -> DVec3 {
        self.state.vel[p.index()]
    }

    /// An error unless `p` is a particle of this world.
    fn check_id(&self, p: ParticleId) -> Result<usize, ModelError> {
        let i = p.index();
        if i < self.len() {
            Ok(i)
        } else {
            Err(ModelError::new(
                "particle",
                format!(
                    "particle #{i} does not exist in this world ({} particles)",
                    self.len()
                ),
            ))
        }
    }

    /// Moves `p` (a fixed particle too: nails can be moved by hand).
    pub fn set_position(&mut self, p: ParticleId, x: DVec3) -> Result<(), ModelError> {
        let i = self.check_id(p)?;
        crate::particle::finite_vec("position", x)?;
        self.state.pos[i] = x;
        Ok(())
    }

    /// Sets the velocity of `p` (ignored for a fixed particle, which never moves).
    pub fn set_velocity(&mut self, p: ParticleId, v: DVec3) -> Result<(), ModelError> {
        let i = self.check_id(p)?;
        crate::particle::finite_vec("velocity", v)?;
        if !self.particles.fixed[i] {
            self.state.vel[i] = v;
        }
        Ok(())
    }

    /// Changes the mass of `p` (kg, > 0; a fixed particle stays fixed).
    pub fn set_mass(&mut self, p: ParticleId, mass: f64) -> Result<(), ModelError> {
        let i = self.check_id(p)?;
        crate::particle::positive("mass", mass)?;
        self.particles.mass[i] = mass;
        if !self.particles.fixed[i] {
            self.particles.set_inv_mass(i, 1.0 / mass);
        }
        Ok(())
    }

    /// Changes the volume of `p` (m³, >= 0: a point mass has none); its
    /// radius follows (a sphere).
    pub fn set_volume(&mut self, p: ParticleId, volume: f64) -> Result<(), ModelError> {
        let i = self.check_id(p)?;
        crate::particle::non_negative("volume", volume)?;
        self.particles.volume[i] = volume;
        self.particles.radius[i] = crate::particle::sphere_radius(volume);
        Ok(())
    }

    /// The current positions and velocities of every particle.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// Every particle's properties.
    pub fn particles(&self) -> &Properties {
        &self.particles
    }

    fn check_ids(&self, field: &'static str, ids: &[ParticleId]) -> Result<(), ModelError> {
        match ids.iter().find(|id| id.index() >= self.len()) {
            Some(id) => Err(ModelError::new(
                field,
                format!("particle #{} does not exist in this world", id.index()),
            )),
            None => Ok(()),
        }
    }

    fn check_targets(&self, targets: &Targets) -> Result<(), ModelError> {
        match targets.max_index() {
            Some(i) if i >= self.len() => Err(ModelError::new(
                "particles",
                format!("particle #{i} does not exist in this world"),
            )),
            _ => Ok(()),
        }
    }

    // ----- forces ----------------------------------------------------------

    /// Gravity `g` on every particle (replacing any earlier gravity).
    pub fn set_gravity(&mut self, g: DVec3) {
        self.forces.gravity = g.is_finite().then(|| Gravity::new(g));
    }

    /// Sets (or with `None` removes) the world's gravity force.
    pub fn set_gravity_force(&mut self, gravity: Option<Gravity>) -> Result<(), ModelError> {
        if let Some(g) = &gravity {
            crate::particle::finite_vec("gravity", g.g)?;
            self.check_targets(&g.targets)?;
        }
        self.forces.gravity = gravity;
        Ok(())
    }

    /// Adds a damped spring.
    pub fn add_spring(&mut self, def: SpringDef) -> Result<SpringId, ModelError> {
        self.check_ids("a", &[def.a])?;
        self.check_ids("b", &[def.b])?;
        self.forces.springs.add(&def, &self.state.pos)
    }

    /// Adds an angle joint.
    pub fn add_angle_joint(&mut self, def: AngleJointDef) -> Result<AngleJointId, ModelError> {
        self.check_ids("a", &[def.a])?;
        self.check_ids("joint", &[def.joint])?;
        self.check_ids("b", &[def.b])?;
        self.forces.angle_joints.add(&def, &self.state.pos)
    }

    /// Adds a torque joint.
    pub fn add_torque_joint(&mut self, def: TorqueJointDef) -> Result<TorqueJointId, ModelError> {
        self.check_ids("end", &[def.end])?;
        self.check_ids("joint", &[def.joint])?;
        self.forces.torque_joints.add(&def)
    }

    /// Adds a constant force `force` (N) on each of `particles`.
    pub fn add_constant_force(
        &mut self,
        particles: Vec<ParticleId>,
        force: DVec3,
    ) -> Result<ConstantForceId, ModelError> {
        self.check_ids("particles", &particles)?;
        self.forces.constant_forces.add(particles, force)
    }

    /// Adds a fluid medium (drag and buoyancy).
    pub fn add_fluid(&mut self, fluid: FluidMedium) -> Result<usize, ModelError> {
        fluid.validate()?;
        self.check_targets(&fluid.targets)?;
        self.forces.fluids.push(fluid);
        Ok(self.forces.fluids.len() - 1)
    }

    /// Adds linear drag (`−b v`) on its targets; returns its index among
    /// the user forces, where it is kept.
    pub fn add_linear_drag(
        &mut self,
        drag: crate::forces::linear_drag::LinearDrag,
    ) -> Result<usize, ModelError> {
        drag.validate()?;
        self.check_targets(&drag.targets)?;
        Ok(self.forces.add_user(Box::new(drag)))
    }

    /// Adds mutual gravitation among a group of bodies.
    pub fn add_nbody(&mut self, nbody: NBodyGravity) -> Result<usize, ModelError> {
        nbody.validate()?;
        self.check_targets(nbody.targets())?;
        self.forces.nbody.push(nbody);
        Ok(self.forces.nbody.len() - 1)
    }

    /// Changes the current of fluid `index` (as returned by
    /// [`add_fluid`](World::add_fluid)).
    pub fn set_fluid_current(
        &mut self,
        index: usize,
        current: crate::forces::current::Current,
    ) -> Result<(), ModelError> {
        let fluid =
            self.forces.fluids.get_mut(index).ok_or_else(|| {
                ModelError::new("fluid", format!("no fluid #{index} in this world"))
            })?;
        let mut changed = fluid.clone();
        changed.current = current;
        changed.validate()?;
        *fluid = changed;
        Ok(())
    }

    /// Adds the floor, the plane y = 0: its collision event and, unless
    /// `def.contact` is false, its normal reaction and friction. A world has
    /// at most one floor; adding another replaces the contact force and adds a
    /// second collision event.
    pub fn add_floor(&mut self, def: FloorDef) -> Result<(), ModelError> {
        self.check_targets(&def.targets)?;
        let collision = FloorCollision::new(def.envelope, def.rest_speed, def.targets.clone());
        collision.validate()?;
        if def.contact {
            let contact = FloorContact {
                static_speed: def.static_speed,
                rest_speed: def.rest_speed,
                contact_tolerance: def.contact_tolerance,
                targets: def.targets,
            };
            contact.validate()?;
            self.forces.floor = Some(contact);
        }
        self.add_event(Box::new(collision));
        Ok(())
    }

    /// Adds sphere–sphere contact among `def.targets` (see
    /// [`SphereContact`](crate::SphereContact)); the pairs joined by a
    /// spring, an angle joint (any two of its three particles) or a torque
    /// joint *now* are excluded, besides `def.excluded`; if the world has a
    /// floor now, contacts never push its spheres into it. Returns the
    /// event's index.
    pub fn add_sphere_contact(
        &mut self,
        mut def: crate::SphereContactDef,
    ) -> Result<usize, ModelError> {
        self.check_targets(&def.targets)?;
        for &(a, b) in &def.excluded {
            self.check_ids("excluded", &[a, b])?;
        }
        def.excluded.extend(self.joined_pairs());
        let mut contact = crate::SphereContact::new(def)?;
        if let Some(floor) = self.event::<FloorCollision>() {
            contact.on_floor(self.len(), &floor.targets);
        }
        Ok(self.add_event(Box::new(contact)))
    }

    /// Every pair of particles joined by a spring, an angle joint (any two of
    /// its three) or a torque joint.
    pub fn joined_pairs(&self) -> Vec<(ParticleId, ParticleId)> {
        let f = &self.forces;
        let mut pairs: Vec<(ParticleId, ParticleId)> = f.springs.iter().map(|s| s.ends()).collect();
        for j in f.angle_joints.iter() {
            let (a, m, b) = j.particles();
            pairs.extend([(a, m), (m, b), (a, b)]);
        }
        pairs.extend(f.torque_joints.iter().map(|j| j.particles()));
        pairs
    }

    /// Adds a user-defined force; it is evaluated at every trial state, in
    /// its [`Stage`](crate::Stage), after the built-in forces of that stage.
    pub fn add_force(&mut self, force: Box<dyn Force>) -> usize {
        self.forces.add_user(force)
    }

    /// Adds a discrete event, checked after every trial step.
    pub fn add_event(&mut self, event: Box<dyn DiscreteEvent>) -> usize {
        self.events.push(event);
        self.event_states.push(EventState::None);
        self.unanswered = false;
        self.settles = self.events.iter().all(|e| e.settles_pieces());
        self.events.len() - 1
    }

    /// The forces, to read or change their parameters (actuators do this).
    pub fn forces(&self) -> &Forces {
        &self.forces
    }

    /// The forces, mutably.
    pub fn forces_mut(&mut self) -> &mut Forces {
        &mut self.forces
    }

    /// The events, in the order they were added.
    pub fn events(&self) -> &[Box<dyn DiscreteEvent>] {
        &self.events
    }

    /// The first event of type `E`, if any (e.g. the floor's collisions).
    pub fn event<E: DiscreteEvent + 'static>(&self) -> Option<&E> {
        self.events
            .iter()
            .find_map(|e| e.as_any().downcast_ref::<E>())
    }

    /// The first event of type `E`, mutably, if it gives itself
    /// ([`DiscreteEvent::as_any_mut`]).
    pub(crate) fn event_mut<E: DiscreteEvent + 'static>(&mut self) -> Option<&mut E> {
        self.events
            .iter_mut()
            .find_map(|e| e.as_any_mut().and_then(|a| a.downcast_mut::<E>()))
    }

    // ----- stepping --------------------------------------------------------

    /// The integration method used by [`step`](World::step).
    pub fn integrator(&self) -> IntegratorKind {
        self.integrator
    }

    /// Chooses the integration method.
    pub fn set_integrator(&mut self, kind: IntegratorKind) {
        self.integrator = kind;
    }

    /// How the implicit integrator solves its linear system.
    pub fn solver(&self) -> Solver {
        self.solver
    }

    /// Sets the implicit integrator's tolerance and iteration limit
    /// (a tolerance in (0, 1), at least one iteration).
    pub fn set_solver(&mut self, solver: Solver) -> Result<(), ModelError> {
        if !(solver.tolerance > 0.0 && solver.tolerance < 1.0) {
            return Err(ModelError::new(
                "tolerance",
                format!("must be in (0, 1), got {}", solver.tolerance),
            ));
        }
        if solver.max_iterations == 0 {
            return Err(ModelError::new("max_iterations", "must be at least 1"));
        }
        self.solver = solver;
        Ok(())
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Totals since the world was created.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// What happened during the last step.
    pub fn last_step(&self) -> StepReport {
        self.last
    }

    /// Advances the world by `dt` seconds.
    ///
    /// The integrator takes a trial step; every event then inspects it. If one
    /// was missed, the trial is thrown away and the step is retaken in halves
    /// (recursively, down to `dt / 2^MAX_BACKTRACK_DEPTH`); occurring events
    /// are handled. If any particle ends non-finite the world stays at its
    /// last good state (with its time: after a blow-up inside a backtracked
    /// step, the time of the last piece accepted) and an error names the
    /// particle.
    ///
    /// A world that splits its work over threads, stepped from outside a
    /// rayon pool, runs the whole step on the global pool: each split would
    /// otherwise send its pieces there and wait for them (16–53 µs a split
    /// on a 2-core machine, several splits a step), where a pool's own
    /// thread splits in 0–8 µs (the `outside_pool` example of
    /// `animats-bench` measures both).
    pub fn step(&mut self, dt: f64) -> Result<StepReport, SimError> {
        if self.on_threads() && rayon::current_thread_index().is_none() {
            return self.step_in_pool(dt);
        }
        self.step_here(dt)
    }

    /// Whether [`World::step`], called from this thread, sends the step to
    /// the global rayon pool (a world that splits its work, stepped from
    /// outside a pool): then a loop of many steps is faster run whole by
    /// [`on_pool`], which enters the pool once instead of at every step.
    pub fn steps_on_pool(&self) -> bool {
        self.on_threads() && rayon::current_thread_index().is_none()
    }

    /// [`World::step`] on a thread of the global pool.
    #[cold]
    #[inline(never)]
    fn step_in_pool(&mut self, dt: f64) -> Result<StepReport, SimError> {
        rayon::scope(|_| self.step_here(dt))
    }

    /// Whether a step splits some of its work over the current rayon
    /// pool's threads (the per-particle loops of a large world, many
    /// springs, a large n-body group).
    fn on_threads(&self) -> bool {
        (crate::parallel::piece_len(self.len()).is_some() && !self.one_piece())
            || self.forces.on_threads(self.len())
    }

    /// Whether a large world keeps its per-particle loops (the updates,
    /// gravity) in one piece: when one of its events cannot answer by
    /// pieces (sphere contact), it checks and handles every particle on
    /// one thread every step, much more work than those loops, while the
    /// pool's other threads fall asleep, and waking them for the loops
    /// cost more than the loops save (a pile of 10,000 spheres 3 % slower
    /// on two threads than on one). Springs split over threads keep the
    /// loops split with them, in the same pieces. The results are the same
    /// bits either way.
    fn one_piece(&self) -> bool {
        self.unanswered && !self.forces.springs.on_threads()
    }

    /// [`World::step`] on the calling thread.
    #[inline(always)]
    fn step_here(&mut self, dt: f64) -> Result<StepReport, SimError> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(SimError::BadStep(dt));
        }
        let n = self.len();
        self.next.resize(n);
        self.scratch.resize(n);
        let t0 = self.time;
        if n < SMALL && self.events.is_empty() {
            let finite = self.trial_alone(t0, dt);
            self.accept(EventState::None, finite, t0 + dt)?;
            return Ok(self.end_step(dt, StepReport::whole(self.scratch.implicit.iterations)));
        }
        for e in &mut self.events {
            e.begin_step();
        }
        // The whole step first; pieces only after a missed event.
        let (events, finite) = self.trial(t0, dt, dt, false);
        let report = if events == EventState::Missed {
            self.end_settled(false);
            let first = self.scratch.implicit.iterations;
            let mut r = self.backtrack(t0, dt)?;
            r.solver_iterations += first;
            r
        } else {
            self.accept(events, finite, t0 + dt)?;
            StepReport::whole(self.scratch.implicit.iterations)
        };
        Ok(self.end_step(dt, report))
    }

    /// Advances the clock past a step that ended with `report`, and counts it.
    #[inline(always)]
    fn end_step(&mut self, dt: f64, report: StepReport) -> StepReport {
        self.advance_clock(dt);
        self.stats.steps += 1;
        self.stats.backtracks += report.backtracks as u64;
        self.stats.unresolved += report.unresolved as u64;
        self.last = report;
        report
    }

    /// [`World::trial`] for a small world without events: nothing to
    /// check, handle or backtrack, so the trial is integrated with none of
    /// the closures and passes that serve events and pieces (they cost a
    /// third of a five-body step whose force does nothing: the `step_floor`
    /// example of `animats-bench`), then kept or refused by `accept`. The
    /// same bits as the general path. Returns whether the integrator knows
    /// the trial to be finite.
    #[inline(always)]
    fn trial_alone(&mut self, t0: f64, dt: f64) -> bool {
        self.scratch.implicit.iterations = 0;
        self.forces.one_piece = self.one_piece();
        self.handle_by_pieces = false;
        self.settled = false;
        let mut dynamics = Dynamics {
            forces: &mut self.forces,
            particles: &self.particles,
            scratch: &mut self.scratch,
            solver: self.solver,
        };
        let (from, to) = (&self.state, &mut self.next);
        match self.integrator {
            // The commonest, inlined whole.
            IntegratorKind::Symplectic => {
                crate::integrators::symplectic::step_small(&mut dynamics, t0, dt, from, to)
            }
            kind => integrate_then(kind, &mut dynamics, t0, dt, from, to, None).finite(),
        }
    }

    /// Integrates from the current state over `[t, t + h]` (part of a step
    /// of `step`) into the trial buffer and asks every event about the
    /// result; returns the worst state, and whether the integrator knows
    /// the trial to be finite. `finest`: the trial cannot be split further.
    ///
    /// When every event settles pieces (and there is one, or the world is
    /// not tiny), each piece of the trial is checked, handled and scanned
    /// for finiteness by the thread that has just written it, inside the
    /// integrator's last loop (those of symplectic Euler and RK4): no pass
    /// of its own, and on many threads no fork and join of its own.
    #[inline(always)]
    fn trial(&mut self, t: f64, h: f64, step: f64, finest: bool) -> (EventState, bool) {
        self.scratch.implicit.iterations = 0;
        self.forces.one_piece = self.one_piece();
        self.handle_by_pieces = false;
        self.settled = false;
        let mut dynamics = Dynamics {
            forces: &mut self.forces,
            particles: &self.particles,
            scratch: &mut self.scratch,
            solver: self.solver,
        };
        let settle = self.settles && (!self.events.is_empty() || self.state.pos.len() >= SMALL);
        let (events, particles, from) = (&self.events, &self.particles, &self.state);
        let flight_shift = self.integrator.free_flight_shift();
        let finish = |first: usize, pos: &mut [DVec3], vel: &mut [DVec3]| {
            let r = first..first + pos.len();
            let mut piece = TrialPiece {
                t: t + h,
                h,
                step,
                flight_shift,
                finest,
                first,
                pos,
                vel,
                start_pos: &from.pos[r.clone()],
                start_vel: &from.vel[r],
                particles,
            };
            let mut worst = EventState::None;
            for e in events {
                worst = worst.max(e.settle_piece(&mut piece));
            }
            Settled {
                finite: all_finite(piece.pos, piece.vel),
                worst,
            }
        };
        let written = integrate_then(
            self.integrator,
            &mut dynamics,
            t,
            h,
            from,
            &mut self.next,
            settle.then_some(&finish),
        );
        let mut finite = match written {
            Written::Settled(s) => {
                self.settled = true;
                return (s.worst, s.finite);
            }
            Written::Known(finite) => finite,
        };
        let large = crate::parallel::piece_len(self.len()).is_some()
            && self.events.len() <= PIECE_EVENTS
            && !self.unanswered;
        if self.events.is_empty() && !large {
            return (EventState::None, finite);
        }
        let ctx = EventContext {
            t: t + h,
            h,
            step,
            flight_shift: self.integrator.free_flight_shift(),
            pos: &self.next.pos,
            vel: &self.next.vel,
            start_pos: &self.state.pos,
            start_vel: &self.state.vel,
            particles: &self.particles,
        };
        if large {
            let answer;
            (finite, answer) = check_by_pieces(&self.events, &mut self.event_states, &ctx, finite);
            match answer {
                ByPieces::Checked(worst) => {
                    self.handle_by_pieces = true;
                    return (worst, finite);
                }
                ByPieces::Check => {}
                // (Sphere contact, say: asking again would only cost a
                // fork-join every step.)
                ByPieces::Unanswered => self.unanswered = true,
            }
        }
        let mut worst = EventState::None;
        for (e, s) in self.events.iter_mut().zip(&mut self.event_states) {
            *s = e.check(&ctx);
            worst = worst.max(*s);
        }
        (worst, finite)
    }

    /// Handles the events of the trial ending at `t`, checks it is finite and
    /// makes it the current state. `finite`: the integrator knows it wrote
    /// only finite numbers (then the state is read again only if an event
    /// changed it).
    #[inline]
    fn accept(&mut self, worst: EventState, finite: bool, t: f64) -> Result<(), SimError> {
        let mut known = finite;
        if self.settled {
            // Handled, and scanned after handling, piece by piece.
        } else if worst != EventState::None && self.handle_by_pieces {
            known = handle_by_pieces(
                &self.events,
                &self.event_states,
                t,
                &mut self.next,
                &self.particles,
            );
        } else if worst != EventState::None {
            for (e, s) in self.events.iter_mut().zip(&self.event_states) {
                if *s != EventState::None {
                    e.handle(t, &mut self.next.pos, &mut self.next.vel, &self.particles);
                }
            }
            known = false;
        }
        let bad = if known {
            None
        } else {
            first_non_finite(&self.next, &self.particles.fixed)
        };
        self.end_settled(bad.is_none());
        if let Some(i) = bad {
            // The world stays at its last finite state.
            return Err(SimError::NonFinite {
                particle: ParticleId(i as u32),
                time: t,
            });
        }
        std::mem::swap(&mut self.state, &mut self.next);
        Ok(())
    }

    /// Tells the events whether the world keeps the trial they have just
    /// settled by pieces (see [`DiscreteEvent::settled`]); nothing for a
    /// trial checked otherwise.
    #[inline]
    fn end_settled(&mut self, kept: bool) {
        if self.settled {
            for e in &mut self.events {
                e.settled(kept);
            }
        }
    }

    /// Takes the step `[t0, t0 + dt]` in pieces: halve a piece whenever an
    /// event is missed in it, and grow the pieces back once they line up.
    #[cold]
    fn backtrack(&mut self, t0: f64, dt: f64) -> Result<StepReport, SimError> {
        let total = 1u32 << MAX_BACKTRACK_DEPTH;
        let (mut done, mut piece) = (0u32, total / 2);
        let mut report = StepReport {
            backtracks: 1,
            ..StepReport::default()
        };
        while done < total {
            let t = t0 + dt * (done as f64 / total as f64);
            let h = dt * (piece as f64 / total as f64);
            let (mut worst, finite) = self.trial(t, h, dt, piece == 1);
            report.solver_iterations += self.scratch.implicit.iterations;
            if worst == EventState::Missed {
                if piece > 1 {
                    self.end_settled(false);
                    piece /= 2;
                    report.backtracks += 1;
                    continue;
                }
                // Cannot split further: handle it as if occurring.
                report.unresolved += 1;
                worst = EventState::Occurring;
            }
            if let Err(e) = self.accept(worst, finite, t + h) {
                // The pieces already accepted moved the state: move the
                // clock with them, so time and state still agree.
                self.advance_clock(dt * (done as f64 / total as f64));
                self.last = report;
                return Err(e);
            }
            done += piece;
            report.pieces += 1;
            if piece < total && done % (2 * piece) == 0 {
                piece *= 2;
            }
        }
        Ok(report)
    }

    /// Kahan-compensated `time += dt`, so a million steps of 1 ms end at 1000 s.
    fn advance_clock(&mut self, dt: f64) {
        let y = dt - self.time_carry;
        let t = self.time + y;
        self.time_carry = (t - self.time) - y;
        self.time = t;
    }

    /// Sets the simulated time (and forgets the clock's rounding carry).
    pub fn set_time(&mut self, t: f64) {
        self.time = t;
        self.time_carry = 0.0;
    }

    // ----- diagnostics -----------------------------------------------------

    /// The largest step at which `kind` keeps every spring mode of this
    /// world bounded, by a conservative bound: the fastest mode's ω² is at
    /// most `2 Σ k / m` over the springs meeting at one particle
    /// (Gershgorin's theorem on `M⁻¹K`; a nail takes none), so `kind` is
    /// stable while `h ≤` [`IntegratorKind::stable_omega_h`]` / ω`. Exact
    /// for two equal masses on one spring; damping, joints and contact are
    /// not counted. `None` without springs between moving particles, and for
    /// the implicit integrator.
    pub fn step_limit(&self, kind: IntegratorKind) -> Option<StepLimit> {
        if !kind.is_explicit() {
            return None; // springs do not limit an implicit step
        }
        let p = &self.particles;
        let n = self.len();
        let mut load = vec![0.0f64; n];
        let mut stiffest: Vec<Option<(f64, usize)>> = vec![None; n];
        for (k, sp) in self.forces.springs.iter().enumerate() {
            let (a, b) = sp.ends();
            for i in [a.index(), b.index()] {
                load[i] += sp.stiffness;
                if stiffest[i].is_none_or(|(kk, _)| sp.stiffness > kk) {
                    stiffest[i] = Some((sp.stiffness, k));
                }
            }
        }
        let (w2, i) = (0..n)
            .map(|i| (2.0 * load[i] * p.inv_mass[i], i))
            .max_by(|x, y| x.0.total_cmp(&y.0))
            .filter(|w| w.0 > 0.0 && w.0.is_finite())?;
        let (_, k) = stiffest[i]?;
        let omega = w2.sqrt();
        Some(StepLimit {
            dt: kind.stable_omega_h() / omega,
            omega,
            particle: ParticleId(i as u32),
            spring: SpringId(k as u32),
        })
    }

    /// The step [`step_limit`](World::step_limit) allows `kind`, s (`None`
    /// when no spring limits it).
    pub fn recommended_dt(&self, kind: IntegratorKind) -> Option<f64> {
        self.step_limit(kind).map(|l| l.dt)
    }

    /// Kinetic and potential energy of the current state.
    pub fn energy(&self) -> Energy {
        let p = &self.particles;
        let kinetic = (0..self.len())
            .filter(|&i| !p.fixed[i])
            .map(|i| 0.5 * p.mass[i] * self.state.vel[i].length_squared())
            .sum();
        let ctx = ForceContext {
            t: self.time,
            dt: 0.0,
            pos: &self.state.pos,
            vel: &self.state.vel,
            particles: p,
            gravity: self.forces.g(),
        };
        let mut potential = 0.0;
        self.forces
            .for_each(|f| potential += f.potential_energy(&ctx));
        Energy { kinetic, potential }
    }

    /// True when every force is conservative and there are no events, so the
    /// total energy should stay constant (up to integration error).
    pub fn is_conservative(&self) -> bool {
        let mut conservative = self.events.iter().all(|e| e.conserves_energy());
        self.forces
            .for_each(|f| conservative &= f.is_conservative());
        conservative
    }

    /// True when nothing in the world can add mechanical energy (see
    /// [`Force::is_passive`]).
    pub fn is_passive(&self) -> bool {
        let mut passive = self.events.iter().all(|e| e.is_passive());
        self.forces.for_each(|f| passive &= f.is_passive());
        passive
    }

    /// Total linear momentum of the moving particles, kg m/s.
    pub fn momentum(&self) -> DVec3 {
        let p = &self.particles;
        (0..self.len())
            .filter(|&i| !p.fixed[i])
            .map(|i| p.mass[i] * self.state.vel[i])
            .sum()
    }

    /// Centre of mass of every particle, m.
    pub fn centre_of_mass(&self) -> DVec3 {
        let p = &self.particles;
        let m: f64 = p.mass.iter().sum();
        let s: DVec3 = (0..self.len()).map(|i| p.mass[i] * self.state.pos[i]).sum();
        s / m
    }
}

/// A large world on many threads checks its trial piece by piece, each
/// thread the piece it has just written, still in its cache: one thread
/// reading every particle (as `check` and the serial finiteness scan do)
/// would pull half the world across cores, and the other thread would then
/// have to take those lines back to write the next step. Returns whether
/// the trial is finite (`finite`: already known to be) and what the events
/// said.
#[inline(never)]
fn check_by_pieces(
    events: &[Box<dyn DiscreteEvent>],
    states: &mut [EventState],
    ctx: &EventContext,
    finite: bool,
) -> (bool, ByPieces) {
    let (finite, flags) = crate::parallel::map_pieces(
        ctx.pos.len(),
        |r| {
            let mut flags = 0u128;
            for (k, e) in events.iter().enumerate() {
                let code = match e.check_piece(ctx, r.clone()) {
                    Some(EventState::None) => 0,
                    Some(EventState::Occurring) => OCCURRING,
                    Some(EventState::Missed) => MISSED,
                    None => UNANSWERED,
                };
                flags |= code << (3 * k);
            }
            (
                finite || all_finite(&ctx.pos[r.clone()], &ctx.vel[r]),
                flags,
            )
        },
        |a, b| (a.0 & b.0, a.1 | b.1),
    );
    if (0..events.len()).any(|k| flags >> (3 * k) & UNANSWERED != 0) {
        return (finite, ByPieces::Unanswered);
    }
    let (mut worst, mut by_pieces) = (EventState::None, true);
    for (k, (e, s)) in events.iter().zip(states.iter_mut()).enumerate() {
        let f = flags >> (3 * k);
        *s = if f & MISSED != 0 {
            EventState::Missed
        } else if f & OCCURRING != 0 {
            EventState::Occurring
        } else {
            EventState::None
        };
        worst = worst.max(*s);
        by_pieces &= *s == EventState::None || e.handles_pieces();
    }
    // An event handled on one thread needs the records of its `check`.
    if worst == EventState::None || by_pieces {
        (finite, ByPieces::Checked(worst))
    } else {
        (finite, ByPieces::Check)
    }
}

/// What [`check_by_pieces`] found.
enum ByPieces {
    /// Every event answered, and those occurring can be handled by pieces:
    /// the worst state (each event's is set).
    Checked(EventState),
    /// Every event answered, but one occurring must be checked and handled
    /// on one thread.
    Check,
    /// Some event cannot answer by pieces.
    Unanswered,
}

/// Handles the events of a trial that [`check_by_pieces`] found occurring,
/// each thread the piece it checked, and looks at it again: true if it is
/// then finite.
#[inline(never)]
fn handle_by_pieces(
    events: &[Box<dyn DiscreteEvent>],
    states: &[EventState],
    t: f64,
    next: &mut State,
    particles: &Properties,
) -> bool {
    crate::parallel::all_by_pieces(true, [&mut next.pos, &mut next.vel], |first, [pos, vel]| {
        for (e, s) in events.iter().zip(states) {
            if *s != EventState::None {
                e.handle_piece(t, first, pos, vel, particles);
            }
        }
        all_finite(pos, vel)
    })
}

/// The index of the first particle with a non-finite position or velocity,
/// preferring a moving one: a nail next to an overflowing spring goes NaN
/// only because 0 × ∞ is NaN, and is not the one to blame.
fn first_non_finite(s: &State, fixed: &[bool]) -> Option<usize> {
    let n = s.pos.len().min(s.vel.len());
    let (pos, vel) = (&s.pos[..n], &s.vel[..n]);
    if all_finite(pos, vel) {
        return None;
    }
    let bad = |i: &usize| !(pos[*i].is_finite() && vel[*i].is_finite());
    (0..n)
        .filter(|&i| !fixed[i])
        .find(bad)
        .or_else(|| (0..n).find(bad))
}

/// True if every coordinate of `pos` and `vel` (as long as each other) is
/// finite.
fn all_finite(pos: &[DVec3], vel: &[DVec3]) -> bool {
    let n = pos.len().min(vel.len());
    let (pos, vel) = (&pos[..n], &vel[..n]);
    // A sum of finite numbers is finite (unless it overflows, which the
    // confirming scan at the end tells apart) and any inf or NaN makes it
    // non-finite. Sixteen independent lanes over the flat coordinates, in
    // the vectors chosen for updates (`simd.rs`), keep the pass short next
    // to the force loops.
    let (p, v) = (flat(pos), flat(vel));
    let sums_finite = chosen(
        Use::Updates,
        #[inline(always)]
        || {
            const LANES: usize = 16;
            let mut acc = [0.0f64; LANES];
            let (pc, vc) = (p.chunks_exact(LANES), v.chunks_exact(LANES));
            let (pr, vr) = (pc.remainder(), vc.remainder());
            for (p, v) in pc.zip(vc) {
                for k in 0..LANES {
                    acc[k] += p[k] + v[k];
                }
            }
            for (a, (p, v)) in acc.iter_mut().zip(pr.iter().zip(vr)) {
                *a += p + v;
            }
            acc.iter().all(|a| a.is_finite())
        },
    );
    if sums_finite {
        return true;
    }
    // A sum may overflow with every term finite: look at each.
    pos.iter()
        .zip(vel)
        .all(|(p, v)| p.is_finite() && v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::{all_finite, first_non_finite};
    use crate::particle::State;
    use glam::DVec3;

    /// The wide scan finds one bad coordinate wherever it is (inside the
    /// vectors or in the remainder), and is not fooled by finite numbers
    /// whose sum overflows.
    #[test]
    fn the_finiteness_scan_finds_every_bad_coordinate() {
        for n in [1, 5, 16, 37] {
            let pos: Vec<DVec3> = (0..n).map(|i| DVec3::splat(i as f64 - 3.5)).collect();
            let vel: Vec<DVec3> = (0..n).map(|i| DVec3::splat(0.25 * i as f64)).collect();
            assert!(all_finite(&pos, &vel));
            let huge = vec![DVec3::splat(f64::MAX); n];
            assert!(
                all_finite(&huge, &huge),
                "{n}: finite, though the sums overflow"
            );
            for i in 0..n {
                for k in 0..3 {
                    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                        for in_pos in [true, false] {
                            let (mut p, mut v) = (pos.clone(), vel.clone());
                            let x = if in_pos { &mut p[i] } else { &mut v[i] };
                            x[k] = bad;
                            assert!(!all_finite(&p, &v), "{n} particles, {i}.{k} = {bad}");
                            let s = State { pos: p, vel: v };
                            assert_eq!(first_non_finite(&s, &vec![false; n]), Some(i));
                        }
                    }
                }
            }
        }
    }
}
