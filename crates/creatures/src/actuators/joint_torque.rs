//! A torque joint's torque as an actuated parameter: a motor.

use crate::actuator::Actuated;
use animats_engine::{TorqueJointId, World};

/// The torque of one torque joint, N m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointTorque(pub TorqueJointId);

impl Actuated for JointTorque {
    fn get(&self, world: &World) -> f64 {
        world.forces().torque_joints.get(self.0).torque
    }
    fn set(&self, world: &mut World, value: f64) {
        world.forces_mut().torque_joints.set_torque(self.0, value);
    }
}
