//! Tilt of a limb from the vertical, in a creature's plane of motion (the
//! roobot's leg-angle sensor, Appendix B `LegAngleSensor`).
//!
//! With θ the angle of the vector from `base` to `tip` from the vertical,
//! positive when the tip leans forward, the level is `0.5 + gain θ`, clamped
//! to [0, 1]. With gain π/2, level 0.5 is upright and the full range is
//! ±1/π rad (±18.2°): this is what Appendix B's `0.5 + (legangle/2.0*Math.PI)`
//! computes (Java reads it as `(legangle/2)·π`). The evident intent was
//! `legangle/(2π)`, but the thesis's evolution ran with the former and its
//! parameters only make sense under it (Table 6's evolved target angle 0.8156
//! is 11.5° with gain π/2 and would be 113° with 1/(2π)). See docs/ROOBOT.md.

use crate::sensor::{unit, Sensor};
use animats_engine::{DVec3, ParticleId, World};

/// Lean of `base → tip` from the vertical along `forward`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TiltSensor {
    /// Lower end of the limb (the foot).
    pub base: ParticleId,
    /// Upper end (the hip).
    pub tip: ParticleId,
    /// Unit horizontal forward direction of the creature.
    pub forward: DVec3,
    /// Level per radian of lean.
    pub gain: f64,
}

impl TiltSensor {
    /// The lean angle θ, rad (positive forward), `atan2(forward, up)`.
    pub fn angle(&self, world: &World) -> f64 {
        let v = world.position(self.tip) - world.position(self.base);
        // libm: the same bits on every platform, for reproducible evolution.
        libm::atan2(v.dot(self.forward), v.y)
    }
}

impl Sensor for TiltSensor {
    fn level(&self, world: &World) -> f64 {
        unit(0.5 + self.gain * self.angle(world))
    }
}
