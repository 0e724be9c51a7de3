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

use crate::brain::{around, check_genome, finite, positive, Brain, GenomeKey};
use animats_engine::ModelError;
use serde::Deserialize;

/// `[[controller]] kind = "fsm"`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FsmEntry {
    /// Unique among controllers.
    pub name: String,
    /// Sensors read, by name (transitions compare their levels).
    #[serde(default)]
    pub inputs: Vec<String>,
    /// Actuators driven, by name.
    pub outputs: Vec<String>,
    /// The state it starts in; default the first.
    pub initial: Option<String>,
    /// Its states, `[[controller.state]]`.
    #[serde(default)]
    pub state: Vec<StateEntry>,
}

/// `[[controller.state]]` of an FSM.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StateEntry {
    /// Unique within the controller.
    pub name: String,
    /// The level of each output in this state.
    pub levels: Vec<f64>,
    /// Level units per second the outputs move towards `levels`; default: at once.
    pub rate: Option<f64>,
    /// Ways out, checked in order.
    #[serde(default)]
    pub transition: Vec<TransitionEntry>,
}

/// `[[controller.state.transition]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransitionEntry {
    /// The state it leads to.
    pub to: String,
    /// An input sensor whose level is compared.
    pub sensor: Option<String>,
    /// Fires when the sensor's level is above this.
    pub above: Option<f64>,
    /// Fires when the sensor's level is below this.
    pub below: Option<f64>,
    /// Fires only after this long in the state, s.
    pub after: Option<f64>,
}

impl FsmEntry {
    /// The machine it describes; `levels` are its outputs' initial levels.
    pub fn build(&self, levels: Vec<f64>) -> Result<Fsm, ModelError> {
        let states = &self.state;
        if states.is_empty() {
            return Err(ModelError::new(
                "state",
                "an FSM needs at least one [[controller.state]]",
            ));
        }
        let built = states
            .iter()
            .enumerate()
            .map(|(i, s)| self.state(i, s))
            .collect::<Result<_, _>>()?;
        let initial = match &self.initial {
            Some(name) => self.index("initial", name)?,
            None => 0,
        };
        Ok(Fsm::new(built, initial, levels))
    }

    fn index(&self, field: &str, name: &str) -> Result<usize, ModelError> {
        self.state
            .iter()
            .position(|s| s.name == name)
            .ok_or_else(|| ModelError::new(field, format!("no state named `{name}`")))
    }

    fn state(&self, i: usize, s: &StateEntry) -> Result<FsmState, ModelError> {
        let n = self.outputs.len();
        let f = |k: &str| format!("state[{i}].{k}");
        if self.state[..i].iter().any(|o| o.name == s.name) {
            return Err(ModelError::new(
                f("name"),
                format!("duplicate state name `{}`", s.name),
            ));
        }
        if s.levels.len() != n {
            return Err(ModelError::new(
                f("levels"),
                format!("needs one level per output ({n}), got {}", s.levels.len()),
            ));
        }
        if let Some(l) = s.levels.iter().find(|l| !(0.0..=1.0).contains(*l)) {
            return Err(ModelError::new(
                f("levels"),
                format!("levels are in [0, 1], got {l}"),
            ));
        }
        let rate = match s.rate {
            Some(r) => Some(positive(&f("rate"), r)?),
            None => None,
        };
        let transitions = s
            .transition
            .iter()
            .enumerate()
            .map(|(j, t)| self.transition(&format!("state[{i}].transition[{j}]."), t))
            .collect::<Result<_, _>>()?;
        Ok(FsmState {
            name: s.name.clone(),
            levels: s.levels.clone(),
            rate,
            transitions,
        })
    }

    fn transition(&self, at: &str, t: &TransitionEntry) -> Result<Transition, ModelError> {
        let g = |k: &str| format!("{at}{k}");
        let to = self.index(&g("to"), &t.to)?;
        let input = match &t.sensor {
            Some(name) => Some(self.inputs.iter().position(|x| x == name).ok_or_else(|| {
                ModelError::new(
                    g("sensor"),
                    format!("`{name}` is not one of this controller's inputs"),
                )
            })?),
            None => None,
        };
        let condition = match (input, t.above, t.below) {
            (Some(input), Some(th), None) => Condition::Above {
                input,
                threshold: finite(&g("above"), th)?,
            },
            (Some(input), None, Some(th)) => Condition::Below {
                input,
                threshold: finite(&g("below"), th)?,
            },
            (Some(_), _, _) => {
                return Err(ModelError::new(
                    g("sensor"),
                    "give exactly one of `above` and `below` with a sensor",
                ))
            }
            (None, None, None) => Condition::None,
            (None, _, _) => {
                return Err(ModelError::new(
                    g("sensor"),
                    "`above` and `below` need a `sensor`",
                ))
            }
        };
        let after = match t.after {
            Some(a) if finite(&g("after"), a)? < 0.0 => {
                return Err(ModelError::new(
                    g("after"),
                    format!("must be >= 0, got {a}"),
                ))
            }
            other => other,
        };
        if condition == Condition::None && after.is_none() {
            return Err(ModelError::new(
                g("after"),
                "a transition needs a sensor condition, `after`, or both",
            ));
        }
        Ok(Transition {
            to,
            condition,
            after,
        })
    }
}

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

    /// The levels it outputs now (each moving towards the current state's
    /// at its `rate`).
    pub fn levels(&self) -> &[f64] {
        &self.levels
    }

    /// When the current state was entered, s, and whether the machine has
    /// started (its first `think` sets the clock of its first state).
    pub fn entered(&self) -> (f64, bool) {
        (self.entered, self.started)
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

/// What an [`Fsm`] keeps in a snapshot: its state, when it entered it,
/// its levels, whether it has begun.
struct FsmKept {
    current: usize,
    entered: f64,
    levels: Vec<f64>,
    started: bool,
}

impl Brain for Fsm {
    fn kind(&self) -> &'static str {
        "fsm"
    }

    fn save_state(&self) -> Option<crate::kept::Kept> {
        Some(crate::kept::Kept::new(FsmKept {
            current: self.current,
            entered: self.entered,
            levels: self.levels.clone(),
            started: self.started,
        }))
    }

    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        let k: &FsmKept = crate::kept::required(kept, "an fsm brain")?;
        if k.current >= self.states.len() || k.levels.len() != self.levels.len() {
            return Err("an fsm brain: the snapshot is of another machine".into());
        }
        self.current = k.current;
        self.entered = k.entered;
        self.levels.clone_from(&k.levels);
        self.started = k.started;
        Ok(())
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
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
