//! The physical parameters an actuator can drive, one per file, and
//! [`AnyActuator`], the actuators a scene file declares.

pub mod force_magnitude;
pub mod force_scale;
pub mod joint_rest_angle;
pub mod joint_torque;
pub mod spring_rest_length;

pub use force_magnitude::ForceMagnitude;
pub use force_scale::ForceScale;
pub use joint_rest_angle::JointRestAngle;
pub use joint_torque::JointTorque;
pub use spring_rest_length::SpringRestLength;

use crate::actuator::{Actuated, Actuator};
use animats_engine::World;

/// An actuator over any of the parameters a scene's `[[actuator]]` can name.
#[derive(Clone, Debug, PartialEq)]
pub enum AnyActuator {
    /// `spring = "..."`: its rest length, m.
    Spring(Actuator<SpringRestLength>),
    /// `angle_joint = "..."`: its rest angle, rad.
    AngleJoint(Actuator<JointRestAngle>),
    /// `torque_joint = "..."`: its torque, N m.
    TorqueJoint(Actuator<JointTorque>),
    /// `constant_force = "..."`: a scale on its vector.
    ConstantForce(Actuator<ForceScale>),
}

impl AnyActuator {
    /// Sets the level (clamped to [0, 1]) and drives the parameter.
    pub fn set_level(&mut self, world: &mut World, level: f64) {
        match self {
            AnyActuator::Spring(a) => a.set_level(world, level),
            AnyActuator::AngleJoint(a) => a.set_level(world, level),
            AnyActuator::TorqueJoint(a) => a.set_level(world, level),
            AnyActuator::ConstantForce(a) => a.set_level(world, level),
        }
    }

    /// Sets the level (clamped to [0, 1]) without driving the parameter:
    /// for a snapshot's restore, whose world holds the value.
    pub fn set_level_alone(&mut self, level: f64) {
        match self {
            AnyActuator::Spring(a) => a.set_level_alone(level),
            AnyActuator::AngleJoint(a) => a.set_level_alone(level),
            AnyActuator::TorqueJoint(a) => a.set_level_alone(level),
            AnyActuator::ConstantForce(a) => a.set_level_alone(level),
        }
    }

    /// Whether a gate can hold it off: a motor's torque and a force's scale
    /// have a zero that is "off"; a rest length or a rest angle has none.
    pub fn can_gate(&self) -> bool {
        matches!(
            self,
            AnyActuator::TorqueJoint(_) | AnyActuator::ConstantForce(_)
        )
    }

    /// Drives the parameter at its level's value while `open`, at zero
    /// while closed (only for actuators that [`AnyActuator::can_gate`]).
    pub fn gate(&self, world: &mut World, open: bool) {
        match self {
            AnyActuator::TorqueJoint(a) => {
                a.target().set(world, if open { a.value() } else { 0.0 })
            }
            AnyActuator::ConstantForce(a) => {
                a.target().set(world, if open { a.value() } else { 0.0 })
            }
            AnyActuator::Spring(_) | AnyActuator::AngleJoint(_) => {}
        }
    }

    /// The level it started at.
    pub fn initial_level(&self) -> f64 {
        match self {
            AnyActuator::Spring(a) => a.initial_level(),
            AnyActuator::AngleJoint(a) => a.initial_level(),
            AnyActuator::TorqueJoint(a) => a.initial_level(),
            AnyActuator::ConstantForce(a) => a.initial_level(),
        }
    }

    /// The current level.
    pub fn level(&self) -> f64 {
        match self {
            AnyActuator::Spring(a) => a.level(),
            AnyActuator::AngleJoint(a) => a.level(),
            AnyActuator::TorqueJoint(a) => a.level(),
            AnyActuator::ConstantForce(a) => a.level(),
        }
    }
}
