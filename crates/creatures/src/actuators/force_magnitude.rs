//! The signed magnitude of a constant force along an axis, as an actuated
//! parameter (the jellyfish's pulse and steering forces, Appendix B's
//! `ConstantForceActuator`). The controller may turn the axis each step
//! (the jellyfish points it along its dome's normal); the magnitude may be
//! negative (a force against the axis).

use crate::actuator::Actuated;
use animats_engine::{ConstantForceId, DVec3, World};

/// `force = axis × magnitude` for one constant force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceMagnitude {
    /// The force driven.
    pub force: ConstantForceId,
    /// Unit axis of the force.
    pub axis: DVec3,
}

impl Actuated for ForceMagnitude {
    fn get(&self, world: &World) -> f64 {
        world
            .forces()
            .constant_forces
            .get(self.force)
            .force
            .dot(self.axis)
    }
    fn set(&self, world: &mut World, value: f64) {
        world
            .forces_mut()
            .constant_forces
            .set(self.force, self.axis * value);
    }
}
