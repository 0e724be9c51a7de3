//! The physical parameters an actuator can drive, one per file.

pub mod force_magnitude;
pub mod joint_torque;
pub mod spring_rest_length;

pub use force_magnitude::ForceMagnitude;
pub use joint_torque::JointTorque;
pub use spring_rest_length::SpringRestLength;
