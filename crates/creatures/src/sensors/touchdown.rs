//! Estimated time until a falling sphere touches the floor (the roobot's
//! Appendix B `TimeTillTouchdownSensor`): ballistic flight from its height
//! `h` and vertical velocity `v`, `t = (v + sqrt(v² + 2 g h)) / g`, in
//! seconds, clamped to [0, 1].

use crate::sensor::{unit, Sensor};
use crate::sensors::height::HeightSensor;
use animats_engine::World;

/// Time till `height.particle` lands, s, in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TouchdownSensor {
    /// The height sensor of the same sphere (the thesis uses its clamped level).
    pub height: HeightSensor,
    /// Gravitational acceleration assumed, m/s² (the thesis's 9.8).
    pub g: f64,
}

impl Sensor for TouchdownSensor {
    fn level(&self, world: &World) -> f64 {
        let h = self.height.level(world);
        let v = world.velocity(self.height.particle).y;
        unit((v + (v * v + 2.0 * self.g * h).sqrt()) / self.g)
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}
