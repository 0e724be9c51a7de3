//! A scale on a constant force's vector as an actuated parameter: the force
//! the scene gives, times the actuator's value (so a range [0, 1] turns it
//! off and on, [−1, 1] reverses it).

use crate::actuator::Actuated;
use animats_engine::{ConstantForceId, DVec3, World};

/// `force = base × value` for one constant force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceScale {
    /// The force driven.
    pub force: ConstantForceId,
    /// Its vector at scale 1, N.
    pub base: DVec3,
}

impl Actuated for ForceScale {
    fn get(&self, world: &World) -> f64 {
        let f = world.forces().constant_forces.get(self.force).force;
        let b2 = self.base.length_squared();
        if b2 > 0.0 {
            f.dot(self.base) / b2
        } else {
            0.0
        }
    }
    fn set(&self, world: &mut World, value: f64) {
        world
            .forces_mut()
            .constant_forces
            .set(self.force, self.base * value);
    }
}
