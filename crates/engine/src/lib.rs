//! # animats-engine
//!
//! The particle dynamics engine of animats, after Paul Urban, *Autonomous
//! Dynamically Simulated Creatures for Virtual Environments* (Rhodes
//! University, 2001), §2.3 and §3.1: point masses (spheres), the forces that act
//! on them, discrete events such as collisions with the floor, and
//! integrators that advance them in time.
//!
//! - A [`World`] stores its particles as arrays (structure of arrays)
//!   addressed by copyable [`ParticleId`] handles.
//! - Forces implement [`Force`]; the built-in ones live in [`forces`], one
//!   file each, and in typed collections so their loops are tight. Add your
//!   own with [`World::add_force`] (see `examples/nbody/gravity.rs`).
//! - Discrete events implement [`DiscreteEvent`]; a missed event makes the
//!   world retake the step in shorter pieces ([`World::step`]). The floor's
//!   collisions and sphere–sphere contact ([`SphereContact`]) are events.
//! - Integrators ([`IntegratorKind`]): explicit Euler, midpoint, RK4 and
//!   symplectic Euler, explicit; implicit Euler for stiff bodies; chosen at
//!   run time.
//!
//! No I/O, no global state: a world is a plain value, so many can run side
//! by side (one per evolving individual). The one exception changes speed,
//! never results: the vector instructions the hot loops use, chosen once
//! per process from the CPU and `ANIMATS_SIMD` ([`simd_summary`]). A large world also splits its own
//! heaviest loops (springs, n-body gravity, the integrators' updates) among
//! the threads of the current rayon pool, with the same bits on any number
//! of threads.

#![warn(missing_docs)]

pub mod cpu;
pub mod error;
pub mod event;
pub mod events;
pub mod force;
pub mod force_set;
pub mod forces;
pub mod guard;
pub mod integrators;
pub mod jacobian;
pub mod math;
mod parallel;
pub mod particle;
pub mod pin;
mod simd;
pub mod snapshot;
pub mod terrain;
pub mod world;

pub use error::{ModelError, Shown, SimError};
pub use event::{AsAny, ByPieces, DiscreteEvent, EventContext, EventState, TrialPiece};
pub use events::floor_collision::{Collision, FloorCollision};
pub use events::plane_constraint::PlaneConstraint;
pub use events::sphere_contact::{Impact, SleepState, SphereContact, SphereContactDef};
pub use force::{Force, ForceContext, Stage, Targets};
pub use force_set::Forces;
pub use forces::{
    angle_joint::{AngleJoint, AngleJointDef, AngleJointId},
    constant_force::{ConstantForce, ConstantForceId},
    current::{Current, ReefWater},
    floor_contact::FloorContact,
    fluid::FluidMedium,
    gravity::Gravity,
    linear_drag::LinearDrag,
    nbody::NBodyGravity,
    rod_drag::RodDrag,
    soft_contact::SoftContact,
    spring::{Spring, SpringDef, SpringId},
    torque_joint::{TorqueJoint, TorqueJointDef, TorqueJointId},
};
pub use guard::DivergenceGuard;
pub use integrators::{IntegratorKind, Solver};
pub use jacobian::Jacobian;
pub use particle::{ParticleDef, ParticleId, Properties, State};
pub use simd::summary as simd_summary;
pub use snapshot::Snapshot;
pub use terrain::{Heightfield, Slope, Steps, Terrain};
pub use world::{on_pool, on_pool_if, Energy, FloorDef, Stats, StepLimit, StepReport, World};

pub use glam::{DVec2, DVec3};
