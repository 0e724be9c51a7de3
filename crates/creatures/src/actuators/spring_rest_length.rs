//! A spring's rest length as an actuated parameter: the spring becomes a
//! muscle (Tu's idea, thesis §2.3.2.3).

use crate::actuator::Actuated;
use animats_engine::{SpringId, World};

/// The rest length of one spring, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringRestLength(pub SpringId);

impl Actuated for SpringRestLength {
    fn get(&self, world: &World) -> f64 {
        world.forces().springs.get(self.0).rest_length
    }
    fn set(&self, world: &mut World, value: f64) {
        world.forces_mut().springs.set_rest_length(self.0, value);
    }
}
