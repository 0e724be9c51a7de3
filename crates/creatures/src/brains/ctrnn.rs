//! A continuous-time recurrent neural network (Beer, "On the dynamics of
//! small continuous-time recurrent neural networks", Adaptive Behavior
//! 3(4), 1995): every neuron `i` has a state `y_i` obeying
//!
//! ```text
//! τ_i dy_i/dt = −y_i + Σ_j w_ij σ(g_j (y_j + θ_j)) + Σ_k v_ik x_k
//! ```
//!
//! with σ(z) = 1/(1 + e^−z), time constants τ, biases θ, gains g,
//! recurrent weights `w` and input weights `v`. The inputs `x` are the
//! sensor levels mapped onto [−1, 1] (`2x − 1`, as the feed-forward
//! network's) and, with a clock of frequency `f`, `sin 2πft` and
//! `cos 2πft`. Output `i` is the firing rate σ(g_i (y_i + θ_i)) of neuron
//! `i`, in [0, 1]: the first neurons drive the outputs, the others are
//! hidden (interneurons).
//!
//! Integrated with the engine's step `h`, once per step, the leak
//! implicitly and the rest explicitly (first order in `h`):
//! `y ← (y + (h/τ)(Σ w σ + Σ v x)) / (1 + h/τ)`, so the state stays
//! between its old value and the drive at any `h/τ` — a time constant far
//! below the step cannot blow the brain up. The states start at 0.
//!
//! Genome: τ (one per neuron), θ, g, then `w` row by row (`w_i0, w_i1, ...`
//! into neuron `i`), then `v` row by row. Bounds: τ in [0.01, 2] s, θ and
//! every weight in [−16, 16] (Beer's), g in [0, 5], each widened to contain
//! the value the scene gives; a τ below 1e-4 s counts as 1e-4 s.

use super::neural::logistic;
use crate::brain::{around, check_genome, finite, network_inputs, positive, Brain, GenomeKey};
use animats_engine::ModelError;
use serde::Deserialize;

/// The most neurons a network may have (10^6 recurrent weights).
pub const MAX_NEURONS: usize = 1000;

/// The shortest time constant used, s.
pub const MIN_TAU: f64 = 1e-4;

/// `[[controller]] kind = "ctrnn"`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CtrnnEntry {
    /// Unique among controllers.
    pub name: String,
    /// Sensors read, by name.
    #[serde(default)]
    pub inputs: Vec<String>,
    /// Actuators driven, by name: neuron `i` drives output `i`.
    pub outputs: Vec<String>,
    /// Neurons, at least one per output; default one per output.
    pub neurons: Option<usize>,
    /// Frequency of the clock inputs, Hz; default no clock.
    pub clock: Option<f64>,
    /// Time constants, s, one per neuron; default 0.1.
    pub tau: Option<Vec<f64>>,
    /// Biases θ, one per neuron; default 0.
    pub bias: Option<Vec<f64>>,
    /// Gains, one per neuron; default 1.
    pub gain: Option<Vec<f64>>,
    /// Recurrent weights, neurons × neurons, row `i` into neuron `i`;
    /// default 0.
    pub weights: Option<Vec<f64>>,
    /// Input weights, neurons × inputs (the clock's two counted), row by
    /// row; default 0.
    pub input_weights: Option<Vec<f64>>,
}

impl CtrnnEntry {
    /// The network it describes.
    pub fn build(&self) -> Result<Ctrnn, ModelError> {
        let outputs = self.outputs.len();
        let n = self.neurons.unwrap_or(outputs);
        if n < outputs.max(1) || n > MAX_NEURONS {
            return Err(ModelError::new(
                "neurons",
                format!(
                    "needs at least one neuron per output ({outputs}) and at most {MAX_NEURONS}, got {n}"
                ),
            ));
        }
        let clock = match self.clock {
            Some(f) => Some(positive("clock", f)?),
            None => None,
        };
        let m = self.inputs.len() + if clock.is_some() { 2 } else { 0 };
        if m.saturating_mul(n) > MAX_NEURONS * MAX_NEURONS {
            return Err(ModelError::new(
                "inputs",
                format!("{m} inputs × {n} neurons: more than 10^6 input weights"),
            ));
        }
        let tau = per_neuron("tau", &self.tau, n, 0.1)?;
        if let Some(t) = tau.iter().find(|t| **t <= 0.0) {
            return Err(ModelError::new(
                "tau",
                format!("time constants must be > 0 s, got {t}"),
            ));
        }
        Ok(Ctrnn {
            outputs,
            clock,
            tau,
            bias: per_neuron("bias", &self.bias, n, 0.0)?,
            gain: per_neuron("gain", &self.gain, n, 1.0)?,
            weights: matrix("weights", &self.weights, n, n)?,
            input_weights: matrix("input_weights", &self.input_weights, n, m)?,
            state: vec![0.0; n],
            scratch: (Vec::new(), Vec::new()),
        })
    }
}

fn per_neuron(
    field: &str,
    v: &Option<Vec<f64>>,
    n: usize,
    default: f64,
) -> Result<Vec<f64>, ModelError> {
    match v {
        None => Ok(vec![default; n]),
        Some(_) => matrix(field, v, n, 1),
    }
}

fn matrix(
    field: &str,
    v: &Option<Vec<f64>>,
    rows: usize,
    cols: usize,
) -> Result<Vec<f64>, ModelError> {
    match v {
        None => Ok(vec![0.0; rows * cols]),
        Some(v) if v.len() != rows * cols => Err(ModelError::new(
            field,
            format!(
                "needs {} numbers ({rows} × {cols}), got {}",
                rows * cols,
                v.len()
            ),
        )),
        Some(v) => {
            for x in v {
                finite(field, *x)?;
            }
            Ok(v.clone())
        }
    }
}

/// A CTRNN (see the module).
#[derive(Clone, Debug, PartialEq)]
pub struct Ctrnn {
    /// Outputs driven: neurons `0..outputs`.
    pub outputs: usize,
    /// Clock frequency, Hz, if the clock is on.
    pub clock: Option<f64>,
    /// Time constants, s.
    pub tau: Vec<f64>,
    /// Biases θ.
    pub bias: Vec<f64>,
    /// Gains.
    pub gain: Vec<f64>,
    /// Recurrent weights, row `i` into neuron `i`.
    pub weights: Vec<f64>,
    /// Input weights, row `i` into neuron `i`.
    pub input_weights: Vec<f64>,
    /// The neurons' states `y`.
    pub state: Vec<f64>,
    scratch: (Vec<f64>, Vec<f64>),
}

/// The logistic function.
pub fn sigma(z: f64) -> f64 {
    1.0 / (1.0 + animats_engine::math::exp(-z))
}

impl Ctrnn {
    /// Neurons.
    pub fn neurons(&self) -> usize {
        self.tau.len()
    }

    /// Neuron `i`'s firing rate now.
    pub fn rate(&self, i: usize) -> f64 {
        sigma(self.gain[i] * (self.state[i] + self.bias[i]))
    }
}

impl Brain for Ctrnn {
    fn kind(&self) -> &'static str {
        "ctrnn"
    }

    /// The neurons' states `y`.
    fn save_state(&self) -> Option<crate::kept::Kept> {
        Some(crate::kept::Kept::new(self.state.clone()))
    }

    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        let y: &Vec<f64> = crate::kept::required(kept, "a ctrnn brain")?;
        if y.len() != self.state.len() {
            return Err(format!(
                "a ctrnn brain of {} neurons: the snapshot holds {}",
                self.state.len(),
                y.len()
            ));
        }
        self.state.clone_from(y);
        Ok(())
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    fn think(&mut self, t: f64, dt: f64, inputs: &[f64], outputs: &mut [f64]) {
        let n = self.neurons();
        let (x, rates) = &mut self.scratch;
        network_inputs(x, inputs, self.clock, t);
        // The rates are `sigma` of each neuron (`Ctrnn::rate`), its
        // exponentials a group of neurons at a time: the same bits (perf:
        // one at a time, `exp` was a fifth of a CTRNN walker's run).
        rates.clear();
        rates.extend((0..n).map(|i| self.gain[i] * (self.state[i] + self.bias[i])));
        logistic(rates);
        let m = x.len();
        for i in 0..n {
            let mut drive = 0.0;
            for (w, r) in self.weights[i * n..(i + 1) * n].iter().zip(rates.iter()) {
                drive += w * r;
            }
            for (v, xk) in self.input_weights[i * m..(i + 1) * m].iter().zip(x.iter()) {
                drive += v * xk;
            }
            let h = dt / self.tau[i].max(MIN_TAU);
            self.state[i] = (self.state[i] + h * drive) / (1.0 + h);
        }
        let k = self.outputs.min(outputs.len());
        for (i, out) in outputs[..k].iter_mut().enumerate() {
            *out = self.gain[i] * (self.state[i] + self.bias[i]);
        }
        logistic(&mut outputs[..k]);
    }

    fn genome(&self) -> Vec<f64> {
        let mut g = self.tau.clone();
        g.extend(&self.bias);
        g.extend(&self.gain);
        g.extend(&self.weights);
        g.extend(&self.input_weights);
        g
    }

    fn set_genome(&mut self, g: &[f64]) -> Result<(), String> {
        let n = self.neurons();
        let (nw, nv) = (self.weights.len(), self.input_weights.len());
        check_genome("ctrnn", 3 * n + nw + nv, g)?;
        let (tau, rest) = g.split_at(n);
        let (bias, rest) = rest.split_at(n);
        let (gain, rest) = rest.split_at(n);
        let (weights, input_weights) = rest.split_at(nw);
        self.tau.copy_from_slice(tau);
        self.bias.copy_from_slice(bias);
        self.gain.copy_from_slice(gain);
        self.weights.copy_from_slice(weights);
        self.input_weights.copy_from_slice(input_weights);
        Ok(())
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        let mut b: Vec<(f64, f64)> = self.tau.iter().map(|&t| around(t, 0.01, 2.0)).collect();
        b.extend(self.bias.iter().map(|&x| around(x, -16.0, 16.0)));
        b.extend(self.gain.iter().map(|&x| around(x, 0.0, 5.0)));
        b.extend(self.weights.iter().map(|&x| around(x, -16.0, 16.0)));
        b.extend(self.input_weights.iter().map(|&x| around(x, -16.0, 16.0)));
        b
    }

    fn genome_keys(&self) -> Vec<GenomeKey> {
        let n = self.neurons();
        vec![
            GenomeKey::array("tau", n),
            GenomeKey::array("bias", n),
            GenomeKey::array("gain", n),
            GenomeKey::array("weights", self.weights.len()),
            GenomeKey::array("input_weights", self.input_weights.len()),
        ]
    }

    fn reset(&mut self) {
        self.state.iter_mut().for_each(|y| *y = 0.0);
    }
}
