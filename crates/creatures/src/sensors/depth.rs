//! How high a particle's centre is above the floor, m, clamped to [0, 1]
//! (the jellyfish's Appendix B `HeightSensor`, its "depth" sense: 1 means at
//! or above 1 m, which the jellyfish takes as too high to swim further).

use crate::sensor::{unit, Sensor};
use animats_engine::{ParticleId, World};

/// Height of `particle`'s centre above y = 0 as a fraction of `ceiling`,
/// in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthSensor {
    /// The particle measured.
    pub particle: ParticleId,
    /// The height that reads as 1, m (Appendix B: 1 m).
    pub ceiling: f64,
}

impl Sensor for DepthSensor {
    fn level(&self, world: &World) -> f64 {
        unit(world.position(self.particle).y / self.ceiling)
    }
}
