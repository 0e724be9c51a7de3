//! A central pattern generator: one sine per output at a shared frequency,
//! `level_i = offset_i + amplitude_i sin(2π f t + phase_i)`, clamped to
//! [0, 1] by the caller. Blind: it reads no sensors.
//!
//! Genome: `[f, amplitude_0..n, phase_0..n, offset_0..n]`. Bounds:
//! f in [0, 5] Hz, amplitudes and offsets in [0, 1], phases in [−π, π],
//! each widened to contain the value the scene gives.

use crate::brain::{around, check_genome, finite, per_output, Brain, GenomeKey};
use animats_engine::ModelError;
use serde::Deserialize;
use std::f64::consts::{PI, TAU};

/// `[[controller]] kind = "oscillator"`: blind, so it takes no `inputs`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OscillatorEntry {
    /// Unique among controllers.
    pub name: String,
    /// Actuators driven, by name.
    pub outputs: Vec<String>,
    /// Hz, >= 0; default 1.
    pub frequency: Option<f64>,
    /// One per output; default 0.25.
    pub amplitude: Option<Vec<f64>>,
    /// rad, one per output; default 0.
    pub phase: Option<Vec<f64>>,
    /// One per output; default 0.5.
    pub offset: Option<Vec<f64>>,
}

impl OscillatorEntry {
    /// The oscillator it describes.
    pub fn build(&self) -> Result<Oscillator, ModelError> {
        let n = self.outputs.len();
        let frequency = finite("frequency", self.frequency.unwrap_or(1.0))?;
        if frequency < 0.0 {
            return Err(ModelError::new(
                "frequency",
                format!("must be >= 0, got {frequency}"),
            ));
        }
        Ok(Oscillator {
            frequency,
            amplitude: per_output("amplitude", &self.amplitude, n, 0.25)?,
            phase: per_output("phase", &self.phase, n, 0.0)?,
            offset: per_output("offset", &self.offset, n, 0.5)?,
        })
    }
}

/// Sines at one frequency.
#[derive(Clone, Debug, PartialEq)]
pub struct Oscillator {
    /// Hz.
    pub frequency: f64,
    /// Per output.
    pub amplitude: Vec<f64>,
    /// Per output, rad.
    pub phase: Vec<f64>,
    /// Per output.
    pub offset: Vec<f64>,
}

impl Oscillator {
    /// Outputs driven.
    pub fn outputs(&self) -> usize {
        self.amplitude.len()
    }
}

impl Brain for Oscillator {
    fn kind(&self) -> &'static str {
        "oscillator"
    }

    fn think(&mut self, t: f64, _dt: f64, _inputs: &[f64], outputs: &mut [f64]) {
        let w = TAU * self.frequency * t;
        for (i, out) in outputs.iter_mut().enumerate() {
            // libm: the same bits on every platform (reproducible evolution).
            *out =
                self.offset[i] + self.amplitude[i] * animats_engine::math::sin(w + self.phase[i]);
        }
    }

    fn genome(&self) -> Vec<f64> {
        let mut g = vec![self.frequency];
        g.extend(&self.amplitude);
        g.extend(&self.phase);
        g.extend(&self.offset);
        g
    }

    fn set_genome(&mut self, g: &[f64]) -> Result<(), String> {
        let n = self.outputs();
        check_genome("oscillator", 1 + 3 * n, g)?;
        self.frequency = g[0];
        self.amplitude.copy_from_slice(&g[1..1 + n]);
        self.phase.copy_from_slice(&g[1 + n..1 + 2 * n]);
        self.offset.copy_from_slice(&g[1 + 2 * n..]);
        Ok(())
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        let mut b = vec![around(self.frequency, 0.0, 5.0)];
        b.extend(self.amplitude.iter().map(|&a| around(a, 0.0, 1.0)));
        b.extend(self.phase.iter().map(|&p| around(p, -PI, PI)));
        b.extend(self.offset.iter().map(|&o| around(o, 0.0, 1.0)));
        b
    }

    fn genome_keys(&self) -> Vec<GenomeKey> {
        let n = self.outputs();
        vec![
            GenomeKey::number("frequency"),
            GenomeKey::array("amplitude", n),
            GenomeKey::array("phase", n),
            GenomeKey::array("offset", n),
        ]
    }
}
