//! A central pattern generator: one sine per output at a shared frequency,
//! `level_i = offset_i + amplitude_i sin(2π f t + phase_i)`, clamped to
//! [0, 1] by the caller. Blind: it reads no sensors.
//!
//! With `duty`, each output's wave is skewed: its level rises from trough
//! to crest in the share `duty_i` of a cycle and falls back in the rest
//! (a fast stroke and a slow return, as a jellyfish's pulse). With
//! `u = frac(f t + (phase_i + π/2)/2π)`, the time since the trough in
//! cycles, the level is `offset_i + amplitude_i sin ψ` with
//! `ψ = −π/2 + π u/duty_i` while `u < duty_i`, else
//! `ψ = π/2 + π (u − duty_i)/(1 − duty_i)`: duty ½ is the sine itself.
//!
//! Genome: `[f, amplitude_0..n, phase_0..n, offset_0..n]`, then
//! `duty_0..n` if the scene gives `duty`. Bounds: f in [0, 5] Hz,
//! amplitudes and offsets in [0, 1], phases in [−π, π], duties in
//! [0.1, 0.9], each widened to contain the value the scene gives.

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
    /// One per output, each in (0, 1): the share of a cycle the level
    /// spends rising. Absent: the sine (and no duty genes).
    pub duty: Option<Vec<f64>>,
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
        let duty = match &self.duty {
            None => None,
            Some(_) => {
                let d = per_output("duty", &self.duty, n, 0.5)?;
                if let Some(x) = d.iter().find(|&&x| !(x > 0.0 && x < 1.0)) {
                    return Err(ModelError::new(
                        "duty",
                        format!("each must be strictly between 0 and 1, got {x}"),
                    ));
                }
                Some(d)
            }
        };
        Ok(Oscillator {
            frequency,
            amplitude: per_output("amplitude", &self.amplitude, n, 0.25)?,
            phase: per_output("phase", &self.phase, n, 0.0)?,
            offset: per_output("offset", &self.offset, n, 0.5)?,
            duty,
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
    /// Per output, in (0, 1): the share of a cycle spent rising; `None`,
    /// the sine.
    pub duty: Option<Vec<f64>>,
}

/// The skewed wave's angle (see the module): `u` cycles since the trough,
/// rising for the share `duty` of a cycle.
pub fn skewed_angle(u: f64, duty: f64) -> f64 {
    use std::f64::consts::FRAC_PI_2;
    if u < duty {
        -FRAC_PI_2 + PI * (u / duty)
    } else {
        FRAC_PI_2 + PI * ((u - duty) / (1.0 - duty))
    }
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
        if let Some(duty) = &self.duty {
            let ft = self.frequency * t;
            for (i, out) in outputs.iter_mut().enumerate() {
                let c = ft + (self.phase[i] + 0.5 * PI) / TAU;
                let psi = skewed_angle(c - c.floor(), duty[i]);
                *out = self.offset[i] + self.amplitude[i] * animats_engine::math::sin(psi);
            }
            return;
        }
        use animats_engine::math::{sin_lanes, LANES};
        let w = TAU * self.frequency * t;
        // libm's sine (the same bits on every platform: reproducible
        // evolution), a group of outputs at a time; lanes past the last
        // output repeat the group's first.
        for (g, group) in outputs.chunks_mut(LANES).enumerate() {
            let at = |k: usize| w + self.phase[g * LANES + if k < group.len() { k } else { 0 }];
            let s = sin_lanes(std::array::from_fn(at));
            for (k, out) in group.iter_mut().enumerate() {
                let i = g * LANES + k;
                *out = self.offset[i] + self.amplitude[i] * s[k];
            }
        }
    }

    fn genome(&self) -> Vec<f64> {
        let mut g = vec![self.frequency];
        g.extend(&self.amplitude);
        g.extend(&self.phase);
        g.extend(&self.offset);
        if let Some(d) = &self.duty {
            g.extend(d);
        }
        g
    }

    fn set_genome(&mut self, g: &[f64]) -> Result<(), String> {
        let n = self.outputs();
        let per = if self.duty.is_some() { 4 } else { 3 };
        check_genome("oscillator", 1 + per * n, g)?;
        if let Some(d) = &mut self.duty {
            let genes = &g[1 + 3 * n..];
            if let Some(x) = genes.iter().find(|&&x| !(x > 0.0 && x < 1.0)) {
                return Err(format!(
                    "oscillator: a duty gene must be strictly between 0 and 1, got {x}"
                ));
            }
            d.copy_from_slice(genes);
        }
        self.frequency = g[0];
        self.amplitude.copy_from_slice(&g[1..1 + n]);
        self.phase.copy_from_slice(&g[1 + n..1 + 2 * n]);
        self.offset.copy_from_slice(&g[1 + 2 * n..1 + 3 * n]);
        Ok(())
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        let mut b = vec![around(self.frequency, 0.0, 5.0)];
        b.extend(self.amplitude.iter().map(|&a| around(a, 0.0, 1.0)));
        b.extend(self.phase.iter().map(|&p| around(p, -PI, PI)));
        b.extend(self.offset.iter().map(|&o| around(o, 0.0, 1.0)));
        if let Some(d) = &self.duty {
            b.extend(d.iter().map(|&x| around(x, 0.1, 0.9)));
        }
        b
    }

    fn genome_keys(&self) -> Vec<GenomeKey> {
        let n = self.outputs();
        let mut keys = vec![
            GenomeKey::number("frequency"),
            GenomeKey::array("amplitude", n),
            GenomeKey::array("phase", n),
            GenomeKey::array("offset", n),
        ];
        if self.duty.is_some() {
            keys.push(GenomeKey::array("duty", n));
        }
        keys
    }
}
