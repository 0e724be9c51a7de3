//! The thesis's evolver (§3.2.1.6, Appendix B `HopEvolver`): selection and
//! mutation only. Keep the best parameter set; each generation mutate 1 to 4
//! randomly chosen parameters by a random relative amount; keep the child if
//! it scores higher.
//!
//! Exactly as Appendix B: the number of mutations is `1 + round(3u)` (1 and 4
//! with probability 1/6, 2 and 3 with 1/3), each picks parameter
//! `floor(n u)` (repeats allowed) and adds `p × 0.5 (lane + 1) (u - 0.5)`, so
//! lane k changes a parameter by up to ±25 (k + 1) %: later lanes explore
//! more boldly. The first candidate asked is the starting set itself.

use crate::optimiser::Optimiser;
use animats_creatures::random::Random;

/// Hill climbing with the thesis's per-lane mutation size.
#[derive(Clone, Debug, PartialEq)]
pub struct HillClimber {
    best: Vec<f64>,
    best_fitness: f64,
    /// Relative mutation scale: `0.5 (lane + 1)`.
    pub scale: f64,
    started: bool,
}

impl HillClimber {
    /// A climber starting from `start` for lane `lane` (0-based).
    pub fn new(start: Vec<f64>, lane: usize) -> Self {
        HillClimber {
            best: start,
            best_fitness: f64::NEG_INFINITY,
            scale: 0.5 * (lane as f64 + 1.0),
            started: false,
        }
    }

    /// Continues from a known best (a resumed run).
    pub fn resume(best: Vec<f64>, best_fitness: f64, lane: usize) -> Self {
        HillClimber {
            best,
            best_fitness,
            scale: 0.5 * (lane as f64 + 1.0),
            started: true,
        }
    }
}

impl Optimiser for HillClimber {
    fn ask(&mut self, rng: &mut Random) -> Vec<f64> {
        let mut child = self.best.clone();
        if !self.started {
            self.started = true;
            return child;
        }
        let n = child.len();
        let mutations = 1 + (3.0 * rng.uniform()).round() as usize;
        for _ in 0..mutations {
            let i = ((n as f64 * rng.uniform()) as usize).min(n - 1);
            child[i] += child[i] * self.scale * (rng.uniform() - 0.5);
        }
        child
    }

    fn tell(&mut self, candidate: &[f64], fitness: f64) -> bool {
        if fitness > self.best_fitness {
            self.best = candidate.to_vec();
            self.best_fitness = fitness;
            true
        } else {
            false
        }
    }

    fn best(&self) -> (&[f64], f64) {
        (&self.best, self.best_fitness)
    }
}
