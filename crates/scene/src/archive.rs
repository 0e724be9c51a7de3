//! `[archive]`: what describes a solution for quality-diversity search
//! (`animats evolve --optimiser map-elites | cma-me`): its measures,
//! computed during the evaluation itself and returned beside the fitness,
//! and the grid archive they index (pyribs's `GridArchive`: `bins` cells
//! along each measure over `ranges`; values outside are clipped into the
//! edge cells).
//!
//! Measures, each `{ kind = "...", ... }`:
//!
//! | kind | value |
//! |---|---|
//! | `contact_fraction` | share of steps `particle` rests on or touches the floor (its surface within `[evolve] touch_tolerance` of the ground: y = 0, or the terrain), [0, 1] |
//! | `feet` | particles on the floor, averaged over the steps |
//! | `displacement` | final centre-of-mass offset of `particles` along `axis`, m |
//! | `mean_height` | centre-of-mass height of `particles`, averaged over the steps, m |
//! | `speed` | `displacement` / time survived, m/s |
//! | `particles`, `muscles`, `mass`, `size` | the body as built: its particles, its actuators, its moving mass (kg), its largest extent (m) |
//! | `energy` | the actuators' positive work, J ([`crate::work`]) |
//!
//! `particles` and `axis` default to `[evolve]`'s. The same measures, each
//! with a `weight`, are `[evolve] terms` of the fitness ([`TermEntry`]).

use crate::build::{At, Names};
use crate::def::Typed;
use crate::error::SceneError;
use crate::evaluate::{centre_of as centre, EvolveSpec};
use animats_engine::{DVec3, ParticleId, World};
use serde::Deserialize;

/// The most cells a grid may have.
pub const MAX_CELLS: u64 = 10_000_000;

/// The most measures an archive may have.
pub const MAX_MEASURES: usize = 16;

/// `[archive]` as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArchiveEntry {
    /// What describes a solution, in order.
    pub measures: Vec<Typed<MeasureEntry>>,
    /// Cells along each measure.
    pub bins: Vec<u64>,
    /// `[min, max]` of each measure.
    pub ranges: Vec<[f64; 2]>,
    /// s: an evaluation that survived less enters no cell; default 0.
    #[serde(default)]
    pub min_time: f64,
    /// CMA-MAE's archive learning rate α in (0, 1]; default 1 (CMA-ME's
    /// elitist archive). Below 1 it needs `threshold_min`.
    pub learning_rate: Option<f64>,
    /// CMA-MAE: the threshold of an empty cell; default −∞.
    pub threshold_min: Option<f64>,
    /// Subtracted from every objective in the QD score (pyribs's
    /// `qd_score_offset`); default 0.
    #[serde(default)]
    pub qd_offset: f64,
    /// MAP-Elites's variation: `gaussian` (an elite plus Gaussian noise) or
    /// `iso-line` (Vassiliades's: plus noise along the line to a second
    /// elite); default `gaussian`.
    #[serde(default)]
    pub emitter: EmitterName,
    /// Emitters, each asking `--population` candidates a generation;
    /// default 1 (map-elites), 5 (cma-me).
    pub emitters: Option<usize>,
    /// The Gaussian's (or the iso-line's isotropic) standard deviation, in
    /// units of each gene's bounds; CMA-ME's initial step, likewise;
    /// default 0.1 (gaussian), 0.01 (iso-line), 0.2 (cma-me).
    pub sigma: Option<f64>,
    /// The iso-line's standard deviation along the line; default 0.2.
    pub line_sigma: Option<f64>,
    /// MAP-Elites's parents: each the best of this many elites drawn
    /// uniformly; default 1 (uniform, pyribs's).
    pub tournament: Option<u64>,
    /// MAP-Elites: ask each generation before the last is told, its
    /// parents drawn from the archive a generation older, so that two
    /// generations are evaluated at once; default false (pyribs's
    /// scheduler).
    #[serde(default)]
    pub overlap: bool,
}

/// `[archive] emitter`.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EmitterName {
    /// pyribs's `GaussianEmitter`.
    #[default]
    Gaussian,
    /// pyribs's `IsoLineEmitter`.
    IsoLine,
}

/// One measure as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum MeasureEntry {
    /// Share of steps `particle` is on the floor.
    ContactFraction {
        /// The particle.
        particle: String,
    },
    /// Particles on the floor, averaged over the steps.
    Feet {},
    /// Final centre-of-mass offset along `axis`.
    Displacement {
        /// Whose centre (default `[evolve] particles`).
        particles: Option<Vec<String>>,
        /// The direction (default `[evolve] axis`).
        axis: Option<[f64; 3]>,
    },
    /// Centre-of-mass height, averaged over the steps.
    MeanHeight {
        /// Whose centre (default `[evolve] particles`).
        particles: Option<Vec<String>>,
    },
    /// Mean forward speed.
    Speed {
        /// Whose centre (default `[evolve] particles`).
        particles: Option<Vec<String>>,
        /// The direction (default `[evolve] axis`).
        axis: Option<[f64; 3]>,
    },
    /// Particles of the body.
    Particles {},
    /// Actuators of the body.
    Muscles {},
    /// Moving mass, kg.
    Mass {},
    /// Largest extent of the body as built, m.
    Size {},
    /// The actuators' positive work, J.
    Energy {},
}

/// `[evolve] terms = [{ kind = "...", weight = w, ... }]`: a measure (as
/// the archive's) and its weight in the fitness; read as a table, so that
/// its errors are reported at its own entry.
#[derive(Clone, Debug)]
pub struct TermEntry(pub Result<(f64, MeasureEntry), String>);

impl<'de> Deserialize<'de> for TermEntry {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut table = toml::Table::deserialize(d)?;
        let weight = match table.remove("weight") {
            None => Err("missing field `weight`".to_string()),
            Some(toml::Value::Float(w)) => Ok(w),
            Some(toml::Value::Integer(w)) => Ok(w as f64),
            Some(other) => Err(format!("`weight` must be a number, got {other}")),
        };
        Ok(TermEntry(weight.and_then(|w| {
            toml::Value::Table(table)
                .try_into::<MeasureEntry>()
                .map(|m| (w, m))
                .map_err(|e| e.message().trim().to_string())
        })))
    }
}

/// Every measure kind, for messages.
pub(crate) const KINDS: &str =
    "contact_fraction, feet, displacement, mean_height, speed, particles, muscles, mass, size, energy";

/// One measure, resolved against the scene.
#[derive(Clone, Debug, PartialEq)]
pub enum Measure {
    /// See [`MeasureEntry::ContactFraction`].
    ContactFraction(ParticleId),
    /// See [`MeasureEntry::Feet`].
    Feet,
    /// Centre of these particles, along this unit axis.
    Displacement(Vec<ParticleId>, DVec3),
    /// See [`MeasureEntry::MeanHeight`].
    MeanHeight(Vec<ParticleId>),
    /// See [`MeasureEntry::Speed`].
    Speed(Vec<ParticleId>, DVec3),
    /// See [`MeasureEntry::Particles`].
    Particles,
    /// See [`MeasureEntry::Muscles`].
    Muscles,
    /// See [`MeasureEntry::Mass`].
    Mass,
    /// See [`MeasureEntry::Size`].
    Size,
    /// See [`MeasureEntry::Energy`].
    Energy,
}

impl Measure {
    /// Whether it needs the actuators' work summed.
    pub fn needs_work(&self) -> bool {
        matches!(self, Measure::Energy)
    }
}

/// The archive's grid and the search's settings: what an optimiser needs,
/// checked without building a world (a `[morphology]` scene's bodies are
/// built one by one).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Grid {
    /// Each measure's name, as `log.csv` and `archive.csv` headers describe
    /// it (`contact_fraction foot_l`).
    pub names: Vec<String>,
    /// Cells along each measure.
    pub bins: Vec<u64>,
    /// `(min, max)` of each measure.
    pub ranges: Vec<(f64, f64)>,
    /// s: shorter evaluations enter no cell.
    pub min_time: f64,
    /// CMA-MAE's α (1: an elitist archive).
    pub learning_rate: f64,
    /// An empty cell's threshold (−∞: CMA-ME's; JSON has no −∞: `null`).
    #[serde(with = "minus_infinity_as_null")]
    pub threshold_min: f64,
    /// pyribs's `qd_score_offset`.
    pub qd_offset: f64,
    /// MAP-Elites's variation.
    pub emitter: EmitterName,
    /// Emitters (`None`: the optimiser's default).
    pub emitters: Option<usize>,
    /// See [`ArchiveEntry::sigma`].
    pub sigma: Option<f64>,
    /// See [`ArchiveEntry::line_sigma`].
    pub line_sigma: Option<f64>,
    /// See [`ArchiveEntry::tournament`] (1: uniform).
    #[serde(default = "one")]
    pub tournament: usize,
    /// See [`ArchiveEntry::overlap`].
    #[serde(default)]
    pub overlap: bool,
}

fn one() -> usize {
    1
}

/// −∞ written as `null` (JSON has no infinities): `#[serde(with = ...)]`.
pub mod minus_infinity_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes `x`, −∞ (or any non-finite value) as `null`.
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_some(x)
        } else {
            s.serialize_none()
        }
    }

    /// Reads a number, `null` as −∞.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NEG_INFINITY))
    }
}

impl Grid {
    /// Cells in all.
    pub fn cells(&self) -> u64 {
        self.bins.iter().product()
    }
}

/// `[archive]`, resolved against its scene.
#[derive(Clone, Debug, PartialEq)]
pub struct ArchiveSpec {
    /// The grid and search settings.
    pub grid: Grid,
    /// The measures, in order.
    pub measures: Vec<Measure>,
}

impl ArchiveEntry {
    /// Checks everything that does not need the world: the grid and the
    /// settings. Errors name the field.
    pub(crate) fn grid(&self, at: &At) -> Result<Grid, SceneError> {
        let k = self.measures.len();
        if k == 0 {
            return Err(at.err("measures", "name at least one measure"));
        }
        if k > MAX_MEASURES {
            return Err(at.err(
                "measures",
                format!("at most {MAX_MEASURES} measures, got {k}"),
            ));
        }
        let mut names = Vec::with_capacity(k);
        for (i, m) in self.measures.iter().enumerate() {
            let m = m.get().map_err(|(field, msg)| {
                at.err(
                    &format!("measures[{i}]{}", dotted(field)),
                    format!("{msg} (kinds: {KINDS})"),
                )
            })?;
            names.push(m.name());
        }
        if self.bins.len() != k {
            return Err(at.err(
                "bins",
                format!("one per measure: {k} measures, {} bins", self.bins.len()),
            ));
        }
        if self.ranges.len() != k {
            return Err(at.err(
                "ranges",
                format!(
                    "one [min, max] per measure: {k} measures, {} ranges",
                    self.ranges.len()
                ),
            ));
        }
        let mut cells: u64 = 1;
        for (i, &b) in self.bins.iter().enumerate() {
            if b == 0 {
                return Err(at.err(&format!("bins[{i}]"), "must be at least 1"));
            }
            cells = cells.saturating_mul(b);
        }
        if cells > MAX_CELLS {
            return Err(at.err(
                "bins",
                format!("a grid of {cells} cells: at most {MAX_CELLS}"),
            ));
        }
        for (i, [lo, hi]) in self.ranges.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(at.err(
                    &format!("ranges[{i}]"),
                    format!("[{lo}, {hi}] is not an interval: min must be below max, both finite"),
                ));
            }
        }
        if !(self.min_time.is_finite() && self.min_time >= 0.0) {
            return Err(at.err("min_time", format!("must be >= 0, got {}", self.min_time)));
        }
        let learning_rate = self.learning_rate.unwrap_or(1.0);
        if !(learning_rate > 0.0 && learning_rate <= 1.0) {
            return Err(at.err(
                "learning_rate",
                format!("must be in (0, 1], got {learning_rate}"),
            ));
        }
        let threshold_min = match self.threshold_min {
            Some(t) if !t.is_finite() => {
                return Err(at.err("threshold_min", format!("must be finite, got {t}")))
            }
            Some(t) => t,
            None if learning_rate < 1.0 => {
                return Err(at.err(
                    "threshold_min",
                    "CMA-MAE (learning_rate below 1) needs the threshold of an empty cell: the lowest objective worth keeping",
                ))
            }
            None => f64::NEG_INFINITY,
        };
        if !self.qd_offset.is_finite() {
            return Err(at.err("qd_offset", "must be finite"));
        }
        if let Some(e) = self.emitters {
            if !(1..=1000).contains(&e) {
                return Err(at.err("emitters", format!("must be between 1 and 1000, got {e}")));
            }
        }
        for (field, v) in [("sigma", self.sigma), ("line_sigma", self.line_sigma)] {
            if let Some(s) = v {
                if !(s.is_finite() && s > 0.0) {
                    return Err(at.err(field, format!("must be > 0, got {s}")));
                }
            }
        }
        let tournament = match self.tournament {
            None => 1,
            Some(t) if (1..=1000).contains(&t) => t as usize,
            Some(t) => {
                return Err(at.err("tournament", format!("must be between 1 and 1000, got {t}")))
            }
        };
        Ok(Grid {
            names,
            bins: self.bins.clone(),
            ranges: self.ranges.iter().map(|[a, b]| (*a, *b)).collect(),
            min_time: self.min_time,
            learning_rate,
            threshold_min,
            qd_offset: self.qd_offset,
            emitter: self.emitter,
            emitters: self.emitters,
            sigma: self.sigma,
            line_sigma: self.line_sigma,
            tournament,
            overlap: self.overlap,
        })
    }

    /// Resolves the measures against the built scene.
    pub(crate) fn build(
        &self,
        at: &At,
        names: &Names,
        evolve: Option<&EvolveSpec>,
    ) -> Result<ArchiveSpec, SceneError> {
        let grid = self.grid(at)?;
        let evolve = evolve.ok_or_else(|| {
            at.err(
                "",
                "an [archive] describes evaluations: the scene needs an [evolve] table",
            )
        })?;
        let mut measures = Vec::with_capacity(grid.names.len());
        for (i, m) in self.measures.iter().enumerate() {
            let Ok(m) = m.get() else { continue };
            measures.push(m.resolve(
                at,
                &format!("measures[{i}]"),
                names,
                &evolve.particles,
                evolve.axis,
            )?);
        }
        Ok(ArchiveSpec { grid, measures })
    }
}

impl MeasureEntry {
    /// The measure, resolved against the scene (`field`: where it was
    /// written; `particles` and `axis`: `[evolve]`'s, the defaults).
    pub(crate) fn resolve(
        &self,
        at: &At,
        field: &str,
        names: &Names,
        particles: &[ParticleId],
        axis: DVec3,
    ) -> Result<Measure, SceneError> {
        let list = |p: &Option<Vec<String>>| -> Result<Vec<ParticleId>, SceneError> {
            match p {
                None => Ok(particles.to_vec()),
                Some(l) if l.is_empty() => Err(at.err(
                    &format!("{field}.particles"),
                    "name at least one particle (or leave it out: [evolve]'s)",
                )),
                Some(l) => names.list(at, &format!("{field}.particles"), l),
            }
        };
        let direction = |a: &Option<[f64; 3]>| -> Result<DVec3, SceneError> {
            match a {
                None => Ok(axis),
                Some(a) => {
                    let v = at.vec3(&format!("{field}.axis"), *a)?;
                    if v.length() == 0.0 {
                        return Err(at.err(&format!("{field}.axis"), "must not be zero"));
                    }
                    Ok(v.normalize())
                }
            }
        };
        Ok(match self {
            MeasureEntry::ContactFraction { particle } => {
                Measure::ContactFraction(names.one(at, &format!("{field}.particle"), particle)?)
            }
            MeasureEntry::Feet {} => Measure::Feet,
            MeasureEntry::Displacement { particles, axis: a } => {
                Measure::Displacement(list(particles)?, direction(a)?)
            }
            MeasureEntry::MeanHeight { particles } => Measure::MeanHeight(list(particles)?),
            MeasureEntry::Speed { particles, axis: a } => {
                Measure::Speed(list(particles)?, direction(a)?)
            }
            MeasureEntry::Particles {} => Measure::Particles,
            MeasureEntry::Muscles {} => Measure::Muscles,
            MeasureEntry::Mass {} => Measure::Mass,
            MeasureEntry::Size {} => Measure::Size,
            MeasureEntry::Energy {} => Measure::Energy,
        })
    }
}

fn dotted(field: &str) -> String {
    if field.is_empty() {
        String::new()
    } else {
        format!(".{field}")
    }
}

impl MeasureEntry {
    /// How logs and headers name it.
    pub fn name(&self) -> String {
        match self {
            MeasureEntry::ContactFraction { particle } => format!("contact_fraction {particle}"),
            MeasureEntry::Feet {} => "feet".into(),
            MeasureEntry::Displacement { .. } => "displacement".into(),
            MeasureEntry::MeanHeight { .. } => "mean_height".into(),
            MeasureEntry::Speed { .. } => "speed".into(),
            MeasureEntry::Particles {} => "particles".into(),
            MeasureEntry::Muscles {} => "muscles".into(),
            MeasureEntry::Mass {} => "mass".into(),
            MeasureEntry::Size {} => "size".into(),
            MeasureEntry::Energy {} => "energy".into(),
        }
    }
}

/// Accumulates the measures of one evaluation, step by step.
pub struct Recorder<'a> {
    measures: &'a [Measure],
    tolerance: f64,
    /// Per measure: a running sum, or the start centre.
    sums: Vec<f64>,
    starts: Vec<DVec3>,
    /// Fixed at the start: particles, muscles, mass, size.
    fixed: Vec<f64>,
    steps: u64,
}

impl<'a> Recorder<'a> {
    /// Starts recording `measures` of `world` (before its first step);
    /// `muscles` is the scene's actuator count.
    pub fn new(
        measures: &'a [Measure],
        evolve: &EvolveSpec,
        world: &World,
        muscles: usize,
    ) -> Self {
        let p = world.particles();
        let moving: Vec<usize> = (0..world.len()).filter(|&i| p.inv_mass[i] > 0.0).collect();
        let fixed = measures
            .iter()
            .map(|m| match m {
                Measure::Particles => moving.len() as f64,
                Measure::Muscles => muscles as f64,
                Measure::Mass => moving.iter().map(|&i| p.mass[i]).sum(),
                Measure::Size => {
                    let (mut lo, mut hi) =
                        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
                    for id in world.particle_ids() {
                        if p.inv_mass[id.index()] > 0.0 {
                            let x = world.position(id);
                            lo = lo.min(x);
                            hi = hi.max(x);
                        }
                    }
                    if moving.is_empty() {
                        0.0
                    } else {
                        (hi - lo).max_element()
                    }
                }
                _ => 0.0,
            })
            .collect();
        let starts = measures
            .iter()
            .map(|m| match m {
                Measure::Displacement(ids, _) | Measure::Speed(ids, _) => centre(world, ids),
                _ => DVec3::ZERO,
            })
            .collect();
        Recorder {
            measures,
            tolerance: evolve.touch_tolerance,
            sums: vec![0.0; measures.len()],
            starts,
            fixed,
            steps: 0,
        }
    }

    /// Records the world after a step.
    pub fn step(&mut self, world: &World) {
        self.steps += 1;
        let on_floor = |p: ParticleId| world.touches_ground(p, self.tolerance);
        for (m, sum) in self.measures.iter().zip(&mut self.sums) {
            match m {
                Measure::ContactFraction(p) if on_floor(*p) => *sum += 1.0,
                Measure::Feet => *sum += world.count_on_ground(self.tolerance) as f64,
                Measure::MeanHeight(ids) => *sum += centre(world, ids).y,
                _ => {}
            }
        }
    }

    /// The measures, given the world at the end, the time survived (s) and
    /// the actuators' positive work (J; read by `energy` alone).
    pub fn finish(&self, world: &World, time: f64, work: f64) -> Vec<f64> {
        let per_step = |s: f64| {
            if self.steps == 0 {
                0.0
            } else {
                s / self.steps as f64
            }
        };
        self.measures
            .iter()
            .enumerate()
            .map(|(i, m)| match m {
                Measure::ContactFraction(_) | Measure::Feet | Measure::MeanHeight(_) => {
                    per_step(self.sums[i])
                }
                Measure::Displacement(ids, axis) => {
                    (centre(world, ids) - self.starts[i]).dot(*axis)
                }
                Measure::Speed(ids, axis) => {
                    if time > 0.0 {
                        (centre(world, ids) - self.starts[i]).dot(*axis) / time
                    } else {
                        0.0
                    }
                }
                Measure::Particles | Measure::Muscles | Measure::Mass | Measure::Size => {
                    self.fixed[i]
                }
                Measure::Energy => work,
            })
            .collect()
    }
}
