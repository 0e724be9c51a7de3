//! A generational genetic algorithm over real genomes: the thesis suggests
//! crossover would help its evolver (§5.4); this is the plain, standard one.
//!
//! - Generation 1 is the starting genome and `P − 1` Gaussian perturbations
//!   of it (σ a quarter of each gene's bounds' width, or of its magnitude, at
//!   least 0.1, when unbounded), clamped into the bounds.
//! - Each later generation keeps the best `max(1, P/10)` unchanged
//!   (elitism) and fills the rest with children: two parents, each the
//!   winner of a tournament of 3 drawn with replacement; uniform crossover
//!   (each gene from either parent, probability ½) with probability 0.9,
//!   else a copy of the first parent; then each gene mutates with
//!   probability `1/D` (at least one gene always does) by a Gaussian of σ a
//!   tenth of its bounds' width (or of its magnitude, at least 0.1, when
//!   unbounded), clamped into the bounds.

use super::{
    check_genomes, check_same, check_told, gaussian, sane, BestSoFar, Bounds, Optimiser, Random,
    Setup,
};
use serde::{Deserialize, Serialize};

/// Tournament size.
pub const TOURNAMENT: usize = 3;
/// Probability of crossover.
pub const CROSSOVER: f64 = 0.9;

/// A generational GA.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ga {
    seed: u64,
    lane: usize,
    start: Vec<f64>,
    bounds: Option<Bounds>,
    size: usize,
    generation: u64,
    /// The population last asked (or evaluated), with fitness once told.
    population: Vec<Vec<f64>>,
    fitness: Vec<f64>,
    asked: bool,
    best: BestSoFar,
}

impl Ga {
    /// A GA from a setup (population default 32).
    pub fn new(s: &Setup) -> Ga {
        Ga {
            seed: s.seed,
            lane: s.lane,
            start: s.start.clone(),
            bounds: s.bounds.clone(),
            size: s.population.unwrap_or(32).max(2),
            generation: 0,
            population: Vec::new(),
            fitness: Vec::new(),
            asked: false,
            best: BestSoFar::default(),
        }
    }

    /// A checkpoint's GA against the one its run's configuration makes
    /// (`fresh`): the same set-up; a population of its size once asked,
    /// with a fitness each once told.
    pub(crate) fn check_state(&self, fresh: &Ga) -> Result<(), String> {
        check_same(
            "its seed and lane",
            &(self.seed, self.lane),
            &(fresh.seed, fresh.lane),
        )?;
        check_same("its start", &self.start, &fresh.start)?;
        check_same("its bounds", &self.bounds, &fresh.bounds)?;
        check_same("its population's size", &self.size, &fresh.size)?;
        let n = self.start.len();
        self.best.check(Some(n))?;
        let (asked, told) = (self.population.len(), self.fitness.len());
        let whole = asked == self.size;
        let fine = if self.asked {
            whole && told == 0
        } else if self.generation > 0 {
            whole && told == asked
        } else {
            told == 0
        };
        if !fine {
            return Err(format!(
                "a population of {asked} with {told} fitnesses, at generation {} of a GA of {}",
                self.generation, self.size
            ));
        }
        check_genomes("individual", &self.population, n)
    }

    fn spread(&self, i: usize, x: f64, fraction: f64) -> f64 {
        match &self.bounds {
            Some(b) => b.width(i) * fraction,
            None => x.abs().max(0.1) * fraction,
        }
    }

    fn clamp(&self, x: &mut [f64]) {
        if let Some(b) = &self.bounds {
            b.clamp(x);
        }
    }

    fn tournament(&self, rng: &mut Random) -> usize {
        let n = self.population.len();
        let mut winner = None::<usize>;
        for _ in 0..TOURNAMENT {
            let i = ((n as f64 * rng.uniform()) as usize).min(n - 1);
            if winner.is_none_or(|w| self.fitness[i] > self.fitness[w]) {
                winner = Some(i);
            }
        }
        winner.unwrap_or(0)
    }

    fn first_generation(&self, rng: &mut Random) -> Vec<Vec<f64>> {
        let mut out = vec![self.start.clone()];
        while out.len() < self.size {
            let mut x: Vec<f64> = self
                .start
                .iter()
                .enumerate()
                .map(|(i, &v)| v + self.spread(i, v, 0.25) * gaussian(rng))
                .collect();
            self.clamp(&mut x);
            out.push(x);
        }
        out
    }

    fn next_generation(&self, rng: &mut Random) -> Vec<Vec<f64>> {
        let n = self.population.len();
        let d = self.start.len();
        let mut order: Vec<usize> = (0..n).collect();
        // Best first; ties by index, so the order is the same on every run.
        order.sort_by(|&a, &b| self.fitness[b].total_cmp(&self.fitness[a]).then(a.cmp(&b)));
        let elite = (self.size / 10).max(1);
        let mut out: Vec<Vec<f64>> = order
            .iter()
            .take(elite)
            .map(|&i| self.population[i].clone())
            .collect();
        while out.len() < self.size {
            let a = &self.population[self.tournament(rng)];
            let b = &self.population[self.tournament(rng)];
            let mut child: Vec<f64> = if rng.uniform() < CROSSOVER {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| if rng.uniform() < 0.5 { *x } else { *y })
                    .collect()
            } else {
                a.clone()
            };
            let forced = ((d as f64 * rng.uniform()) as usize).min(d - 1);
            for (i, x) in child.iter_mut().enumerate() {
                if i == forced || rng.uniform() < 1.0 / d as f64 {
                    *x += self.spread(i, *x, 0.1) * gaussian(rng);
                }
            }
            self.clamp(&mut child);
            out.push(child);
        }
        out
    }
}

impl Optimiser for Ga {
    fn ask(&mut self) -> Vec<Vec<f64>> {
        let generation = self.generation + 1;
        let mut rng = Random::for_evaluation(self.seed, self.lane, generation);
        self.population = if self.generation == 0 {
            self.first_generation(&mut rng)
        } else {
            self.next_generation(&mut rng)
        };
        self.fitness.clear();
        self.asked = true;
        self.population.clone()
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<(), String> {
        check_told(
            if self.asked { self.population.len() } else { 0 },
            fitness.len(),
        )?;
        self.fitness = fitness.iter().map(|f| sane(*f)).collect();
        for (x, f) in self.population.iter().zip(&self.fitness) {
            self.best.offer(x, *f);
        }
        self.asked = false;
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
