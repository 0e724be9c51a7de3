//! Forward speed of a particle (the roobot's hip speed sensor, Appendix B
//! `SpeedSensor`): m/s along the creature's forward direction, clamped to [0, 1].

use crate::sensor::{unit, Sensor};
use animats_engine::{DVec3, ParticleId, World};

/// Velocity of `particle` along `forward`, m/s, in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedSensor {
    /// The particle measured.
    pub particle: ParticleId,
    /// Unit forward direction.
    pub forward: DVec3,
}

impl SpeedSensor {
    /// The unclamped forward speed, m/s.
    pub fn speed(&self, world: &World) -> f64 {
        world.velocity(self.particle).dot(self.forward)
    }
}

impl Sensor for SpeedSensor {
    fn level(&self, world: &World) -> f64 {
        unit(self.speed(world))
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}
