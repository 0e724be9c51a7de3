//! The sensors a scene file declares (`[[sensor]]`): a physical reading
//! mapped linearly from [min, max] onto [0, 1] and clamped.

use crate::sensor::{unit, Sensor};
use animats_engine::{DVec3, ParticleId, World};

/// How close to the floor a sphere's lowest point must be to touch it, m.
/// Resting spheres sit within a micrometre of the plane; a sphere that hits
/// it is put back on it by the collision.
pub const TOUCH_TOLERANCE: f64 = 1e-3;

/// True while `p`'s lowest point is on or below the floor (within
/// [`TOUCH_TOLERANCE`]).
pub fn touches_floor(world: &World, p: ParticleId) -> bool {
    world.position(p).y - world.particles().radius[p.index()] <= TOUCH_TOLERANCE
}

/// What is read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Probe {
    /// The y of a particle, m.
    Height(ParticleId),
    /// The velocity of a particle along a unit axis, m/s.
    Speed(ParticleId, DVec3),
    /// 1 while the particle touches the floor, else 0.
    Touch(ParticleId),
    /// The distance between two particles, m.
    Length(ParticleId, ParticleId),
    /// The angle at `joint` between `a` and `b`, rad in [0, π].
    Angle {
        /// End of the first arm.
        a: ParticleId,
        /// The vertex.
        joint: ParticleId,
        /// End of the second arm.
        b: ParticleId,
    },
    /// The angle of `a → b` from the vertical, rad in [0, π].
    Tilt(ParticleId, ParticleId),
}

impl Probe {
    /// The raw reading, in SI units.
    pub fn read(&self, world: &World) -> f64 {
        let p = |id: ParticleId| world.position(id);
        match *self {
            Probe::Height(q) => p(q).y,
            Probe::Speed(q, axis) => world.velocity(q).dot(axis),
            Probe::Touch(q) => {
                if touches_floor(world, q) {
                    1.0
                } else {
                    0.0
                }
            }
            Probe::Length(a, b) => p(a).distance(p(b)),
            Probe::Angle { a, joint, b } => {
                animats_engine::forces::angle_joint::angle_at(p(a), p(joint), p(b))
            }
            Probe::Tilt(a, b) => {
                let v = p(b) - p(a);
                let horizontal = (v.x * v.x + v.z * v.z).sqrt();
                libm::atan2(horizontal, v.y)
            }
        }
    }
}

/// A probe whose reading maps from [min, max] onto [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaledSensor {
    /// What is read.
    pub probe: Probe,
    /// The reading that gives level 0.
    pub min: f64,
    /// The reading that gives level 1.
    pub max: f64,
}

impl Sensor for ScaledSensor {
    fn level(&self, world: &World) -> f64 {
        unit((self.probe.read(world) - self.min) / (self.max - self.min))
    }
}
