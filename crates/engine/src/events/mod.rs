//! The built-in discrete events, one per file.

pub mod floor_collision;
pub mod plane_constraint;
pub mod sphere_contact;
