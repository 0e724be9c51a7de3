//! A finite-state machine as data, after the thesis's hopping FSM
//! (§3.2.1.4): each state sets every output to a target level (at once, or
//! moving towards it at a given rate); transitions leave a state when a
//! sensor level crosses a threshold, after a time in the state, or both.
//!
//! Each step: first the transitions of the current state are checked in
//! order, and the first whose conditions all hold is taken (one per step;
//! the time in the new state starts at 0); then the state's levels are
//! applied. A transition with a sensor condition and `after` needs both.
//!
//! Genome, state by state: its levels (one per output), its rate if it has
//! one, then for each of its transitions its threshold (if it reads a
//! sensor) and its `after` (if it has one). Bounds: levels and thresholds
//! in [0, 1], times in [0, max(2 s, 2 × value)], rates in
//! [0, max(100, 2 × value)] per second.

use crate::brain::{around, check_genome, Brain, GenomeKey};

/// What a transition reads.
#[derive(Clone, Debug, PartialEq)]
pub enum Condition {
    /// Input `input` (an index into the controller's inputs) above the threshold.
    Above {
        /// Which input.
        input: usize,
        /// The level it must exceed.
        threshold: f64,
    },
    /// Input below the threshold.
    Below {
        /// Which input.
        input: usize,
        /// The level it must fall under.
        threshold: f64,
    },
    /// No sensor condition: time alone.
    None,
}

/// A way out of a state.
#[derive(Clone, Debug, PartialEq)]
pub struct Transition {
    /// The state it leads to (an index).
    pub to: usize,
    /// The sensor condition.
    pub condition: Condition,
    /// Least time in the state, s.
    pub after: Option<f64>,
}

/// One state.
#[derive(Clone, Debug, PartialEq)]
pub struct FsmState {
    /// Its name.
    pub name: String,
    /// The level of each output in this state.
    pub levels: Vec<f64>,
    /// Level units per second the outputs move towards the levels; `None`:
    /// at once.
    pub rate: Option<f64>,
    /// Ways out, checked in order.
    pub transitions: Vec<Transition>,
}

/// The machine.
#[derive(Clone, Debug, PartialEq)]
pub struct Fsm {
    /// Its states.
    pub states: Vec<FsmState>,
    /// Where it starts.
    pub initial: usize,
    current: usize,
    entered: f64,
    levels: Vec<f64>,
    started: bool,
}

impl Fsm {
    /// A machine starting in `initial`; `levels` are the outputs' levels
    /// before it acts (the actuators' initial levels).
    pub fn new(states: Vec<FsmState>, initial: usize, levels: Vec<f64>) -> Fsm {
        Fsm {
            states,
            initial,
            current: initial,
            entered: 0.0,
            levels,
            started: false,
        }
    }

    /// The current state's index.
    pub fn current(&self) -> usize {
        self.current
    }

    fn fires(t: &Transition, inputs: &[f64], in_state: f64) -> bool {
        let sensed = match t.condition {
            Condition::Above { input, threshold } => inputs[input] > threshold,
            Condition::Below { input, threshold } => inputs[input] < threshold,
            Condition::None => true,
        };
        sensed && t.after.is_none_or(|a| in_state >= a)
    }

    /// Every gene in genome order, with its key in the scene file's
    /// controller table and its bounds (the one place the layout is
    /// written).
    fn genes(&mut self) -> Vec<(GenomeKey, &mut f64, (f64, f64))> {
        let mut out = Vec::new();
        for (i, s) in self.states.iter_mut().enumerate() {
            let n = s.levels.len();
            for l in s.levels.iter_mut() {
                let b = around(*l, 0.0, 1.0);
                out.push((GenomeKey::array(format!("state[{i}].levels"), n), l, b));
            }
            if let Some(r) = &mut s.rate {
                let b = around(*r, 0.0, (2.0 * *r).max(100.0));
                out.push((GenomeKey::number(format!("state[{i}].rate")), r, b));
            }
            for (j, t) in s.transitions.iter_mut().enumerate() {
                let key = |k: &str| GenomeKey::number(format!("state[{i}].transition[{j}].{k}"));
                match &mut t.condition {
                    Condition::Above { threshold, .. } => {
                        let b = around(*threshold, 0.0, 1.0);
                        out.push((key("above"), threshold, b));
                    }
                    Condition::Below { threshold, .. } => {
                        let b = around(*threshold, 0.0, 1.0);
                        out.push((key("below"), threshold, b));
                    }
                    Condition::None => {}
                }
                if let Some(a) = &mut t.after {
                    let b = around(*a, 0.0, (2.0 * *a).max(2.0));
                    out.push((key("after"), a, b));
                }
            }
        }
        out
    }
}

impl Brain for Fsm {
    fn kind(&self) -> &'static str {
        "fsm"
    }

    fn think(&mut self, t: f64, dt: f64, inputs: &[f64], outputs: &mut [f64]) {
        if !self.started {
            self.started = true;
            self.entered = t;
        }
        let in_state = t - self.entered;
        let next = self.states[self.current]
            .transitions
            .iter()
            .find(|tr| Fsm::fires(tr, inputs, in_state))
            .map(|tr| tr.to);
        if let Some(next) = next {
            self.current = next;
            self.entered = t;
        }
        let s = &self.states[self.current];
        for (l, target) in self.levels.iter_mut().zip(&s.levels) {
            *l = match s.rate {
                None => *target,
                Some(r) => {
                    let step = r * dt;
                    *l + (target - *l).clamp(-step, step)
                }
            };
        }
        outputs.copy_from_slice(&self.levels);
    }

    fn state(&self) -> Option<&str> {
        Some(&self.states[self.current].name)
    }

    fn genome(&self) -> Vec<f64> {
        self.clone().genes().into_iter().map(|g| *g.1).collect()
    }

    fn set_genome(&mut self, g: &[f64]) -> Result<(), String> {
        let mut genes = self.genes();
        check_genome("fsm", genes.len(), g)?;
        for (slot, v) in genes.iter_mut().zip(g) {
            *slot.1 = *v;
        }
        Ok(())
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        self.clone().genes().into_iter().map(|g| g.2).collect()
    }

    fn genome_keys(&self) -> Vec<GenomeKey> {
        let mut keys: Vec<GenomeKey> = Vec::new();
        for (key, _, _) in self.clone().genes() {
            // A state's levels are one array: one key for all of them.
            if keys.last() != Some(&key) {
                keys.push(key);
            }
        }
        keys
    }

    fn reset(&mut self) {
        self.current = self.initial;
        self.started = false;
    }
}
