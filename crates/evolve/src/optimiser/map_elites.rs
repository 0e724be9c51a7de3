//! Quality-diversity search: an archive of elites ([`GridArchive`]) filled
//! by emitters, as pyribs's `Scheduler` runs them: each generation every
//! emitter asks its batch, the whole generation is evaluated, added to the
//! archive in one batch (every status against the archive as it was), and
//! each emitter is told its own slice.
//!
//! - `map-elites` (Mouret & Clune 2015): emitters that vary elites drawn
//!   uniformly from the archive (or each the best of `[archive]
//!   tournament` drawn so): `gaussian` (pyribs's `GaussianEmitter`:
//!   elite + σ·N(0, I)) or `iso-line` (`IsoLineEmitter`, Vassiliades &
//!   Mouret 2018: elite + σ_iso·N(0, I) + σ_line·N(0, 1)·(other − elite)).
//!   While the archive is empty they vary the starting genome. For a
//!   `[morphology]` scene the emitter is the body GA's variation: a mutant
//!   of an elite (or of a crossover of two, with the body GA's odds),
//!   checked and retried as the body GA's children are.
//! - `cma-me` (Fontaine et al. 2020): CMA-ES emitters ([`CmaEmitter`])
//!   ranked by improvement of the archive.
//!
//! A bounded genome is searched in units of each gene's bounds (σ = 0.1
//! moves a gene by a tenth of its range) and clipped into them; an
//! unbounded one as it is. Every emitter draws from its own stream named
//! by (seed, lane, generation, emitter), so a generation is the same bits
//! on any thread and after a checkpoint.

use super::body_ga::{self, Made, Variation, CROSSOVER};
use super::cma_me::CmaEmitter;
use super::{
    check_body, check_genome, check_same, check_told, gaussian, BestSoFar, Bounds, Random,
};
use crate::archive::{Added, Candidate, GridArchive};
use crate::problem::Outcome;
use animats_scene::archive::{EmitterName, Grid};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A generation's candidates per emitter unless told (pyribs's examples use
/// 36 with CMA-ME).
pub const BATCH: usize = 36;

/// Which quality-diversity search.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum QdKind {
    /// Elites varied by Gaussian or iso-line noise (or bodies' variation).
    MapElites,
    /// CMA-ES emitters.
    CmaMe,
}

/// One emitter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Emitter {
    /// Elite + σ·N(0, I).
    Gaussian {
        /// Candidates a generation.
        batch: usize,
        /// σ.
        sigma: f64,
    },
    /// Elite + σ_iso·N(0, I) + σ_line·N(0, 1)·(other − elite).
    IsoLine {
        /// Candidates a generation.
        batch: usize,
        /// σ_iso.
        iso_sigma: f64,
        /// σ_line.
        line_sigma: f64,
    },
    /// Bodies varied by their problem's own operators.
    Body {
        /// Candidates a generation.
        batch: usize,
    },
    /// A CMA-ES improving the archive.
    Cma(Box<CmaEmitter>),
}

impl Emitter {
    fn batch(&self) -> usize {
        match self {
            Emitter::Gaussian { batch, .. }
            | Emitter::IsoLine { batch, .. }
            | Emitter::Body { batch } => *batch,
            Emitter::Cma(c) => c.batch,
        }
    }
}

/// A quality-diversity search's whole state: what a checkpoint holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Qd {
    /// (Not `kind`: [`super::AnyOptimiser`]'s tag.)
    #[serde(rename = "search")]
    kind: QdKind,
    seed: u64,
    lane: usize,
    generation: u64,
    /// The archive.
    pub archive: GridArchive,
    /// The emitters, in order.
    pub emitters: Vec<Emitter>,
    /// Where search starts (in search units).
    x0: Vec<f64>,
    bounds: Option<Bounds>,
    /// Candidates last asked (genomes), and how many each emitter asked.
    asked: Vec<Vec<f64>>,
    counts: Vec<usize>,
    /// `[archive] overlap`: the next generation is asked before the last
    /// is told.
    #[serde(default)]
    overlap: bool,
    /// With `overlap`, the generation asked after the one not yet told
    /// (its genomes and each emitter's count).
    #[serde(default)]
    ahead: Option<(Vec<Vec<f64>>, Vec<usize>)>,
    best: BestSoFar,
    refused: BTreeMap<String, u64>,
    kept: u64,
}

/// The defaults of a search over a genome of `dim` genes.
pub fn default_batch(kind: QdKind, dim: usize) -> usize {
    match kind {
        QdKind::MapElites => BATCH,
        QdKind::CmaMe => super::cma_default_lambda(dim),
    }
}

impl Qd {
    /// A search of `kind` over `grid`, from `start` within `bounds`;
    /// `bodies`: the genomes are bodies, varied by their problem.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        kind: QdKind,
        grid: Grid,
        start: &[f64],
        bounds: Option<Bounds>,
        population: Option<usize>,
        seed: u64,
        lane: usize,
        bodies: bool,
    ) -> Result<Qd, String> {
        if bodies && kind == QdKind::CmaMe {
            return Err(
                "optimiser: cma-me adapts a fixed-length genome; a [morphology] scene's bodies change shape: use map-elites"
                    .into(),
            );
        }
        let overlap = grid.overlap;
        if overlap && kind == QdKind::CmaMe {
            return Err(
                "[archive] overlap: cma-me's emitters adapt from every generation told before the next is asked: use map-elites"
                    .into(),
            );
        }
        if !bodies && start.is_empty() {
            return Err("the genome is empty: nothing to evolve".into());
        }
        let batch = population.unwrap_or_else(|| default_batch(kind, start.len()));
        let count = grid.emitters.unwrap_or(match kind {
            QdKind::MapElites => 1,
            QdKind::CmaMe => 5,
        });
        let x0 = match &bounds {
            Some(b) => start
                .iter()
                .enumerate()
                .map(|(i, x)| ((x - b.lo[i]) / b.width(i)).clamp(0.0, 1.0))
                .collect(),
            None => start.to_vec(),
        };
        let emitters = (0..count)
            .map(|_| {
                if bodies {
                    return Emitter::Body { batch };
                }
                match (kind, grid.emitter) {
                    (QdKind::MapElites, EmitterName::Gaussian) => Emitter::Gaussian {
                        batch,
                        sigma: grid.sigma.unwrap_or(0.1),
                    },
                    (QdKind::MapElites, EmitterName::IsoLine) => Emitter::IsoLine {
                        batch,
                        iso_sigma: grid.sigma.unwrap_or(0.01),
                        line_sigma: grid.line_sigma.unwrap_or(0.2),
                    },
                    (QdKind::CmaMe, _) => Emitter::Cma(Box::new(CmaEmitter::new(
                        &x0,
                        grid.sigma.unwrap_or(0.2),
                        batch,
                        bounds.is_some(),
                    ))),
                }
            })
            .collect();
        Ok(Qd {
            kind,
            seed,
            lane,
            generation: 0,
            archive: GridArchive::new(grid),
            emitters,
            x0,
            bounds,
            asked: Vec::new(),
            counts: Vec::new(),
            overlap,
            ahead: None,
            best: BestSoFar::default(),
            refused: BTreeMap::new(),
            kept: 0,
        })
    }

    /// A checkpoint's search against the one its run's configuration
    /// makes (`fresh`): the same set-up, grid and emitters (a CMA-ME
    /// emitter checked as [`CmaEmitter::check_state`] does); each emitter's
    /// whole batch asked, or none; every genome asked, asked ahead or kept
    /// as an elite of the genome's length and finite, or a body the
    /// scene's `variation` accepts.
    pub(crate) fn check_state(
        &self,
        fresh: &Qd,
        variation: Option<&dyn Variation>,
    ) -> Result<(), String> {
        check_same(
            "its kind, seed and lane",
            &(self.kind, self.seed, self.lane),
            &(fresh.kind, fresh.seed, fresh.lane),
        )?;
        check_same("its start", &self.x0, &fresh.x0)?;
        check_same("its bounds", &self.bounds, &fresh.bounds)?;
        check_same("its overlap", &self.overlap, &fresh.overlap)?;
        check_same(
            "its archive's grid",
            &self.archive.grid,
            &fresh.archive.grid,
        )?;
        if self.emitters.len() != fresh.emitters.len() {
            return Err(format!(
                "{} emitters where its configuration makes {}",
                self.emitters.len(),
                fresh.emitters.len()
            ));
        }
        for (k, (e, f)) in self.emitters.iter().zip(&fresh.emitters).enumerate() {
            match (e, f) {
                (Emitter::Cma(e), Emitter::Cma(f)) => e
                    .check_state(f)
                    .map_err(|why| format!("emitter {k}: {why}"))?,
                _ => check_same(&format!("emitter {k}"), e, f)?,
            }
        }
        let bodies = self.varies_bodies();
        let genome = |what: &str, g: &[f64]| {
            if bodies {
                check_body(what, g, variation)
            } else {
                check_genome(what, g, self.x0.len())
            }
        };
        let batches: Vec<usize> = self.emitters.iter().map(Emitter::batch).collect();
        let ahead = self
            .ahead
            .as_ref()
            .map(|(g, c)| (g.as_slice(), c.as_slice()));
        for (what, asked, counts) in [
            ("asked", Some((&self.asked[..], &self.counts[..]))),
            ("asked ahead", ahead),
        ]
        .into_iter()
        .filter_map(|(w, a)| a.map(|(g, c)| (w, g, c)))
        {
            let whole =
                counts == batches.as_slice() && asked.len() == batches.iter().sum::<usize>();
            if !(whole || (asked.is_empty() && counts.is_empty())) {
                return Err(format!(
                    "{} candidates {what} by emitters counting {counts:?}, whose batches are {batches:?}",
                    asked.len()
                ));
            }
            for (k, g) in asked.iter().enumerate() {
                genome(&format!("candidate {k} {what}"), g)?;
            }
        }
        if self.ahead.is_some() && (!self.overlap || self.asked.is_empty()) {
            return Err("a generation asked ahead of none untold".into());
        }
        for e in self.archive.elites() {
            genome(&format!("the elite of cell {}", e.index), &e.genome)?;
        }
        self.best
            .check(if bodies { None } else { Some(self.x0.len()) })?;
        if let Some((g, _)) = self.best.get() {
            genome("the best", g)?;
        }
        Ok(())
    }

    /// Which search this is.
    pub fn kind(&self) -> QdKind {
        self.kind
    }

    /// Whether the next generation is asked before the last is told
    /// (`[archive] overlap`).
    pub fn overlaps(&self) -> bool {
        self.overlap
    }

    /// True when its emitters vary bodies (a `[morphology]` scene's).
    pub fn varies_bodies(&self) -> bool {
        self.emitters
            .iter()
            .any(|e| matches!(e, Emitter::Body { .. }))
    }

    /// A search-space point as a genome.
    fn genome(&self, x: &[f64]) -> Vec<f64> {
        match &self.bounds {
            Some(b) => x
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    // Clamped again: lo + width rounds past hi by an ulp.
                    (b.lo[i] + v.clamp(0.0, 1.0) * b.width(i)).clamp(b.lo[i], b.hi[i])
                })
                .collect(),
            None => x.to_vec(),
        }
    }

    /// A genome as a search-space point.
    fn point(&self, g: &[f64]) -> Vec<f64> {
        match &self.bounds {
            Some(b) => g
                .iter()
                .enumerate()
                .map(|(i, v)| (v - b.lo[i]) / b.width(i))
                .collect(),
            None => g.to_vec(),
        }
    }

    fn clip(&self, mut x: Vec<f64>) -> Vec<f64> {
        if self.bounds.is_some() {
            for v in &mut x {
                *v = v.clamp(0.0, 1.0);
            }
        }
        x
    }

    /// The next generation: every emitter's batch, in emitter order.
    /// With `[archive] overlap`, asked while a generation is untold, it is
    /// the next one (its parents from the archive as it stands), told
    /// after that one.
    pub fn ask(&mut self, variation: Option<&dyn Variation>) -> Result<Vec<Vec<f64>>, String> {
        let ahead = self.overlap && !self.asked.is_empty();
        if ahead && self.ahead.is_some() {
            return Err(
                "map-elites with [archive] overlap asks one generation ahead at most: tell the oldest first"
                    .into(),
            );
        }
        let mut all = Vec::new();
        let mut counts = Vec::with_capacity(self.emitters.len());
        let (seed, lane) = (self.seed, self.lane);
        let generation = self.generation + u64::from(ahead);
        let mut emitters = std::mem::take(&mut self.emitters);
        for (k, e) in emitters.iter_mut().enumerate() {
            let mut rng = Random::for_child(seed, lane, generation, k as u64);
            let batch: Vec<Vec<f64>> = match e {
                Emitter::Gaussian { batch, sigma } => {
                    let parents = self.parents(*batch, &mut rng);
                    parents
                        .into_iter()
                        .map(|p| {
                            let x = p.iter().map(|v| v + *sigma * gaussian(&mut rng)).collect();
                            self.genome(&self.clip(x))
                        })
                        .collect()
                }
                Emitter::IsoLine {
                    batch,
                    iso_sigma,
                    line_sigma,
                } => {
                    let parents = self.parents(2 * *batch, &mut rng);
                    let (a, b) = parents.split_at(*batch);
                    a.iter()
                        .zip(b)
                        .map(|(x, y)| {
                            let line = *line_sigma * gaussian(&mut rng);
                            let v = x
                                .iter()
                                .zip(y)
                                .map(|(xi, yi)| {
                                    xi + *iso_sigma * gaussian(&mut rng) + line * (yi - xi)
                                })
                                .collect();
                            self.genome(&self.clip(v))
                        })
                        .collect()
                }
                Emitter::Body { batch } => {
                    let v = variation.ok_or(
                        "map-elites over bodies varies them with the scene's [morphology]",
                    )?;
                    self.bodies(*batch, k, generation, v)
                }
                Emitter::Cma(c) => {
                    let xs = c.ask(&mut rng);
                    xs.iter().map(|x| self.genome(x)).collect()
                }
            };
            counts.push(batch.len());
            all.extend(batch);
        }
        self.emitters = emitters;
        if ahead {
            self.ahead = Some((all.clone(), counts));
        } else {
            self.counts = counts;
            self.asked = all.clone();
        }
        Ok(all)
    }

    /// `n` parents in search units: elites drawn uniformly, or the start
    /// while the archive is empty.
    fn parents(&self, n: usize, rng: &mut Random) -> Vec<Vec<f64>> {
        if self.archive.is_empty() {
            vec![self.x0.clone(); n]
        } else {
            self.archive
                .parents(n, rng)
                .into_iter()
                .map(|e| self.point(&e.genome))
                .collect()
        }
    }

    /// `n` bodies of emitter `k`, each from its own stream (made in
    /// parallel).
    fn bodies(&mut self, n: usize, k: usize, generation: u64, v: &dyn Variation) -> Vec<Vec<f64>> {
        let start = v.start();
        let (seed, lane) = (self.seed, self.lane);
        let archive = &self.archive;
        // The start body itself once: not again in a generation asked
        // ahead of the first's telling (`[archive] overlap`).
        let first = generation == self.generation;
        let made = body_ga::make_children(v, n, |i| {
            let key = (1u64 << 48) | ((k as u64) << 24) | i as u64;
            let mut rng = Random::for_child(seed, lane, generation, key);
            if archive.is_empty() {
                return match &start {
                    Some(s) if i == 0 && k == 0 && first => Made {
                        genome: s.clone(),
                        refused: Vec::new(),
                        kept: false,
                    },
                    Some(s) => body_ga::vary(v, &mut rng, |v, r| v.mutate(s, r), s),
                    None => body_ga::random_body(v, &mut rng),
                };
            }
            let parent: &[f64] = &archive.parents(1, &mut rng)[0].genome;
            if rng.uniform() < CROSSOVER {
                let other: &[f64] = &archive.parents(1, &mut rng)[0].genome;
                body_ga::vary(
                    v,
                    &mut rng,
                    |v, r| {
                        let c = v.crossover(parent, other, r);
                        v.mutate(&c, r)
                    },
                    parent,
                )
            } else {
                body_ga::vary(v, &mut rng, |v, r| v.mutate(parent, r), parent)
            }
        });
        made.into_iter()
            .map(|m| {
                for r in m.refused {
                    *self.refused.entry(r.to_string()).or_insert(0) += 1;
                }
                self.kept += m.kept as u64;
                m.genome
            })
            .collect()
    }

    /// Takes the last generation's outcomes (fitness and measures): the
    /// archive takes them in one batch, then each emitter its own slice.
    /// The answers of the archive, in order.
    pub fn tell(&mut self, outcomes: &[Outcome]) -> Result<Vec<Added>, String> {
        check_told(self.asked.len(), outcomes.len())?;
        let k = self.archive.grid.bins.len();
        if let Some((i, o)) = outcomes
            .iter()
            .enumerate()
            .find(|(_, o)| o.measures.len() != k)
        {
            return Err(format!(
                "candidate {i}: {} measures told, the archive has {k} ([archive] measures)",
                o.measures.len()
            ));
        }
        let asked = std::mem::take(&mut self.asked);
        for (g, o) in asked.iter().zip(outcomes) {
            self.best.offer(g, o.fitness);
        }
        let batch: Vec<Candidate> = asked
            .iter()
            .zip(outcomes)
            .map(|(g, o)| Candidate::new(g, o))
            .collect();
        let added = self.archive.add(&batch);
        let (seed, lane, generation) = (self.seed, self.lane, self.generation);
        let mut at = 0;
        let counts = std::mem::take(&mut self.counts);
        let mut emitters = std::mem::take(&mut self.emitters);
        for (k, (e, &n)) in emitters.iter_mut().zip(&counts).enumerate() {
            if let Emitter::Cma(c) = e {
                let archive = &self.archive;
                let restart = || {
                    let mut rng =
                        Random::for_child(seed, lane, generation, (1u64 << 40) | k as u64);
                    archive
                        .sample(1, &mut rng)
                        .first()
                        .map(|e| self.point(&e.genome))
                };
                c.tell(&added[at..at + n], restart);
            }
            at += n;
        }
        self.emitters = emitters;
        self.generation += 1;
        if let Some((asked, counts)) = self.ahead.take() {
            self.asked = asked;
            self.counts = counts;
        }
        Ok(added)
    }

    /// The best candidate told so far.
    pub fn best(&self) -> Option<(&[f64], f64)> {
        self.best.get()
    }

    /// Generations told.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Candidates a generation asks.
    pub fn batch(&self) -> usize {
        self.emitters.iter().map(Emitter::batch).sum()
    }

    /// Refused body variations so far, by reason.
    pub fn refused(&self) -> &BTreeMap<String, u64> {
        &self.refused
    }

    /// Children that fell back to their parent.
    pub fn kept(&self) -> u64 {
        self.kept
    }

    /// CMA-ME's restarts so far, all emitters.
    pub fn restarts(&self) -> u64 {
        self.emitters
            .iter()
            .map(|e| match e {
                Emitter::Cma(c) => c.restarts,
                _ => 0,
            })
            .sum()
    }
}
