//! The magnitude of a constant force along a direction, as an actuated
//! parameter (the jellyfish's pulse and steering forces).

use crate::actuator::Actuated;
use animats_engine::{ConstantForceId, DVec3, World};

/// The magnitude of a constant force; setting it keeps the force's current
/// direction (or `direction` when the force is zero).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceMagnitude {
    /// The force driven.
    pub force: ConstantForceId,
    /// Direction used when the force is zero.
    pub direction: DVec3,
}

impl Actuated for ForceMagnitude {
    fn get(&self, world: &World) -> f64 {
        world
            .forces()
            .constant_forces
            .get(self.force)
            .force
            .length()
    }
    fn set(&self, world: &mut World, value: f64) {
        let current = world.forces().constant_forces.get(self.force).force;
        let dir = current.try_normalize().unwrap_or(self.direction);
        world
            .forces_mut()
            .constant_forces
            .set(self.force, dir * value);
    }
}
