//! The controller kinds a scene file can declare, one per file. Adding a
//! kind: a file here implementing [`crate::brain::Brain`], its entry in
//! `crates/scene/src/def.rs` and its case in `crates/scene/src/brains.rs`.

pub mod fsm;
pub mod neural;
pub mod oscillator;

pub use fsm::{Condition, Fsm, FsmState, Transition};
pub use neural::Neural;
pub use oscillator::Oscillator;
