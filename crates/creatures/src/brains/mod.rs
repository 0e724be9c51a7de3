//! The controller kinds a scene file can declare (`[[controller]]`), one
//! per file: each file holds its brain (a [`crate::brain::Brain`]) and its
//! entry (the keys a scene file gives it, checked by serde and by its
//! `build`). Adding a kind: a file here, and its variant of
//! [`ControllerEntry`] below.

pub mod ctrnn;
pub mod fsm;
pub mod neural;
pub mod oscillator;

pub use ctrnn::{Ctrnn, CtrnnEntry};
pub use fsm::{Condition, Fsm, FsmEntry, FsmState, StateEntry, Transition, TransitionEntry};
pub use neural::{Neural, NeuralEntry};
pub use oscillator::{Oscillator, OscillatorEntry};

use crate::brain::Brain;
use animats_engine::ModelError;
use serde::Deserialize;

/// `[[controller]]`: a brain from sensors to actuators, of the kind its
/// `kind` key names.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum ControllerEntry {
    /// Sines at one frequency.
    Oscillator(OscillatorEntry),
    /// A feed-forward network.
    Neural(NeuralEntry),
    /// A finite-state machine.
    Fsm(FsmEntry),
    /// A continuous-time recurrent network.
    Ctrnn(CtrnnEntry),
}

impl ControllerEntry {
    /// Its name.
    pub fn name(&self) -> &str {
        match self {
            ControllerEntry::Oscillator(e) => &e.name,
            ControllerEntry::Neural(e) => &e.name,
            ControllerEntry::Fsm(e) => &e.name,
            ControllerEntry::Ctrnn(e) => &e.name,
        }
    }

    /// The sensors it reads, by name.
    pub fn inputs(&self) -> &[String] {
        match self {
            ControllerEntry::Oscillator(_) => &[],
            ControllerEntry::Neural(e) => &e.inputs,
            ControllerEntry::Fsm(e) => &e.inputs,
            ControllerEntry::Ctrnn(e) => &e.inputs,
        }
    }

    /// The actuators it drives, by name.
    pub fn outputs(&self) -> &[String] {
        match self {
            ControllerEntry::Oscillator(e) => &e.outputs,
            ControllerEntry::Neural(e) => &e.outputs,
            ControllerEntry::Fsm(e) => &e.outputs,
            ControllerEntry::Ctrnn(e) => &e.outputs,
        }
    }

    /// The brain it describes; `levels` are its outputs' initial levels.
    pub fn build(&self, levels: Vec<f64>) -> Result<Box<dyn Brain>, ModelError> {
        Ok(match self {
            ControllerEntry::Oscillator(e) => Box::new(e.build()?),
            ControllerEntry::Neural(e) => Box::new(e.build()?),
            ControllerEntry::Fsm(e) => Box::new(e.build(levels)?),
            ControllerEntry::Ctrnn(e) => Box::new(e.build()?),
        })
    }
}
