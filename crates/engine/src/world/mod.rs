//! The world: particles, the forces and events acting on them, a clock, and
//! the step that advances them (thesis §3.1.4, `advance()`).
//!
//! - this file: the value and its API (particles, forces, events, time);
//! - `step.rs`: the step, its events and threads, backtracking;
//! - `diagnostics.rs`: the step limit, energy, momentum.

mod diagnostics;
mod step;

pub use diagnostics::{Energy, StepLimit};
pub use step::MAX_BACKTRACK_DEPTH;
use step::{Checked, Pieces};

use crate::error::ModelError;
use crate::event::{DiscreteEvent, EventState};
use crate::events::floor_collision::FloorCollision;
use crate::force::{Force, Targets};
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
use crate::integrators::{IntegratorKind, Scratch, Solver};
use crate::particle::{ParticleDef, ParticleId, Properties, State};
use glam::DVec3;

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
    /// The ground's shape: the plane y = 0, or a slope, steps or a
    /// heightfield ([`Terrain`](crate::Terrain)).
    pub terrain: crate::Terrain,
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
            terrain: crate::Terrain::Flat,
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
    /// How the events meet the threads.
    pieces: Pieces,
    /// How the last trial's events were checked.
    checked: Checked,
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
            pieces: Pieces::Settle,
            checked: Checked::Whole,
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

    /// Adds the floor, the plane y = 0 or the terrain `def.terrain`: its
    /// collision event and, unless
    /// `def.contact` is false, its normal reaction and friction. A world has
    /// at most one floor; adding another replaces the contact force and adds a
    /// second collision event.
    pub fn add_floor(&mut self, def: FloorDef) -> Result<(), ModelError> {
        self.check_targets(&def.targets)?;
        def.terrain.validate()?;
        let terrain = std::sync::Arc::new(def.terrain);
        let collision = FloorCollision::new(def.envelope, def.rest_speed, def.targets.clone())
            .with_terrain(terrain.clone());
        collision.validate()?;
        if def.contact {
            let contact = FloorContact {
                static_speed: def.static_speed,
                rest_speed: def.rest_speed,
                contact_tolerance: def.contact_tolerance,
                targets: def.targets,
                terrain,
            };
            contact.validate()?;
            self.forces.floor = Some(contact);
        }
        self.add_event(Box::new(collision));
        Ok(())
    }

    /// The floor's shape, if the world has a floor.
    pub fn terrain(&self) -> Option<&crate::Terrain> {
        self.event::<FloorCollision>().map(FloorCollision::terrain)
    }

    /// How far particle `p`'s surface is from the ground (the floor's
    /// terrain; the plane y = 0 without a floor), m: negative when it is
    /// inside it. On a heightfield, more than 8 cells from the surface,
    /// it is the distance to the surface within 8 cells across.
    #[inline]
    pub fn clearance(&self, p: ParticleId) -> f64 {
        // The flat floor's contact force answers without a search (the
        // roobot asks several times a step).
        if let Some(f) = &self.forces.floor {
            if f.terrain.is_flat() {
                return self.position(p).y - self.particles().radius[p.index()];
            }
        }
        self.clearance_searched(p)
    }

    /// Whether particle `p` is within `tolerance` of the ground: exactly
    /// `self.clearance(p) <= tolerance`, but on terrain a particle certainly
    /// farther than that is told so without the search for the nearest
    /// point (the terrain's probe given a reach a billionth above `radius +
    /// tolerance`, and never less than the rounding of `p`'s coordinates).
    /// What the end rules, touch sensors and `feet` ask each step.
    #[inline]
    pub fn touches_ground(&self, p: ParticleId, tolerance: f64) -> bool {
        if let Some(f) = &self.forces.floor {
            if f.terrain.is_flat() {
                return self.position(p).y - self.particles().radius[p.index()] <= tolerance;
            }
        }
        self.touches_searched(p, tolerance)
    }

    /// [`World::touches_ground`] off the flat floor's contact force.
    #[inline(never)]
    fn touches_searched(&self, p: ParticleId, tolerance: f64) -> bool {
        let (x, r) = (self.position(p), self.particles().radius[p.index()]);
        match self.ground() {
            Some(t) if !t.is_flat() => {
                let reach = r + tolerance;
                let margin = 1e-9 * (reach.abs() + 1.0 + x.abs().max_element());
                match t.probe(x, reach + margin) {
                    Some((d, _)) => d - r <= tolerance,
                    None => false,
                }
            }
            _ => x.y - r <= tolerance,
        }
    }

    /// The terrain [`World::clearance`] measures from: the contact force's,
    /// else the collision event's.
    fn ground(&self) -> Option<&crate::Terrain> {
        match &self.forces.floor {
            Some(f) => Some(&*f.terrain),
            None => self.terrain(),
        }
    }

    /// How many particles that move (a positive inverse mass) have a
    /// [`World::clearance`] of at most `tolerance`: the `feet` measure, each
    /// step. One loop over the arrays on a flat floor.
    pub fn count_on_ground(&self, tolerance: f64) -> usize {
        let (pos, props) = (&self.state().pos, self.particles());
        if let Some(f) = &self.forces.floor {
            if f.terrain.is_flat() {
                return pos
                    .iter()
                    .zip(&props.radius)
                    .zip(&props.inv_mass)
                    .filter(|((x, &r), &inv)| inv > 0.0 && x.y - r <= tolerance)
                    .count();
            }
        }
        // (Not flat, or no contact force.)
        self.particle_ids()
            .filter(|&p| props.inv_mass[p.index()] > 0.0 && self.touches_searched(p, tolerance))
            .count()
    }

    /// [`World::clearance`] from the floor's collision event.
    #[inline(never)]
    fn clearance_searched(&self, p: ParticleId) -> f64 {
        let (x, r) = (self.position(p), self.particles().radius[p.index()]);
        match self.ground() {
            Some(t) if !t.is_flat() => t.probe(x, f64::INFINITY).map_or(x.y, |(d, _)| d) - r,
            _ => x.y - r,
        }
    }

    /// Adds sphere–sphere contact among `def.targets` (see
    /// [`SphereContact`](crate::SphereContact)); the pairs joined by a
    /// spring, an angle joint (any two of its three particles) or a torque
    /// joint *now* are excluded, besides `def.excluded`; if the world has a
    /// flat floor now, contacts never push its spheres into it. Returns the
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
        // Only the flat floor holds spheres up against contacts; on terrain
        // the floor's own collision event moves them out.
        if let Some(floor) = self
            .event::<FloorCollision>()
            .filter(|f| f.terrain().is_flat())
        {
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
        let settles = |e: &dyn DiscreteEvent| e.by_pieces().is_some_and(|b| b.settles_pieces());
        self.pieces = if self.events.iter().all(|e| settles(e.as_ref())) {
            Pieces::Settle
        } else {
            Pieces::Check
        };
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
            .find_map(|e| e.as_ref().as_any().downcast_ref::<E>())
    }

    /// The first event of type `E`, mutably, if it gives itself
    /// ([`DiscreteEvent::as_any_mut`]).
    pub(crate) fn event_mut<E: DiscreteEvent + 'static>(&mut self) -> Option<&mut E> {
        self.events
            .iter_mut()
            .find_map(|e| e.as_mut().as_any_mut().downcast_mut::<E>())
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

    /// The clock's rounding carry: steps are added to [`World::time`] by
    /// compensated (Kahan) summation, and this is what the last addition
    /// lost. With the time, what a second implementation of the step (the
    /// GPU's C) needs to keep the same clock.
    pub fn time_carry(&self) -> f64 {
        self.time_carry
    }

    /// Totals since the world was created.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// What happened during the last step.
    pub fn last_step(&self) -> StepReport {
        self.last
    }
}
