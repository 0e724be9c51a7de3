//! Smell of food (the jellyfish's Appendix B `FoodSensor`): falls off with the
//! horizontal distance `d` from the sensing particle to the food as `0.1 / d`,
//! clamped to [0, 1] (full strength within 10 cm).

use crate::sensor::{unit, Sensor};
use animats_engine::math;
use animats_engine::{ParticleId, World};

/// Food concentration at `sensor`, from `food`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FoodSensor {
    /// Where the sense is (a dome mass).
    pub sensor: ParticleId,
    /// The food.
    pub food: ParticleId,
}

impl FoodSensor {
    /// Horizontal distance from the sensor to the food, m.
    pub fn distance(&self, world: &World) -> f64 {
        let d = world.position(self.food) - world.position(self.sensor);
        math::hypot(d.x, d.z)
    }
}

impl Sensor for FoodSensor {
    fn level(&self, world: &World) -> f64 {
        unit(0.1 / self.distance(world))
    }
}
