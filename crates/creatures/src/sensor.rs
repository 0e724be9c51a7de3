//! The `Sensor` interface (thesis §2.3.2.2, §4.2.2): one number in [0, 1]
//! read from the world. Sensors are abstract, "innate" senses (the thesis's
//! word): they read the simulation directly rather than simulating eyes.

use animats_engine::World;

/// A sense: reports a level in [0, 1].
pub trait Sensor {
    /// The current level, clamped to [0, 1].
    fn level(&self, world: &World) -> f64;

    /// The sensor as itself, for code that reads a built-in kind's
    /// parameters (the GPU's packer reads a scene's `[[sensor]]`); a
    /// user's sensor need not say.
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }
}

/// Clamps `x` to [0, 1] (NaN becomes 0, so a sensor never reports NaN).
#[inline]
pub fn unit(x: f64) -> f64 {
    if x >= 1.0 {
        1.0
    } else if x > 0.0 {
        x
    } else {
        0.0
    }
}
