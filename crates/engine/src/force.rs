//! The `Force` interface (thesis §3.1.2): anything that adds to the particles'
//! force accumulators, given the time and the step.
//!
//! Built-in forces implement this trait too, so one file of `forces/` is the
//! pattern to copy when you write your own. A user force is added with
//! [`World::add_force`](crate::World::add_force) and evaluated at every trial
//! state of the integrator, exactly like the built-in ones.

use crate::jacobian::Jacobian;
use crate::particle::{ParticleId, Properties};
use glam::DVec3;

/// What a force sees when it is applied: the trial state it must evaluate, the
/// particles' properties, and the clock.
#[derive(Clone, Copy)]
pub struct ForceContext<'a> {
    /// Simulated time of this trial state, s.
    pub t: f64,
    /// The step being taken, s. Only forces that must not overshoot within one
    /// step (friction) use it.
    pub dt: f64,
    /// Positions of the trial state.
    pub pos: &'a [DVec3],
    /// Velocities of the trial state.
    pub vel: &'a [DVec3],
    /// Masses, radii, friction coefficients...
    pub particles: &'a Properties,
    /// The world's gravitational acceleration (zero when it has none); forces
    /// such as buoyancy need it.
    pub gravity: DVec3,
}

/// When a force is applied relative to the others.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Stage {
    /// Ordinary forces: they do not look at the accumulator.
    #[default]
    Body,
    /// Reaction forces that read the net force accumulated by every `Body`
    /// force (the floor's normal reaction and friction).
    Contact,
}

/// A force acting on some particles.
///
/// `apply` adds to `forces` (one entry per particle of the world) and must not
/// assume it is called once per step: higher-order integrators call it at each
/// trial state. Forces that conserve energy say so and report their potential
/// energy, which the world uses to report energy drift.
///
/// A force is `Clone` (derive it), so that a world can be cloned whole.
pub trait Force: Send + CloneForce {
    /// Adds this force's contribution at the trial state `ctx` to `forces`.
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]);

    /// Potential energy of the configuration `ctx`, J (0 unless conservative).
    fn potential_energy(&self, _ctx: &ForceContext) -> f64 {
        0.0
    }

    /// True when the force is conservative (its work is minus the change of
    /// [`potential_energy`](Force::potential_energy)).
    fn is_conservative(&self) -> bool {
        false
    }

    /// True when the force can never add mechanical energy (conservative or
    /// dissipative: springs, joints, drag in still fluid, the floor); a motor,
    /// a constant push or a current is not.
    fn is_passive(&self) -> bool {
        self.is_conservative()
    }

    /// Adds this force's derivatives at `ctx` to `jac` (see
    /// [`Jacobian`]) and returns true, so that the implicit integrator can
    /// take it implicitly. The default adds nothing and returns false: the
    /// implicit integrator then takes the force explicitly (it still acts,
    /// only a stiff one limits the step as under an explicit integrator).
    fn jacobian(&self, _ctx: &ForceContext, _jac: &mut Jacobian) -> bool {
        false
    }

    /// When it is applied; see [`Stage`].
    fn stage(&self) -> Stage {
        Stage::Body
    }

    /// A short name for summaries and error messages.
    fn name(&self) -> &str {
        "force"
    }

    /// The force as [`std::any::Any`], for a built-in force a second
    /// implementation reads (the GPU step's packer); `None` by default.
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }
}

/// The particles a force or event acts on: the thesis makes every association
/// explicit, and a scene may say "all".
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum Targets {
    /// Every particle of the world, including those added later.
    #[default]
    All,
    /// Only these.
    Only(Vec<ParticleId>),
}

impl Targets {
    /// Exactly these particles.
    pub fn only(ids: impl IntoIterator<Item = ParticleId>) -> Self {
        Targets::Only(ids.into_iter().collect())
    }

    /// Calls `f` with the index of every target, for a world of `n` particles.
    #[inline]
    pub fn for_each(&self, n: usize, mut f: impl FnMut(usize)) {
        match self {
            Targets::All => (0..n).for_each(f),
            Targets::Only(ids) => ids.iter().for_each(|id| f(id.index())),
        }
    }

    /// True if `id` is a target.
    pub fn contains(&self, id: ParticleId) -> bool {
        match self {
            Targets::All => true,
            Targets::Only(ids) => ids.contains(&id),
        }
    }

    /// The largest particle index named, if any, for validation.
    pub(crate) fn max_index(&self) -> Option<usize> {
        match self {
            Targets::All => None,
            Targets::Only(ids) => ids.iter().map(|id| id.index()).max(),
        }
    }
}

/// Clones a boxed force; implemented for every `Force + Clone`, so a user
/// force needs only `#[derive(Clone)]`.
pub trait CloneForce {
    /// A boxed copy.
    fn clone_box(&self) -> Box<dyn Force>;
}

impl<T: Force + Clone + 'static> CloneForce for T {
    fn clone_box(&self) -> Box<dyn Force> {
        Box::new(self.clone())
    }
}

impl Clone for Box<dyn Force> {
    fn clone(&self) -> Self {
        self.as_ref().clone_box()
    }
}
