//! A (μ + λ) genetic algorithm over bodies: genomes whose length and
//! meaning change as they vary (a `[morphology]` scene's), varied by the
//! problem's own operators ([`Variation`]) and checked before they are
//! evaluated.
//!
//! - Generation 1: the scene's starting body and `P − 1` mutants of it, or
//!   `P` random bodies.
//! - Each later generation: `P` children, each from its own random stream
//!   (so they are made in parallel, the same bits on any thread): with
//!   probability [`CROSSOVER`] a crossover of two parents, else a mutant
//!   of one, each parent the winner of a tournament of [`TOURNAMENT`].
//! - Every child is checked; a refused variation is retried up to
//!   `RETRIES` times (EvoGym's rule), then the parent is kept in its
//!   place. Refusals are counted by reason.
//! - Parents and children together, best first (parents first among
//!   equals), the best `P` survive.

use super::{check_body, check_same, check_told, sane, BestSoFar, Random};
use crate::screen::Screen;
use animats_scene::morphology::vary::RETRIES;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Tournament size.
pub const TOURNAMENT: usize = 2;
/// Probability that a child is a crossover.
pub const CROSSOVER: f64 = 0.25;
/// Default population.
pub const POPULATION: usize = 16;
/// Tries a random first-generation body gets before it is taken as it is
/// (it has no parent to fall back on).
const RANDOM_TRIES: usize = 100;

/// What a body GA needs of its problem: random bodies, variation and the
/// checks.
pub trait Variation: Sync {
    /// The scene's starting body, if it names one.
    fn start(&self) -> Option<Vec<f64>>;
    /// A random body.
    fn random(&self, rng: &mut Random) -> Vec<f64>;
    /// A mutant of `parent`.
    fn mutate(&self, parent: &[f64], rng: &mut Random) -> Vec<f64>;
    /// A child of `a` and `b`.
    fn crossover(&self, a: &[f64], b: &[f64], rng: &mut Random) -> Vec<f64>;
    /// Whether `genome` may be evaluated; if not, the reason's name.
    fn check(&self, genome: &[f64]) -> Result<(), &'static str>;
    /// Hears how long making each child of a generation took, s (in the
    /// children's order), and the wall time of making them all on the
    /// pool's threads: for the schedule model (`evolve --schedule`).
    fn made(&self, _children: &[f64], _wall: f64) {}
}

/// Makes `n` children with `make(i)` on the current pool, each timed, and
/// tells `variation` the times ([`Variation::made`]).
pub(crate) fn make_children(
    variation: &dyn Variation,
    n: usize,
    make: impl Fn(usize) -> Made + Sync,
) -> Vec<Made> {
    let began = std::time::Instant::now();
    let timed: Vec<(Made, f64)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let t = std::time::Instant::now();
            let m = make(i);
            (m, t.elapsed().as_secs_f64())
        })
        .collect();
    let seconds: Vec<f64> = timed.iter().map(|t| t.1).collect();
    variation.made(&seconds, began.elapsed().as_secs_f64());
    timed.into_iter().map(|t| t.0).collect()
}

/// A body GA's state: what a checkpoint holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodyGa {
    seed: u64,
    lane: usize,
    size: usize,
    generation: u64,
    /// The survivors, best first, with their fitness.
    parents: Vec<(Vec<f64>, f64)>,
    /// The children last asked.
    asked: Vec<Vec<f64>>,
    best: BestSoFar,
    /// Refused variations so far, by reason.
    refused: BTreeMap<String, u64>,
    /// Children that fell back to their parent after every retry failed.
    kept: u64,
}

/// One child and the refusals it took to make.
pub(crate) struct Made {
    pub(crate) genome: Vec<f64>,
    pub(crate) refused: Vec<&'static str>,
    pub(crate) kept: bool,
}

/// A child made by `make`, checked and retried up to `RETRIES` times;
/// `parent` if every try is refused.
pub(crate) fn vary(
    variation: &dyn Variation,
    rng: &mut Random,
    make: impl Fn(&dyn Variation, &mut Random) -> Vec<f64>,
    parent: &[f64],
) -> Made {
    let mut refused = Vec::new();
    for _ in 0..=RETRIES {
        let g = make(variation, rng);
        match variation.check(&g) {
            Ok(()) => {
                return Made {
                    genome: g,
                    refused,
                    kept: false,
                }
            }
            Err(r) => refused.push(r),
        }
    }
    Made {
        genome: parent.to_vec(),
        refused,
        kept: true,
    }
}

/// A random body, checked: retried up to [`RANDOM_TRIES`] times, then taken
/// as it is (it has no parent to fall back on).
pub(crate) fn random_body(variation: &dyn Variation, rng: &mut Random) -> Made {
    let mut refused = Vec::new();
    let mut genome = variation.random(rng);
    for _ in 1..RANDOM_TRIES {
        match variation.check(&genome) {
            Ok(()) => break,
            Err(r) => refused.push(r),
        }
        genome = variation.random(rng);
    }
    Made {
        genome,
        refused,
        kept: false,
    }
}

impl BodyGa {
    /// A body GA of `population` (default [`POPULATION`]) for `lane` of a
    /// run seeded `seed`.
    pub fn new(seed: u64, lane: usize, population: Option<usize>) -> BodyGa {
        BodyGa {
            seed,
            lane,
            size: population.unwrap_or(POPULATION).max(2),
            generation: 0,
            parents: Vec::new(),
            asked: Vec::new(),
            best: BestSoFar::default(),
            refused: BTreeMap::new(),
            kept: 0,
        }
    }

    /// A checkpoint's body GA against the one its run's configuration
    /// makes (`fresh`): the same set-up; at most its size in parents and
    /// none or all of its children asked, each a body `variation`
    /// accepts.
    pub(crate) fn check_state(
        &self,
        fresh: &BodyGa,
        variation: Option<&dyn Variation>,
    ) -> Result<(), String> {
        check_same(
            "its seed and lane",
            &(self.seed, self.lane),
            &(fresh.seed, fresh.lane),
        )?;
        check_same("its population's size", &self.size, &fresh.size)?;
        if self.parents.len() > self.size
            || !(self.asked.is_empty() || self.asked.len() == self.size)
        {
            return Err(format!(
                "{} parents and {} children asked in a population of {}",
                self.parents.len(),
                self.asked.len(),
                self.size
            ));
        }
        for (k, (g, f)) in self.parents.iter().enumerate() {
            if f.is_nan() {
                return Err(format!("parent {k}'s fitness is not a number"));
            }
            check_body(&format!("parent {k}"), g, variation)?;
        }
        for (k, g) in self.asked.iter().enumerate() {
            check_body(&format!("child {k}"), g, variation)?;
        }
        self.best.check(None)?;
        if let Some((g, _)) = self.best.get() {
            check_body("the best", g, variation)?;
        }
        Ok(())
    }

    /// The next generation's children, made and checked by `variation`.
    pub fn ask(&mut self, variation: &dyn Variation) -> Vec<Vec<f64>> {
        let start = variation.start();
        let made = make_children(variation, self.size, |i| {
            let mut rng = Random::for_child(self.seed, self.lane, self.generation, i as u64);
            match (&start, self.parents.is_empty()) {
                (Some(s), true) if i == 0 => Made {
                    genome: s.clone(),
                    refused: Vec::new(),
                    kept: false,
                },
                (Some(s), true) => vary(variation, &mut rng, |v, r| v.mutate(s, r), s),
                (None, true) => random_body(variation, &mut rng),
                (_, false) => self.child(variation, &mut rng),
            }
        });
        self.asked = Vec::with_capacity(made.len());
        for m in made {
            for r in m.refused {
                *self.refused.entry(r.to_string()).or_insert(0) += 1;
            }
            self.kept += m.kept as u64;
            self.asked.push(m.genome);
        }
        self.asked.clone()
    }

    fn tournament(&self, rng: &mut Random) -> usize {
        let n = self.parents.len();
        let mut winner = ((rng.uniform() * n as f64) as usize).min(n - 1);
        for _ in 1..TOURNAMENT {
            let other = ((rng.uniform() * n as f64) as usize).min(n - 1);
            // Parents are sorted best first: the lower index wins.
            winner = winner.min(other);
        }
        winner
    }

    fn child(&self, variation: &dyn Variation, rng: &mut Random) -> Made {
        let a = self.tournament(rng);
        let parent = &self.parents[a].0;
        if rng.uniform() < CROSSOVER {
            let b = self.tournament(rng);
            let other = &self.parents[b].0;
            vary(
                variation,
                rng,
                |v, r| {
                    let c = v.crossover(parent, other, r);
                    v.mutate(&c, r)
                },
                parent,
            )
        } else {
            vary(variation, rng, |v, r| v.mutate(parent, r), parent)
        }
    }

    /// Which children need a robust scene's half-step run: once the
    /// population is full, those above its worst (a child at or below it
    /// cannot survive: parents win ties).
    pub fn screen(&self) -> Screen {
        match self.parents.last() {
            Some(&(_, bar)) if self.parents.len() == self.size => Screen::Above { bar },
            _ => Screen::All,
        }
    }

    /// Takes the children's fitness; the best `P` of parents and children
    /// survive.
    pub fn tell(&mut self, fitness: &[f64]) -> Result<(), String> {
        check_told(self.asked.len(), fitness.len())?;
        let children = std::mem::take(&mut self.asked);
        for (g, &f) in children.iter().zip(fitness) {
            self.best.offer(g, f);
        }
        let mut all = std::mem::take(&mut self.parents);
        all.extend(children.into_iter().zip(fitness.iter().map(|&f| sane(f))));
        // Stable: parents (first in `all`) stay ahead of equal children.
        all.sort_by(|x, y| y.1.total_cmp(&x.1));
        all.truncate(self.size);
        self.parents = all;
        self.generation += 1;
        Ok(())
    }

    /// The best body so far.
    pub fn best(&self) -> Option<(&[f64], f64)> {
        self.best.get()
    }

    /// Generations told.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Refused variations so far, by reason.
    pub fn refused(&self) -> &BTreeMap<String, u64> {
        &self.refused
    }

    /// Refused variations so far, all reasons.
    pub fn refused_total(&self) -> u64 {
        self.refused.values().sum()
    }

    /// Children that fell back to their parent.
    pub fn kept(&self) -> u64 {
        self.kept
    }

    /// The survivors, best first.
    pub fn parents(&self) -> &[(Vec<f64>, f64)] {
        &self.parents
    }
}
