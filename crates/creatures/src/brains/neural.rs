//! A feed-forward neural network: tanh hidden layers, logistic outputs in
//! [0, 1].
//!
//! Inputs are the sensor levels mapped from [0, 1] onto [−1, 1] (`2x − 1`,
//! so that a level of 0.5 is no signal), then, with a clock of frequency
//! `f`, `sin 2πft` and `cos 2πft`. Each layer computes
//! `y_j = act(b_j + Σ_i w_ji x_i)`.
//!
//! Genome (the scene's `weights`): layer by layer from the inputs, for each
//! layer its weights row by row (`w_j0, w_j1, ...` for neuron j), then its
//! biases. Bounds: [−10, 10] each, widened to contain the value given.

use crate::brain::{around, check_genome, network_inputs, positive, Brain, GenomeKey};
use crate::random::Random;
use animats_engine::ModelError;
use serde::Deserialize;

/// `[[controller]] kind = "neural"`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NeuralEntry {
    /// Unique among controllers.
    pub name: String,
    /// Sensors read, by name.
    #[serde(default)]
    pub inputs: Vec<String>,
    /// Actuators driven, by name.
    pub outputs: Vec<String>,
    /// Hidden layer sizes; default none.
    pub hidden: Option<Vec<usize>>,
    /// Frequency of the clock inputs, Hz; default no clock.
    pub clock: Option<f64>,
    /// Every weight and bias, layer by layer; default random.
    pub weights: Option<Vec<f64>>,
    /// Seed of the default random weights; default 1.
    pub seed: Option<u64>,
}

/// Each `a` in `y` becomes `1 / (1 + e^−a)`, libm's `exp` a group of
/// outputs at a time (the same bits as one at a time; lanes past the last
/// repeat the group's first). A CTRNN's rates are this too.
pub(crate) fn logistic(y: &mut [f64]) {
    use animats_engine::math::{exp_lanes, LANES};
    for group in y.chunks_mut(LANES) {
        let e = exp_lanes(std::array::from_fn(|k| {
            -group[if k < group.len() { k } else { 0 }]
        }));
        for (a, e) in group.iter_mut().zip(e) {
            *a = 1.0 / (1.0 + e);
        }
    }
}

/// The most weights and biases a network may have.
pub const MAX_WEIGHTS: usize = 1_000_000;

impl NeuralEntry {
    /// The network it describes, its weights given or drawn from `seed`.
    pub fn build(&self) -> Result<Neural, ModelError> {
        let hidden = self.hidden.clone().unwrap_or_default();
        if hidden.iter().any(|h| *h == 0 || *h > 4096) || hidden.len() > 16 {
            return Err(ModelError::new(
                "hidden",
                "up to 16 layers of 1 to 4096 neurons each",
            ));
        }
        let clock = match self.clock {
            Some(f) => Some(positive("clock", f)?),
            None => None,
        };
        if self.inputs.is_empty() && clock.is_none() {
            return Err(ModelError::new(
                "inputs",
                "a neural controller needs inputs, a clock, or both",
            ));
        }
        // Counted before anything is allocated.
        let mut sizes = vec![self.inputs.len() + if clock.is_some() { 2 } else { 0 }];
        sizes.extend(&hidden);
        sizes.push(self.outputs.len());
        let count = Neural::weight_count(&sizes);
        if count > MAX_WEIGHTS {
            return Err(ModelError::new(
                "hidden",
                format!("{count} weights and biases: more than the limit of 1,000,000"),
            ));
        }
        let mut net = Neural::new(self.inputs.len(), &hidden, self.outputs.len(), clock);
        match &self.weights {
            Some(w) => net.set_genome(w).map_err(|_| {
                ModelError::new(
                    "weights",
                    format!(
                        "needs {} finite numbers (layers {:?}: every weight, then the biases, layer by layer), got {}",
                        net.weights.len(),
                        net.sizes,
                        w.len()
                    ),
                )
            })?,
            None => net.randomise(self.seed.unwrap_or(1)),
        }
        Ok(net)
    }
}

/// A multilayer perceptron.
#[derive(Clone, Debug, PartialEq)]
pub struct Neural {
    /// Layer sizes, inputs (clock included) first, outputs last.
    pub sizes: Vec<usize>,
    /// Clock frequency, Hz, if the clock is on.
    pub clock: Option<f64>,
    /// Every weight and bias (see the module for the order).
    pub weights: Vec<f64>,
    scratch: (Vec<f64>, Vec<f64>),
}

impl Neural {
    /// A network with `inputs` sensor inputs, `hidden` layers and `outputs`
    /// outputs; the weights are zero (see [`Neural::randomise`]).
    pub fn new(inputs: usize, hidden: &[usize], outputs: usize, clock: Option<f64>) -> Neural {
        let mut sizes = vec![inputs + if clock.is_some() { 2 } else { 0 }];
        sizes.extend(hidden);
        sizes.push(outputs);
        let n = Neural::weight_count(&sizes);
        Neural {
            sizes,
            clock,
            weights: vec![0.0; n],
            scratch: (Vec::new(), Vec::new()),
        }
    }

    /// Weights and biases of a network with these layer sizes.
    pub fn weight_count(sizes: &[usize]) -> usize {
        sizes.windows(2).map(|w| w[1] * (w[0] + 1)).sum()
    }

    /// Small random weights from `seed`: uniform in ±1/√(fan-in), biases 0.
    pub fn randomise(&mut self, seed: u64) {
        let mut rng = Random::for_entry(seed, 0x6e65_7572);
        let mut k = 0;
        for w in self.sizes.windows(2) {
            let scale = 1.0 / (w[0].max(1) as f64).sqrt();
            for _ in 0..w[1] * w[0] {
                self.weights[k] = scale * (2.0 * rng.uniform() - 1.0);
                k += 1;
            }
            for _ in 0..w[1] {
                self.weights[k] = 0.0;
                k += 1;
            }
        }
    }
}

impl Brain for Neural {
    fn kind(&self) -> &'static str {
        "neural"
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    fn think(&mut self, t: f64, _dt: f64, inputs: &[f64], outputs: &mut [f64]) {
        let (x, y) = &mut self.scratch;
        network_inputs(x, inputs, self.clock, t);
        let layers = self.sizes.len() - 1;
        let mut k = 0;
        for (l, s) in self.sizes.windows(2).enumerate() {
            let (n_in, n_out) = (s[0], s[1]);
            let biases = k + n_out * n_in;
            y.clear();
            for j in 0..n_out {
                let row = &self.weights[k + j * n_in..k + (j + 1) * n_in];
                let mut a = self.weights[biases + j];
                for (w, xi) in row.iter().zip(x.iter()) {
                    a += w * xi;
                }
                y.push(if l + 1 == layers {
                    a
                } else {
                    animats_engine::math::tanh(a)
                });
            }
            if l + 1 == layers {
                logistic(y);
            }
            k = biases + n_out;
            std::mem::swap(x, y);
        }
        outputs.copy_from_slice(&x[..outputs.len()]);
    }

    fn genome(&self) -> Vec<f64> {
        self.weights.clone()
    }

    fn set_genome(&mut self, g: &[f64]) -> Result<(), String> {
        check_genome("neural", self.weights.len(), g)?;
        self.weights.copy_from_slice(g);
        Ok(())
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        self.weights
            .iter()
            .map(|&w| around(w, -10.0, 10.0))
            .collect()
    }

    fn genome_keys(&self) -> Vec<GenomeKey> {
        vec![GenomeKey::array("weights", self.weights.len())]
    }
}
