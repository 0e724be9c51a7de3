//! The built-in forces, one per file. To write your own, copy the shape of
//! `constant_force.rs` (the simplest) and implement [`Force`](crate::Force).

pub mod angle_joint;
pub mod constant_force;
pub mod current;
pub mod floor_contact;
pub mod fluid;
pub mod gravity;
pub mod linear_drag;
pub mod nbody;
pub mod rod_drag;
pub mod soft_contact;
pub mod spring;
pub mod torque_joint;
