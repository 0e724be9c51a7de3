//! Height of a sphere's lowest point above the floor (the roobot's foot
//! height sensor, Appendix B `HeightSensor`): metres, clamped to [0, 1].

use crate::sensor::{unit, Sensor};
use animats_engine::{ParticleId, World};

/// Height of `particle`'s lowest point above the plane y = 0 (on terrain:
/// its distance from the terrain's surface), m, in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeightSensor {
    /// The sphere measured.
    pub particle: ParticleId,
}

impl Sensor for HeightSensor {
    fn level(&self, world: &World) -> f64 {
        unit(world.clearance(self.particle))
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}
