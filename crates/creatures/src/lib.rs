//! # animats-creatures
//!
//! The animat layer (thesis §2.3.2, §4.2) on top of the engine: sensors that
//! report a level in [0, 1], actuators that map a level in [0, 1] onto a
//! physical parameter, controllers that read the one and set the other once
//! per step, and the thesis's creatures built from them.
//!
//! - [`sensor::Sensor`], one sensor per file in [`sensors`];
//! - [`actuator::Actuator`] over an [`actuator::Actuated`] parameter, one per
//!   file in [`actuators`];
//! - [`brain::Brain`] (sensor levels in, actuator levels out) and the
//!   kinds a scene declares in [`brains`], wired by [`nervous_system`];
//! - [`controller::Actor`]: whatever acts once per step beside the nervous
//!   system (a jellyfish's own FSM, a bubble column);
//! - [`roobot`]: the hopping monopod, its FSM and Raibert's controller.

#![warn(missing_docs)]

pub mod actuator;
pub mod actuators;
pub mod brain;
pub mod brains;
pub mod controller;
pub mod env;
pub mod jellyfish;
pub mod kept;
pub mod nervous_system;
pub mod quadruped;
pub mod random;
pub mod roobot;
pub mod seaworld;
pub mod sensor;
pub mod sensors;
pub mod vec_env;

pub use brain::Brain;
pub use controller::{Actor, Status};
pub use nervous_system::NervousSystem;
