//! Tilt of a limb from the vertical, in a creature's plane of motion (the
//! roobot's leg-angle sensor, Appendix B `LegAngleSensor`).
//!
//! With θ the angle of the vector from `base` to `tip` from the vertical,
//! positive when the tip leans forward, the level is `0.5 + gain θ`, clamped
//! to [0, 1]. The roobot uses gain 1/(2π) (`BodyConstants::leg_angle_gain`):
//! full scale ±π. Appendix B's `0.5 + (legangle/2.0*Math.PI)` is read by Java
//! as gain π/2 (full scale ±18.2°); the evident intent is `legangle/(2π)`,
//! and with our body only that reading reproduces the thesis's behaviour,
//! though Table 6's evolved values (0.8156: 11.5° under π/2, 113° under
//! 1/(2π)) fit the slip. docs/ROOBOT.md gives the measurements.

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
        animats_engine::math::atan2(v.dot(self.forward), v.y)
    }
}

impl Sensor for TiltSensor {
    fn level(&self, world: &World) -> f64 {
        unit(0.5 + self.gain * self.angle(world))
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}
