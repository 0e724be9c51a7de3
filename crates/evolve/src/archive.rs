//! A grid archive of elites, as pyribs's `GridArchive` (0.12) defines one:
//! `bins[i]` equal cells along measure `i` over `ranges[i]`, values outside
//! clipped into the edge cells, one elite per cell.
//!
//! Adding a batch follows pyribs's `add` exactly, so that emitters ranking
//! by its answers behave as pyribs's do:
//!
//! - a candidate *can* enter its cell when its objective beats the cell's
//!   threshold (an empty cell's is `threshold_min`, −∞ by default; an
//!   occupied one's is its elite's objective, or with CMA-MAE's learning
//!   rate α < 1 a running threshold);
//! - status 2: it found a new cell; 1: it improved an occupied one; 0: not
//!   added. Statuses and values are computed against the archive as it was
//!   before the batch, so two candidates finding the same new cell both
//!   get 2;
//! - value: the objective minus the cell's threshold (0 for a new cell
//!   when `threshold_min` is −∞, as CMA-ME defines improvement);
//! - of the candidates that can enter one cell, the best (the first of
//!   equals) does; with α < 1 the cell's threshold becomes
//!   `(1−α)^n t + (1 − (1−α)^n) mean`, n of them with that mean objective
//!   (Fontaine & Nikolaidis 2023's batch rule).
//!
//! Statistics as pyribs's `ArchiveStats`: `coverage` (occupied / cells),
//! `qd_score` (Σ (objective − `qd_offset`) over elites), `norm_qd_score`
//! (qd_score / cells), `obj_max` and `obj_mean`.
//!
//! A candidate with a non-finite objective or measure, one that survived
//! less than `min_time`, or one whose run blew up, enters no cell (status 0).

use crate::optimiser::Random;
use animats_scene::archive::Grid;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// pyribs's epsilon, added before flooring a measure to its cell.
pub const EPSILON: f64 = 1e-6;

/// One elite.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Elite {
    /// Its cell, as pyribs numbers them (row-major over the bins).
    pub index: u64,
    /// The genome.
    pub genome: Vec<f64>,
    /// Its objective (the fitness).
    pub objective: f64,
    /// Its measures.
    pub measures: Vec<f64>,
    /// The cell's threshold (its objective unless α < 1).
    pub threshold: f64,
    /// Time survived, s.
    pub time: f64,
    /// Distance, m.
    pub distance: f64,
    /// Why its evaluation ended.
    pub ended: String,
}

/// What the archive made of one candidate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Added {
    /// 0 not added, 1 improved an occupied cell, 2 found a new one.
    pub status: u8,
    /// Objective minus the cell's threshold.
    pub value: f64,
}

/// A candidate offered to the archive.
#[derive(Clone, Debug)]
pub struct Candidate<'a> {
    /// The genome.
    pub genome: &'a [f64],
    /// Its objective.
    pub objective: f64,
    /// Its measures.
    pub measures: &'a [f64],
    /// Time survived, s.
    pub time: f64,
    /// Distance, m.
    pub distance: f64,
    /// Why its evaluation ended.
    pub ended: String,
}

impl<'a> Candidate<'a> {
    /// `genome` as its evaluation `o` describes it.
    pub fn new(genome: &'a [f64], o: &'a crate::problem::Outcome) -> Candidate<'a> {
        Candidate {
            genome,
            objective: o.fitness,
            measures: &o.measures,
            time: o.time,
            distance: o.distance,
            ended: o.ended.to_string(),
        }
    }
}

/// The archive's statistics, as pyribs's `ArchiveStats`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    /// Elites.
    pub elites: usize,
    /// Occupied share of the cells.
    pub coverage: f64,
    /// Σ (objective − offset).
    pub qd_score: f64,
    /// qd_score / cells.
    pub norm_qd_score: f64,
    /// The best objective ever inserted (`None` while empty).
    pub obj_max: Option<f64>,
    /// The elites' mean objective (`None` while empty).
    pub obj_mean: Option<f64>,
}

/// The archive.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GridArchive {
    /// Its grid and settings.
    pub grid: Grid,
    /// Elites in the order their cells were first occupied.
    elites: Vec<Elite>,
    /// Cell → position in `elites` (as pairs: a checkpoint is JSON, whose
    /// keys are strings).
    #[serde(with = "pairs")]
    cells: BTreeMap<u64, usize>,
    /// Σ objective over the elites.
    objective_sum: f64,
    /// The best objective ever inserted.
    obj_max: Option<f64>,
    /// The best elite ever inserted (it may since have been replaced, when
    /// α < 1).
    best: Option<Elite>,
}

mod pairs {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    use std::collections::BTreeMap;

    pub fn serialize<S: Serializer>(m: &BTreeMap<u64, usize>, s: S) -> Result<S::Ok, S::Error> {
        m.iter().collect::<Vec<_>>().serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<BTreeMap<u64, usize>, D::Error> {
        Ok(Vec::<(u64, usize)>::deserialize(d)?.into_iter().collect())
    }
}

/// The cell of `measures` in `grid` along each measure (pyribs's grid
/// index).
pub fn grid_index(grid: &Grid, measures: &[f64]) -> Vec<u64> {
    measures
        .iter()
        .zip(&grid.bins)
        .zip(&grid.ranges)
        .map(|((&m, &bins), &(lo, hi))| {
            let x = ((bins as f64) * (m - lo) + EPSILON) / (hi - lo);
            // Truncation toward zero then clipping, as numpy's astype and
            // clip.
            let i = if x >= 0.0 { x.trunc() } else { 0.0 };
            (i.min((bins - 1) as f64)) as u64
        })
        .collect()
}

/// The cell of `measures` in `grid` (row-major, the last measure fastest:
/// `numpy.ravel_multi_index`).
pub fn index_of(grid: &Grid, measures: &[f64]) -> u64 {
    grid_index(grid, measures)
        .iter()
        .zip(&grid.bins)
        .fold(0, |acc, (&i, &b)| acc * b + i)
}

impl GridArchive {
    /// An empty archive over `grid` (checked by the scene).
    pub fn new(grid: Grid) -> GridArchive {
        GridArchive {
            grid,
            elites: Vec::new(),
            cells: BTreeMap::new(),
            objective_sum: 0.0,
            obj_max: None,
            best: None,
        }
    }

    /// Checks an archive read back from a checkpoint: every elite in its
    /// own cell, once, with as many measures as the grid has.
    pub fn validate(&self) -> Result<(), String> {
        let k = self.grid.bins.len();
        let cells = self
            .grid
            .bins
            .iter()
            .try_fold(1u64, |n, &b| n.checked_mul(b))
            .unwrap_or(u64::MAX);
        if k == 0
            || self.grid.bins.contains(&0)
            || cells > animats_scene::archive::MAX_CELLS
            || self.grid.ranges.len() != k
            || self.grid.names.len() != k
            || self
                .grid
                .ranges
                .iter()
                .any(|(a, b)| !(a.is_finite() && b.is_finite() && a < b))
        {
            return Err("the archive's grid is malformed".into());
        }
        if self.cells.len() != self.elites.len()
            || self.cells.iter().any(|(&i, &at)| {
                self.elites.get(at).is_none_or(|e| {
                    e.index != i || e.measures.len() != k || self.index_of(&e.measures) != i
                })
            })
        {
            return Err("the archive's cells and elites disagree".into());
        }
        Ok(())
    }

    /// Cells in all.
    pub fn cells(&self) -> u64 {
        self.grid.cells()
    }

    /// Elites now.
    pub fn len(&self) -> usize {
        self.elites.len()
    }

    /// True while empty.
    pub fn is_empty(&self) -> bool {
        self.elites.is_empty()
    }

    /// Every elite, in the order their cells were first occupied.
    pub fn elites(&self) -> &[Elite] {
        &self.elites
    }

    /// The elite of cell `index`.
    pub fn get(&self, index: u64) -> Option<&Elite> {
        self.cells.get(&index).map(|&k| &self.elites[k])
    }

    /// The best elite ever inserted.
    pub fn best(&self) -> Option<&Elite> {
        self.best.as_ref()
    }

    /// The cell of `measures` along each measure (pyribs's grid index).
    pub fn grid_index(&self, measures: &[f64]) -> Vec<u64> {
        grid_index(&self.grid, measures)
    }

    /// The cell of `measures` (row-major, the last measure fastest:
    /// `numpy.ravel_multi_index`).
    pub fn index_of(&self, measures: &[f64]) -> u64 {
        index_of(&self.grid, measures)
    }

    /// Cell `index` along each measure.
    pub fn unravel(&self, mut index: u64) -> Vec<u64> {
        let mut out = vec![0; self.grid.bins.len()];
        for (o, &b) in out.iter_mut().zip(&self.grid.bins).rev() {
            *o = index % b;
            index /= b;
        }
        out
    }

    /// Adds a batch; one answer per candidate, in order.
    pub fn add(&mut self, batch: &[Candidate]) -> Vec<Added> {
        let k = self.grid.bins.len();
        let tmin = self.grid.threshold_min;
        // Against the archive as it was: which cell, its threshold, and
        // whether each candidate can enter.
        let mut answers = Vec::with_capacity(batch.len());
        let mut entering: BTreeMap<u64, Vec<usize>> = BTreeMap::new();
        // A run that blew up describes no behaviour: its measures and its
        // objective were read from a state on its way to infinity (a
        // distance of −10²³⁰ m, which would swamp the QD score).
        let blow_up = crate::problem::Ended::BlowUp.to_string();
        let eligible: Vec<bool> = batch
            .iter()
            .map(|c| {
                c.objective.is_finite()
                    && c.measures.len() == k
                    && c.measures.iter().all(|m| m.is_finite())
                    && c.time >= self.grid.min_time
                    && c.ended != blow_up
            })
            .collect();
        for (i, c) in batch.iter().enumerate() {
            if !eligible[i] {
                answers.push(Added {
                    status: 0,
                    value: f64::NAN,
                });
                continue;
            }
            let index = self.index_of(c.measures);
            let current = self.get(index);
            let threshold = current.map_or(tmin, |e| e.threshold);
            let can = c.objective > threshold;
            let status = match (can, current.is_some()) {
                (true, false) => 2,
                (true, true) => 1,
                _ => 0,
            };
            let base = if status == 2 && tmin == f64::NEG_INFINITY {
                0.0
            } else {
                threshold
            };
            answers.push(Added {
                status,
                value: c.objective - base,
            });
            if can {
                entering.entry(index).or_default().push(i);
            }
        }
        // pyribs refuses ineligible candidates outright; here they rank
        // last, one below the worst eligible value (−∞ would swamp a
        // ranking's spread).
        let worst = answers
            .iter()
            .filter(|a| !a.value.is_nan())
            .map(|a| a.value)
            .fold(f64::INFINITY, f64::min);
        for a in answers.iter_mut().filter(|a| a.value.is_nan()) {
            a.value = if worst.is_finite() { worst - 1.0 } else { -1.0 };
        }
        // Each cell takes its best entrant (the first of equals).
        for (index, list) in entering {
            let mut top = list[0];
            for &i in &list[1..] {
                if batch[i].objective > batch[top].objective {
                    top = i;
                }
            }
            let old = self.get(index).map(|e| (e.threshold, e.objective));
            let threshold = if tmin == f64::NEG_INFINITY {
                batch[top].objective
            } else {
                let cur = old.map_or(tmin, |(t, _)| t);
                let n = list.len() as f64;
                let mean = list.iter().map(|&i| batch[i].objective).sum::<f64>() / n;
                let ratio = animats_engine::math::pow(1.0 - self.grid.learning_rate, n);
                ratio * cur + mean * (1.0 - ratio)
            };
            let c = &batch[top];
            let elite = Elite {
                index,
                genome: c.genome.to_vec(),
                objective: c.objective,
                measures: c.measures.to_vec(),
                threshold,
                time: c.time,
                distance: c.distance,
                ended: c.ended.clone(),
            };
            self.objective_sum += c.objective - old.map_or(0.0, |(_, o)| o);
            if self.obj_max.is_none_or(|m| c.objective > m) {
                self.obj_max = Some(c.objective);
                self.best = Some(elite.clone());
            }
            match self.cells.get(&index) {
                Some(&k) => self.elites[k] = elite,
                None => {
                    self.cells.insert(index, self.elites.len());
                    self.elites.push(elite);
                }
            }
        }
        answers
    }

    /// The statistics now.
    pub fn stats(&self) -> Stats {
        let n = self.elites.len();
        let qd = self.objective_sum - n as f64 * self.grid.qd_offset;
        Stats {
            elites: n,
            coverage: n as f64 / self.cells() as f64,
            qd_score: qd,
            norm_qd_score: qd / self.cells() as f64,
            obj_max: self.obj_max,
            obj_mean: (n > 0).then(|| self.objective_sum / n as f64),
        }
    }

    /// `n` elites drawn uniformly with replacement (empty while the archive
    /// is).
    pub fn sample<'a>(&'a self, n: usize, rng: &mut Random) -> Vec<&'a Elite> {
        if self.elites.is_empty() {
            return Vec::new();
        }
        (0..n)
            .map(|_| {
                let k = ((rng.uniform() * self.elites.len() as f64) as usize)
                    .min(self.elites.len() - 1);
                &self.elites[k]
            })
            .collect()
    }

    /// `n` parents, each the best of the grid's `tournament` elites drawn
    /// uniformly (the first of equals); with 1, [`GridArchive::sample`].
    pub fn parents<'a>(&'a self, n: usize, rng: &mut Random) -> Vec<&'a Elite> {
        let k = self.grid.tournament.max(1);
        (0..n)
            .filter_map(|_| {
                self.sample(k, rng).into_iter().reduce(|a, b| {
                    if b.objective > a.objective {
                        b
                    } else {
                        a
                    }
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use animats_scene::archive::EmitterName;

    fn grid(bins: Vec<u64>, ranges: Vec<(f64, f64)>, lr: f64, tmin: f64) -> Grid {
        Grid {
            names: (0..bins.len()).map(|i| format!("m{i}")).collect(),
            bins,
            ranges,
            min_time: 0.0,
            learning_rate: lr,
            threshold_min: tmin,
            qd_offset: 0.0,
            emitter: EmitterName::Gaussian,
            emitters: None,
            sigma: None,
            line_sigma: None,
            tournament: 1,
            overlap: false,
        }
    }

    fn cand<'a>(g: &'a [f64], f: f64, m: &'a [f64]) -> Candidate<'a> {
        Candidate {
            genome: g,
            objective: f,
            measures: m,
            time: 1.0,
            distance: 0.0,
            ended: "timeout".into(),
        }
    }

    /// Parents by tournament: of 1, the uniform draws of `sample` (the
    /// same random numbers); of k, each parent the best of k uniform
    /// draws, so the best of n elites is picked with probability
    /// 1 − (1 − 1/n)^k.
    #[test]
    fn tournaments_pick_the_better_elites() {
        let mut a = GridArchive::new(grid(vec![10], vec![(0.0, 10.0)], 1.0, f64::NEG_INFINITY));
        let genomes: Vec<Vec<f64>> = (0..10).map(|i| vec![i as f64]).collect();
        let measures: Vec<Vec<f64>> = (0..10).map(|i| vec![i as f64 + 0.5]).collect();
        let batch: Vec<Candidate> = (0..10)
            .map(|i| cand(&genomes[i], i as f64, &measures[i]))
            .collect();
        a.add(&batch);
        let draws = 20_000;
        let (mut r1, mut r2) = (Random::for_entry(3, 1), Random::for_entry(3, 1));
        let uniform: Vec<f64> = a
            .sample(draws, &mut r1)
            .iter()
            .map(|e| e.objective)
            .collect();
        let one: Vec<f64> = a
            .parents(draws, &mut r2)
            .iter()
            .map(|e| e.objective)
            .collect();
        assert_eq!(uniform, one);
        for k in [2, 4] {
            a.grid.tournament = k;
            let mut r = Random::for_entry(3, 2);
            let best = a
                .parents(draws, &mut r)
                .iter()
                .filter(|e| e.objective == 9.0)
                .count() as f64
                / draws as f64;
            let p = 1.0 - 0.9f64.powi(k as i32);
            // Binomial: 5 standard deviations.
            let sd = (p * (1.0 - p) / draws as f64).sqrt();
            assert!((best - p).abs() < 5.0 * sd, "k = {k}: {best} against {p}");
        }
    }

    /// pyribs's `index_of` on the values its own tests use: a 10 × 20 grid
    /// over [-1, 1] × [-2, 2]; edges and beyond clip into the edge cells.
    #[test]
    fn indices_match_pyribs() {
        let a = GridArchive::new(grid(
            vec![10, 20],
            vec![(-1.0, 1.0), (-2.0, 2.0)],
            1.0,
            f64::NEG_INFINITY,
        ));
        assert_eq!(a.grid_index(&[-1.0, -2.0]), vec![0, 0]);
        assert_eq!(a.grid_index(&[1.0, 2.0]), vec![9, 19]);
        assert_eq!(a.grid_index(&[-5.0, 5.0]), vec![0, 19]);
        assert_eq!(a.grid_index(&[0.0, 0.0]), vec![5, 10]);
        // 0.2 is a cell edge: the epsilon puts it in the upper cell, as
        // numpy's floating point would without it only sometimes.
        assert_eq!(a.grid_index(&[-0.8, 0.0]), vec![1, 10]);
        assert_eq!(a.index_of(&[0.0, 0.0]), 5 * 20 + 10);
        assert_eq!(a.unravel(5 * 20 + 10), vec![5, 10]);
    }

    /// Statuses and values as pyribs documents them, ties to the first,
    /// and the statistics.
    #[test]
    fn add_follows_pyribs() {
        let mut a = GridArchive::new(grid(vec![10], vec![(0.0, 1.0)], 1.0, f64::NEG_INFINITY));
        let g = [0.0];
        let r = a.add(&[
            cand(&g, 1.0, &[0.05]),
            cand(&g, 3.0, &[0.06]),
            cand(&g, 2.0, &[0.55]),
        ]);
        // Both candidates of the new cell 0 get status 2, value = objective.
        assert_eq!(
            r.iter().map(|x| x.status).collect::<Vec<_>>(),
            vec![2, 2, 2]
        );
        assert_eq!(r[1].value, 3.0);
        assert_eq!(a.len(), 2);
        assert_eq!(a.get(0).map(|e| e.objective), Some(3.0));
        let r = a.add(&[
            cand(&g, 2.5, &[0.0]),
            cand(&g, 4.0, &[0.0]),
            cand(&g, 4.0, &[0.01]),
        ]);
        assert_eq!((r[0].status, r[0].value), (0, -0.5));
        assert_eq!((r[1].status, r[1].value), (1, 1.0));
        // Tie: the first of equals enters.
        assert_eq!(a.get(0).map(|e| e.measures[0]), Some(0.0));
        let s = a.stats();
        assert_eq!(s.elites, 2);
        assert_eq!(s.coverage, 0.2);
        assert_eq!(s.qd_score, 6.0);
        assert_eq!(s.norm_qd_score, 0.6);
        assert_eq!(s.obj_max, Some(4.0));
        // NaN objective, NaN measure, a blow-up: not added.
        let mut blown = cand(&g, 9.0, &[0.5]);
        blown.ended = "blow-up".into();
        let r = a.add(&[
            cand(&g, f64::NAN, &[0.5]),
            cand(&g, 9.0, &[f64::NAN]),
            blown,
        ]);
        assert!(r.iter().all(|x| x.status == 0));
        assert_eq!(a.len(), 2);
    }

    /// An archive read back from a checkpoint is checked: an elite out of
    /// its cell, or a grid of zero bins, is refused, not trusted.
    #[test]
    fn a_tampered_archive_is_refused() {
        let mut a = GridArchive::new(grid(vec![10], vec![(0.0, 1.0)], 1.0, f64::NEG_INFINITY));
        a.add(&[cand(&[0.0], 1.0, &[0.55])]);
        assert_eq!(a.validate(), Ok(()));
        let text = serde_json::to_string(&a).unwrap();
        let moved: GridArchive = serde_json::from_str(&text.replace("[[5,0]]", "[[6,0]]")).unwrap();
        assert!(moved.validate().is_err());
        let mut zero = a.clone();
        zero.grid.bins = vec![0];
        assert!(zero.validate().is_err());
    }

    /// CMA-MAE's batch threshold: with α = 0.1 and threshold_min 0, two
    /// entrants of mean 2 move an empty cell's threshold to
    /// 0.81·0 + 0.19·2 = 0.38, and the best of them is the elite.
    #[test]
    fn learning_rate_moves_thresholds() {
        let mut a = GridArchive::new(grid(vec![4], vec![(0.0, 1.0)], 0.1, 0.0));
        let g = [0.0];
        let r = a.add(&[cand(&g, 1.0, &[0.1]), cand(&g, 3.0, &[0.2])]);
        assert_eq!(r[0].status, 2);
        assert_eq!(r[0].value, 1.0);
        let e = a.get(0).cloned();
        assert_eq!(e.as_ref().map(|e| e.objective), Some(3.0));
        let t = e.map_or(f64::NAN, |e| e.threshold);
        assert!((t - 0.38).abs() < 1e-12, "{t}");
        // A worse candidate above the threshold replaces the elite.
        let r = a.add(&[cand(&g, 0.5, &[0.1])]);
        assert_eq!(r[0].status, 1);
        assert!((r[0].value - 0.12).abs() < 1e-12);
        assert_eq!(a.get(0).map(|e| e.objective), Some(0.5));
        assert_eq!(a.stats().obj_max, Some(3.0));
    }
}
