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
//!
//! Two extensions, both off in the thesis's set-up: with bounds (a scene's
//! genome, whose genes may be 0, where a relative change never moves), a
//! mutation adds `w × 0.1 (lane + 1) (u − 0.5)` for a gene whose bounds are
//! `w` wide and clamps into them; with a population λ > 1 each generation
//! asks λ children of the best and keeps the best of them if it beats it,
//! a (1+λ) scheme.

use super::{check_genomes, check_same, check_told, BestSoFar, Bounds, Optimiser, Random, Setup};
use serde::{Deserialize, Serialize};

/// Hill climbing with the thesis's per-lane mutation size.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HillClimber {
    seed: u64,
    lane: usize,
    best: BestSoFar,
    start: Vec<f64>,
    /// Relative mutation scale: `0.5 (lane + 1)`.
    pub scale: f64,
    bounds: Option<Bounds>,
    population: usize,
    generation: u64,
    pending: Vec<Vec<f64>>,
}

impl HillClimber {
    /// The thesis's climber from `start` for lane `lane` (0-based), drawing
    /// from the streams of `seed`.
    pub fn new(start: Vec<f64>, lane: usize, seed: u64) -> Self {
        HillClimber {
            seed,
            lane,
            best: BestSoFar::default(),
            start,
            scale: 0.5 * (lane as f64 + 1.0),
            bounds: None,
            population: 1,
            generation: 0,
            pending: Vec::new(),
        }
    }

    /// From a [`Setup`] (bounds and population as given).
    pub fn from_setup(s: &Setup) -> Self {
        HillClimber {
            bounds: s.bounds.clone(),
            population: s.population.unwrap_or(1),
            ..HillClimber::new(s.start.clone(), s.lane, s.seed)
        }
    }

    /// A checkpoint's climber against the one its run's configuration
    /// makes (`fresh`): the same set-up, and a best and pending children
    /// of its genome's length.
    pub(crate) fn check_state(&self, fresh: &HillClimber) -> Result<(), String> {
        check_same(
            "its seed and lane",
            &(self.seed, self.lane),
            &(fresh.seed, fresh.lane),
        )?;
        check_same("its start", &self.start, &fresh.start)?;
        check_same("its bounds", &self.bounds, &fresh.bounds)?;
        check_same(
            "its population and mutation scale",
            &(self.population, self.scale),
            &(fresh.population, fresh.scale),
        )?;
        let n = self.start.len();
        self.best.check(Some(n))?;
        if !(self.pending.is_empty() || self.pending.len() == self.population) {
            return Err(format!(
                "{} children pending in a population of {}",
                self.pending.len(),
                self.population
            ));
        }
        check_genomes("pending child", &self.pending, n)
    }

    /// One child of `parent`: Appendix B's mutation (see the module).
    pub fn mutate(&self, parent: &[f64], rng: &mut Random) -> Vec<f64> {
        let mut child = parent.to_vec();
        let n = child.len();
        let mutations = 1 + (3.0 * rng.uniform()).round() as usize;
        for _ in 0..mutations {
            let i = ((n as f64 * rng.uniform()) as usize).min(n - 1);
            match &self.bounds {
                None => child[i] += child[i] * self.scale * (rng.uniform() - 0.5),
                Some(b) => {
                    child[i] += b.width(i) * 0.2 * self.scale * (rng.uniform() - 0.5);
                    child[i] = child[i].clamp(b.lo[i], b.hi[i]);
                }
            }
        }
        child
    }
}

impl Optimiser for HillClimber {
    fn ask(&mut self) -> Vec<Vec<f64>> {
        let generation = self.generation + 1;
        let mut rng = Random::for_evaluation(self.seed, self.lane, generation);
        let parent = match self.best.get() {
            Some((b, _)) => b.to_vec(),
            None => self.start.clone(),
        };
        let mut out = Vec::with_capacity(self.population);
        if self.generation == 0 {
            out.push(parent.clone());
        }
        while out.len() < self.population {
            out.push(self.mutate(&parent, &mut rng));
        }
        self.pending = out.clone();
        out
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<(), String> {
        check_told(self.pending.len(), fitness.len())?;
        // The best child replaces the parent only if strictly better.
        let mut top: Option<(usize, f64)> = None;
        for (i, &f) in fitness.iter().enumerate() {
            let f = crate::optimiser::sane(f);
            if top.is_none_or(|(_, t)| f > t) {
                top = Some((i, f));
            }
        }
        if let Some((i, f)) = top {
            self.best.offer(&self.pending[i], f);
        }
        self.pending.clear();
        self.generation += 1;
        Ok(())
    }

    fn best(&self) -> Option<(&[f64], f64)> {
        self.best.get()
    }

    fn generation(&self) -> u64 {
        self.generation
    }
}
