//! An angle joint's rest angle as an actuated parameter: a joint servo.

use crate::actuator::Actuated;
use animats_engine::{AngleJointId, World};

/// The rest angle of one angle joint, rad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointRestAngle(pub AngleJointId);

impl Actuated for JointRestAngle {
    fn get(&self, world: &World) -> f64 {
        world.forces().angle_joints.get(self.0).rest_angle
    }
    fn set(&self, world: &mut World, value: f64) {
        world.forces_mut().angle_joints.get_mut(self.0).rest_angle = value;
    }
}
