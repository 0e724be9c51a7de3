//! Every force of a world, in typed collections so each hot loop is tight,
//! evaluated in a fixed order at each trial state.

use crate::force::{Force, ForceContext, Stage, Targets};
use crate::forces::{
    angle_joint::AngleJoints,
    constant_force::ConstantForces,
    floor_contact::FloorContact,
    fluid::FluidMedium,
    gravity::{start_with_weights, Gravity},
    nbody::NBodyGravity,
    spring::Springs,
    torque_joint::TorqueJoints,
};
use crate::particle::Properties;
use glam::DVec3;

/// The forces of a world. Built-in kinds live in their own collections; user
/// forces ([`Force`] trait objects) are kept in the order they were added.
///
/// The collections whose parameters actuators drive (springs, joints,
/// constant forces) are public; the ones whose particle lists could be made
/// to point outside the world (gravity, fluids, n-body groups, the floor) are
/// read here and changed only through [`World`](crate::World), which checks.
///
/// Order of evaluation: gravity, springs, angle joints, torque joints,
/// constant forces, fluids, n-body gravity, user body forces; then the
/// contact stage (floor, user contact forces), which reads the net force.
#[derive(Clone, Default)]
pub struct Forces {
    pub(crate) gravity: Option<Gravity>,
    /// Damped springs.
    pub springs: Springs,
    /// Angle joints.
    pub angle_joints: AngleJoints,
    /// Torque joints (motors).
    pub torque_joints: TorqueJoints,
    /// Constant forces.
    pub constant_forces: ConstantForces,
    pub(crate) fluids: Vec<FluidMedium>,
    pub(crate) nbody: Vec<NBodyGravity>,
    pub(crate) floor: Option<FloorContact>,
    pub(crate) user_body: Vec<Box<dyn Force>>,
    pub(crate) user_contact: Vec<Box<dyn Force>>,
    /// Keep the per-particle loops (gravity and the floor's contact here, the integrators' updates)
    /// in one piece even in a large world (set by the world; see
    /// `World::one_piece`).
    pub(crate) one_piece: bool,
}

impl Forces {
    /// Uniform gravity, if any.
    pub fn gravity(&self) -> Option<&Gravity> {
        self.gravity.as_ref()
    }

    /// Fluid media (drag and buoyancy), in the order they were added.
    pub fn fluids(&self) -> &[FluidMedium] {
        &self.fluids
    }

    /// Mutual gravitation groups.
    pub fn nbody(&self) -> &[NBodyGravity] {
        &self.nbody
    }

    /// The floor's normal reaction and friction, if there is a floor.
    pub fn floor(&self) -> Option<&FloorContact> {
        self.floor.as_ref()
    }

    /// The world's gravitational acceleration (zero without gravity).
    pub fn g(&self) -> DVec3 {
        self.gravity.as_ref().map_or(DVec3::ZERO, |g| g.g)
    }

    /// The forces added with [`crate::World::add_force`], in the order
    /// they act (body forces, then contact forces).
    pub fn user(&self) -> impl Iterator<Item = &dyn Force> {
        self.user_body
            .iter()
            .chain(&self.user_contact)
            .map(|f| f.as_ref())
    }

    /// Whether evaluating splits work over the current rayon pool's
    /// threads, for a world of `n` particles (user forces aside: what they
    /// do inside is theirs).
    pub(crate) fn on_threads(&self, n: usize) -> bool {
        self.springs.on_threads() || self.nbody.iter().any(|g| g.on_threads(n))
    }

    pub(crate) fn add_user(&mut self, force: Box<dyn Force>) -> usize {
        match force.stage() {
            Stage::Body => self.user_body.push(force),
            Stage::Contact => self.user_contact.push(force),
        }
        self.user_body.len() + self.user_contact.len() - 1
    }

    /// The forces' view of a trial state.
    fn context<'a>(
        &self,
        t: f64,
        dt: f64,
        pos: &'a [DVec3],
        vel: &'a [DVec3],
        particles: &'a Properties,
    ) -> ForceContext<'a> {
        ForceContext {
            t,
            dt,
            pos,
            vel,
            particles,
            gravity: self.g(),
        }
    }

    /// Overwrites `out` with the net force on every particle at the given
    /// trial state.
    #[inline]
    pub fn evaluate(
        &mut self,
        t: f64,
        dt: f64,
        pos: &[DVec3],
        vel: &[DVec3],
        particles: &Properties,
        out: &mut [DVec3],
    ) {
        let ctx = self.context(t, dt, pos, vel, particles);
        // Gravity on every particle starts the accumulator (m g) instead of
        // adding to zeros: one pass over the particles instead of two.
        let mut springs_done = false;
        match &mut self.gravity {
            Some(g) if g.targets == Targets::All && self.springs.on_threads() => {
                self.springs.apply_from(g.g, &particles.mass, &ctx, out);
                springs_done = true;
            }
            Some(g) if g.targets == Targets::All => {
                let (g, mass) = (g.g, &particles.mass);
                crate::parallel::by_pieces(!self.one_piece, [&mut *out], |first, [out]| {
                    start_with_weights(g, &mass[first..], out)
                });
            }
            Some(g) => {
                out.fill(DVec3::ZERO);
                g.apply(&ctx, out);
            }
            None => out.fill(DVec3::ZERO),
        }
        if !self.springs.is_empty() && !springs_done {
            self.springs.apply(&ctx, out);
        }
        if !self.angle_joints.is_empty() {
            self.angle_joints.apply(&ctx, out);
        }
        if !self.torque_joints.is_empty() {
            self.torque_joints.apply(&ctx, out);
        }
        if !self.constant_forces.is_empty() {
            self.constant_forces.apply(&ctx, out);
        }
        for f in &mut self.fluids {
            f.apply(&ctx, out);
        }
        for f in &mut self.nbody {
            f.apply(&ctx, out);
        }
        for f in &mut self.user_body {
            f.apply(&ctx, out);
        }
        if let Some(f) = &self.floor {
            f.apply_split(&ctx, out, !self.one_piece);
        }
        for f in &mut self.user_contact {
            f.apply(&ctx, out);
        }
    }

    /// Whether [`Self::evaluate_then`] may be used for a world of `n`
    /// particles: gravity on every particle or none, springs in blocks, and
    /// no other force (so the springs are the last to add to a particle);
    /// and the springs split over threads, or the per-particle loops not
    /// (so the springs' pieces are the loops' pieces).
    pub(crate) fn can_evaluate_then(&self, n: usize) -> bool {
        self.gravity
            .as_ref()
            .is_none_or(|g| g.targets == Targets::All)
            && self.springs.can_apply_then()
            && self.angle_joints.is_empty()
            && self.torque_joints.is_empty()
            && self.constant_forces.is_empty()
            && self.fluids.is_empty()
            && self.nbody.is_empty()
            && self.user_body.is_empty()
            && self.floor.is_none()
            && self.user_contact.is_empty()
            && (self.springs.on_threads()
                || self.one_piece
                || crate::parallel::piece_len(n).is_none())
    }

    /// [`Self::evaluate`] ([`Self::can_evaluate_then`]), handing on each
    /// run of particles whose net force is complete as soon as it is,
    /// while it is still in the cache (see `Springs::apply_then`):
    /// `then(first, forces, [x, v])` with the same run of `outs`, each
    /// particle once; the answers combined by `combine` (associative and
    /// commutative). The same forces, to the bit, as [`Self::evaluate`].
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn evaluate_then<R: Send>(
        &mut self,
        t: f64,
        dt: f64,
        pos: &[DVec3],
        vel: &[DVec3],
        particles: &Properties,
        out: &mut [DVec3],
        outs: [&mut [DVec3]; 2],
        then: impl Fn(usize, &[DVec3], [&mut [DVec3]; 2]) -> R + Sync,
        combine: impl Fn(R, R) -> R + Sync + Send,
    ) -> Option<R> {
        let ctx = self.context(t, dt, pos, vel, particles);
        let g = self.gravity.as_ref().map(|g| g.g);
        let mass = &particles.mass;
        let start = |r: std::ops::Range<usize>, out: &mut [DVec3]| match g {
            Some(g) => start_with_weights(g, &mass[r], out),
            None => out.fill(DVec3::ZERO),
        };
        self.springs
            .apply_then(&ctx, out, start, outs, then, combine)
    }

    /// Adds the derivatives of every force that gives them at `ctx` to
    /// `jac` (see [`Force::jacobian`]); the others are left to be taken
    /// explicitly.
    pub fn jacobian(&self, ctx: &ForceContext, jac: &mut crate::Jacobian) {
        self.for_each(|f| {
            f.jacobian(ctx, jac);
        });
    }

    /// Calls `visit` with every force, built-in collections first.
    pub fn for_each(&self, mut visit: impl FnMut(&dyn Force)) {
        if let Some(g) = &self.gravity {
            visit(g);
        }
        visit(&self.springs);
        visit(&self.angle_joints);
        visit(&self.torque_joints);
        visit(&self.constant_forces);
        self.fluids.iter().for_each(|f| visit(f));
        self.nbody.iter().for_each(|f| visit(f));
        self.user_body.iter().for_each(|f| visit(f.as_ref()));
        if let Some(f) = &self.floor {
            visit(f);
        }
        self.user_contact.iter().for_each(|f| visit(f.as_ref()));
    }
}
