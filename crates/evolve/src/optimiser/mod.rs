//! The optimiser interface: ask for a whole population, tell its fitness.
//! One evaluation loop ([`crate::run`]) serves every strategy: the thesis's
//! hill climber, a GA and CMA-ES. All maximise.
//!
//! An optimiser draws its random numbers from [`Random::for_evaluation`]
//! (seed, lane, generation): it stores no generator state, so a checkpoint
//! taken between generations resumes to the identical run.
//!
//! One file per strategy in this folder; adding one: its file, and its
//! place in [`OptimiserKind`] and [`AnyOptimiser`] below.

pub mod body_ga;
pub mod cma_es;
pub mod cma_me;
pub mod eigen;
pub mod ga;
pub mod hill_climber;
pub mod map_elites;

use crate::screen::Screen;
use animats_engine::math;
use body_ga::{BodyGa, Variation};
use cma_es::CmaEs;
use ga::Ga;
use hill_climber::HillClimber;
use map_elites::{Qd, QdKind};
use serde::{Deserialize, Serialize};

pub use animats_creatures::random::Random;

/// An ask/tell optimiser over real vectors, maximising fitness.
pub trait Optimiser {
    /// The next generation's candidates (at least one).
    fn ask(&mut self) -> Vec<Vec<f64>>;
    /// The fitness of each candidate of the last `ask`, in order. A
    /// non-finite fitness counts as the worst possible.
    fn tell(&mut self, fitness: &[f64]) -> Result<(), String>;
    /// The best candidate so far and its fitness.
    fn best(&self) -> Option<(&[f64], f64)>;
    /// Generations told so far.
    fn generation(&self) -> u64;
}

/// Box bounds on a genome: `lo[i] <= x[i] <= hi[i]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
}

impl Bounds {
    /// Checks the bounds: finite, `lo < hi`, one pair per dimension.
    pub fn validate(&self, dim: usize) -> Result<(), String> {
        if self.lo.len() != dim || self.hi.len() != dim {
            return Err(format!("bounds: expected {dim} pairs"));
        }
        for (i, (l, h)) in self.lo.iter().zip(&self.hi).enumerate() {
            if !(l.is_finite() && h.is_finite() && l < h) {
                return Err(format!("bounds of gene {i}: [{l}, {h}] is not an interval"));
            }
        }
        Ok(())
    }

    /// The width of dimension `i`.
    pub fn width(&self, i: usize) -> f64 {
        self.hi[i] - self.lo[i]
    }

    /// Moves `x` into the box.
    pub fn clamp(&self, x: &mut [f64]) {
        for (i, v) in x.iter_mut().enumerate() {
            *v = v.clamp(self.lo[i], self.hi[i]);
        }
    }
}

/// Which optimiser, as named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OptimiserKind {
    /// The thesis's hill climber (§3.2.1.6): (1+λ), λ = 1 by default.
    HillClimber,
    /// A generational GA: tournaments, uniform crossover, Gaussian mutation, elitism.
    Ga,
    /// Hansen's CMA-ES, (μ/μ_w, λ).
    CmaEs,
    /// A (μ + λ) GA over bodies, with the problem's own variation and
    /// checks: what a `[morphology]` scene evolves with.
    BodyGa,
    /// MAP-Elites: an archive of elites over the scene's `[archive]`
    /// measures, filled by varying elites.
    MapElites,
    /// CMA-ME: the archive filled by CMA-ES emitters.
    CmaMe,
}

impl OptimiserKind {
    /// All kinds, in the order they are documented.
    pub const ALL: [OptimiserKind; 6] = [
        OptimiserKind::HillClimber,
        OptimiserKind::Ga,
        OptimiserKind::CmaEs,
        OptimiserKind::BodyGa,
        OptimiserKind::MapElites,
        OptimiserKind::CmaMe,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            OptimiserKind::HillClimber => "hill-climber",
            OptimiserKind::Ga => "ga",
            OptimiserKind::CmaEs => "cma-es",
            OptimiserKind::BodyGa => "body-ga",
            OptimiserKind::MapElites => "map-elites",
            OptimiserKind::CmaMe => "cma-me",
        }
    }

    /// The quality-diversity search this is, if it is one.
    pub fn qd(self) -> Option<QdKind> {
        match self {
            OptimiserKind::MapElites => Some(QdKind::MapElites),
            OptimiserKind::CmaMe => Some(QdKind::CmaMe),
            _ => None,
        }
    }

    /// Parses a command-line name.
    pub fn parse(s: &str) -> Result<OptimiserKind, String> {
        OptimiserKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = OptimiserKind::ALL.iter().map(|k| k.name()).collect();
                format!("unknown optimiser `{s}`: use {}", names.join(", "))
            })
    }

    /// The population a generation asks for by default in `dim` dimensions.
    pub fn default_population(self, dim: usize) -> usize {
        match self {
            OptimiserKind::HillClimber => 1,
            OptimiserKind::Ga => 32,
            OptimiserKind::CmaEs => cma_default_lambda(dim),
            OptimiserKind::BodyGa => body_ga::POPULATION,
            OptimiserKind::MapElites => map_elites::default_batch(QdKind::MapElites, dim),
            OptimiserKind::CmaMe => map_elites::default_batch(QdKind::CmaMe, dim),
        }
    }
}

/// The most genes an optimiser takes: a million (8 MB a genome).
pub const MAX_GENES: usize = 1_000_000;

/// The most genes CMA-ES and CMA-ME take: their covariance holds n²
/// numbers (800 MB at this size) and its decomposition costs n³ (at 1,000
/// genes 0.98 s a decomposition, 0.13 s a generation, on one core of an
/// Intel Xeon: `cargo run --release -p animats-bench --example
/// cma_es_genes`).
pub const MAX_CMA_GENES: usize = 10_000;

/// Hansen's default population, `4 + floor(3 ln n)`.
pub fn cma_default_lambda(dim: usize) -> usize {
    4 + (3.0 * math::log(dim.max(1) as f64)).floor() as usize
}

/// What an optimiser starts from.
#[derive(Clone, Debug, PartialEq)]
pub struct Setup {
    /// The strategy.
    pub kind: OptimiserKind,
    /// The starting genome (the hill climber's first candidate, the GA's
    /// first individual, CMA-ES's initial mean).
    pub start: Vec<f64>,
    /// Bounds; without them the hill climber mutates relatively (the
    /// thesis's scheme) and CMA-ES samples freely.
    pub bounds: Option<Bounds>,
    /// Candidates per generation; `None`: the kind's default.
    pub population: Option<usize>,
    /// The run's seed.
    pub seed: u64,
    /// This lane, 0-based (the hill climber's mutation size grows with it).
    pub lane: usize,
    /// CMA-ES's initial step size: in units of the bounds' widths when
    /// bounded (default 0.3), absolute otherwise (default 0.3).
    pub sigma: Option<f64>,
    /// CMA-ES's restarts with a doubled population (IPOP) when a run
    /// converges or stagnates; 0: none.
    pub restarts: u32,
}

impl Setup {
    /// Checks the setup, naming the offending part.
    pub fn validate(&self) -> Result<(), String> {
        if self.start.is_empty() {
            return Err("the genome is empty: nothing to evolve".into());
        }
        let n = self.start.len();
        let most = match self.kind {
            OptimiserKind::CmaEs | OptimiserKind::CmaMe => MAX_CMA_GENES,
            _ => MAX_GENES,
        };
        if n > most {
            return Err(format!(
                "the genome has {n} genes, more than {} takes ({most}){}",
                self.kind.name(),
                if most == MAX_CMA_GENES {
                    ": its covariance is n × n; use ga or map-elites"
                } else {
                    ""
                }
            ));
        }
        if !self.start.iter().all(|x| x.is_finite()) {
            return Err("start: every gene must be finite".into());
        }
        if let Some(b) = &self.bounds {
            b.validate(self.start.len())?;
        }
        if let Some(p) = self.population {
            let least = if self.kind == OptimiserKind::HillClimber {
                1
            } else {
                2
            };
            if p < least || p > 100_000 {
                return Err(format!(
                    "population: must be between {least} and 100000 for {}, got {p}",
                    self.kind.name()
                ));
            }
        }
        if let Some(s) = self.sigma {
            if !(s.is_finite() && s > 0.0) {
                return Err(format!("sigma: must be > 0, got {s}"));
            }
        }
        Ok(())
    }
}

/// Any of the built-in optimisers: what a run and its checkpoint hold.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum AnyOptimiser {
    /// See [`HillClimber`].
    HillClimber(HillClimber),
    /// See [`Ga`].
    Ga(Ga),
    /// See [`CmaEs`] (boxed: its state is the largest by far).
    CmaEs(Box<CmaEs>),
    /// See [`BodyGa`].
    BodyGa(Box<BodyGa>),
    /// See [`Qd`]: MAP-Elites or CMA-ME.
    Qd(Box<Qd>),
}

impl AnyOptimiser {
    /// A fresh optimiser. A body GA starts from its problem's bodies, not
    /// from `setup.start`.
    pub fn new(setup: &Setup) -> Result<AnyOptimiser, String> {
        AnyOptimiser::with_archive(setup, None, false)
    }

    /// A fresh optimiser; a quality-diversity one fills an archive over
    /// `grid` (refused without one), of bodies if `bodies`.
    pub fn with_archive(
        setup: &Setup,
        grid: Option<&animats_scene::archive::Grid>,
        bodies: bool,
    ) -> Result<AnyOptimiser, String> {
        if !bodies {
            setup.validate()?;
        }
        if let Some(kind) = setup.kind.qd() {
            let grid = grid.ok_or_else(|| {
                format!(
                    "optimiser: {} fills an archive: the scene needs an [archive] table naming its measures (docs/DIVERSITY.md)",
                    setup.kind.name()
                )
            })?;
            let mut grid = grid.clone();
            if setup.sigma.is_some() && grid.sigma.is_none() {
                grid.sigma = setup.sigma;
            }
            return Ok(AnyOptimiser::Qd(Box::new(Qd::new(
                kind,
                grid,
                &setup.start,
                setup.bounds.clone(),
                setup.population,
                setup.seed,
                setup.lane,
                bodies,
            )?)));
        }
        Ok(match setup.kind {
            OptimiserKind::HillClimber => AnyOptimiser::HillClimber(HillClimber::from_setup(setup)),
            OptimiserKind::Ga => AnyOptimiser::Ga(Ga::new(setup)),
            OptimiserKind::CmaEs => AnyOptimiser::CmaEs(Box::new(CmaEs::new(setup))),
            OptimiserKind::BodyGa => AnyOptimiser::BodyGa(Box::new(BodyGa::new(
                setup.seed,
                setup.lane,
                setup.population,
            ))),
            OptimiserKind::MapElites | OptimiserKind::CmaMe => {
                return Err("a quality-diversity search needs its archive's grid".into())
            }
        })
    }

    /// Checks a checkpoint's optimiser against the one its run's
    /// configuration makes (`fresh`, of the same kind): each kind's own
    /// `check_state`, with the scene's body `variation` if it has one.
    pub fn check_state(
        &self,
        fresh: &AnyOptimiser,
        variation: Option<&dyn Variation>,
    ) -> Result<(), String> {
        match (self, fresh) {
            (AnyOptimiser::HillClimber(o), AnyOptimiser::HillClimber(f)) => o.check_state(f),
            (AnyOptimiser::Ga(o), AnyOptimiser::Ga(f)) => o.check_state(f),
            (AnyOptimiser::CmaEs(o), AnyOptimiser::CmaEs(f)) => o.check_state(f),
            (AnyOptimiser::BodyGa(o), AnyOptimiser::BodyGa(f)) => o.check_state(f, variation),
            (AnyOptimiser::Qd(o), AnyOptimiser::Qd(f)) => o.check_state(f, variation),
            _ => Err(format!(
                "it is {} where its configuration makes {}",
                self.kind().name(),
                fresh.kind().name()
            )),
        }
    }

    /// The next generation: a body GA's made by `variation` (refused
    /// without one), any other's by its own [`Optimiser::ask`].
    pub fn ask_with(&mut self, variation: Option<&dyn Variation>) -> Result<Vec<Vec<f64>>, String> {
        match self {
            AnyOptimiser::BodyGa(o) => {
                let v = variation
                    .ok_or("body-ga varies bodies: it evolves a scene with a [morphology] table")?;
                Ok(o.ask(v))
            }
            AnyOptimiser::Qd(o) => o.ask(variation),
            other => Ok(other.ask()),
        }
    }

    /// A body GA's refused variations so far by reason, and the children
    /// that kept their parent; `None` for any other optimiser.
    pub fn refusals(&self) -> Option<(&std::collections::BTreeMap<String, u64>, u64)> {
        match self {
            AnyOptimiser::BodyGa(o) => Some((o.refused(), o.kept())),
            AnyOptimiser::Qd(o) if !o.refused().is_empty() || o.kept() > 0 => {
                Some((o.refused(), o.kept()))
            }
            _ => None,
        }
    }

    /// A body GA's refused variations so far (all reasons), else `None`.
    pub fn refused(&self) -> Option<u64> {
        match self {
            AnyOptimiser::BodyGa(o) => Some(o.refused_total()),
            AnyOptimiser::Qd(o) if !o.refused().is_empty() => Some(o.refused().values().sum()),
            _ => None,
        }
    }

    /// Which kind this is.
    pub fn kind(&self) -> OptimiserKind {
        match self {
            AnyOptimiser::HillClimber(_) => OptimiserKind::HillClimber,
            AnyOptimiser::Ga(_) => OptimiserKind::Ga,
            AnyOptimiser::CmaEs(_) => OptimiserKind::CmaEs,
            AnyOptimiser::BodyGa(_) => OptimiserKind::BodyGa,
            AnyOptimiser::Qd(o) => match o.kind() {
                QdKind::MapElites => OptimiserKind::MapElites,
                QdKind::CmaMe => OptimiserKind::CmaMe,
            },
        }
    }

    /// The real-vector optimiser inside, if it is one.
    fn inner(&self) -> Option<&dyn Optimiser> {
        match self {
            AnyOptimiser::HillClimber(o) => Some(o),
            AnyOptimiser::Ga(o) => Some(o),
            AnyOptimiser::CmaEs(o) => Some(o.as_ref()),
            AnyOptimiser::BodyGa(_) | AnyOptimiser::Qd(_) => None,
        }
    }

    /// Which candidates of the generation just asked need a robust
    /// scene's half-step run ([`Screen`]): above the worst survivor (body
    /// GA), above their cell's threshold (MAP-Elites over bodies), all (any
    /// other: they rank every candidate, or, MAP-Elites over a fixed
    /// genome, are pyribs's search).
    pub fn screen(&self) -> Screen {
        match self {
            AnyOptimiser::BodyGa(o) => o.screen(),
            AnyOptimiser::Qd(o) if o.kind() == QdKind::MapElites && o.varies_bodies() => {
                Screen::cells(&o.archive)
            }
            _ => Screen::All,
        }
    }

    /// Whether the next generation is asked before the last is told
    /// (MAP-Elites with `[archive] overlap`).
    pub fn overlaps(&self) -> bool {
        matches!(self, AnyOptimiser::Qd(o) if o.overlaps())
    }

    /// The archive of a quality-diversity search.
    pub fn archive(&self) -> Option<&crate::archive::GridArchive> {
        match self {
            AnyOptimiser::Qd(o) => Some(&o.archive),
            _ => None,
        }
    }

    /// Tells whole outcomes: a quality-diversity search takes their
    /// measures too, any other optimiser their fitness.
    pub fn tell_outcomes(&mut self, outcomes: &[crate::problem::Outcome]) -> Result<(), String> {
        match self {
            AnyOptimiser::Qd(o) => o.tell(outcomes).map(|_| ()),
            other => {
                let fitness: Vec<f64> = outcomes.iter().map(|o| o.fitness).collect();
                other.tell(&fitness)
            }
        }
    }

    fn inner_mut(&mut self) -> Option<&mut dyn Optimiser> {
        match self {
            AnyOptimiser::HillClimber(o) => Some(o),
            AnyOptimiser::Ga(o) => Some(o),
            AnyOptimiser::CmaEs(o) => Some(o.as_mut()),
            AnyOptimiser::BodyGa(_) | AnyOptimiser::Qd(_) => None,
        }
    }
}

impl Optimiser for AnyOptimiser {
    /// A body GA asked without its problem's variation ([`AnyOptimiser::ask_with`])
    /// has nothing to offer: an empty generation, which a `tell` refuses.
    fn ask(&mut self) -> Vec<Vec<f64>> {
        self.inner_mut().map_or_else(Vec::new, |o| o.ask())
    }
    fn tell(&mut self, fitness: &[f64]) -> Result<(), String> {
        match self {
            AnyOptimiser::BodyGa(o) => o.tell(fitness),
            AnyOptimiser::Qd(_) => {
                Err("a quality-diversity search is told outcomes with their measures".into())
            }
            other => other.inner_mut().map_or(Ok(()), |o| o.tell(fitness)),
        }
    }
    fn best(&self) -> Option<(&[f64], f64)> {
        match self {
            AnyOptimiser::BodyGa(o) => o.best(),
            AnyOptimiser::Qd(o) => o.best(),
            other => other.inner().and_then(|o| o.best()),
        }
    }
    fn generation(&self) -> u64 {
        match self {
            AnyOptimiser::BodyGa(o) => o.generation(),
            AnyOptimiser::Qd(o) => o.generation(),
            other => other.inner().map_or(0, |o| o.generation()),
        }
    }
}

/// A standard normal deviate (Box–Muller with libm, so the same bits on
/// every platform).
pub fn gaussian(rng: &mut Random) -> f64 {
    let u1 = 1.0 - rng.uniform(); // (0, 1]
    let u2 = rng.uniform();
    (-2.0 * animats_engine::math::log(u1)).sqrt()
        * animats_engine::math::cos(std::f64::consts::TAU * u2)
}

/// Fitness with NaN mapped to −∞, so that it always sorts last.
pub fn sane(f: f64) -> f64 {
    if f.is_nan() {
        f64::NEG_INFINITY
    } else {
        f
    }
}

/// Keeps track of the best candidate told so far (ties keep the earlier).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
pub struct BestSoFar {
    /// The genome.
    pub genome: Vec<f64>,
    /// Its fitness; `None` before anything finite was told.
    pub fitness: Option<f64>,
}

impl BestSoFar {
    /// Offers a candidate; true if it became the best.
    pub fn offer(&mut self, genome: &[f64], fitness: f64) -> bool {
        let f = sane(fitness);
        if f > self.fitness.unwrap_or(f64::NEG_INFINITY) {
            self.genome = genome.to_vec();
            self.fitness = Some(f);
            true
        } else {
            false
        }
    }

    /// As the trait's `best`.
    pub fn get(&self) -> Option<(&[f64], f64)> {
        self.fitness.map(|f| (self.genome.as_slice(), f))
    }

    /// A checkpoint's best: a genome of `n` finite genes with a fitness
    /// that is a number, or nothing yet (a body's genome has no fixed
    /// length: `n` is `None`).
    pub(crate) fn check(&self, n: Option<usize>) -> Result<(), String> {
        match self.fitness {
            Some(f) if f.is_nan() => Err("the best's fitness is not a number".into()),
            Some(_) => match n {
                Some(n) => check_genome("the best", &self.genome, n),
                None => check_genome("the best", &self.genome, self.genome.len()),
            },
            None => Ok(()),
        }
    }
}

/// A checkpoint's part fixed when its run started: it must equal what the
/// run's own configuration makes (`fresh`); the error names it.
pub(crate) fn check_same<T: PartialEq>(what: &str, stored: &T, fresh: &T) -> Result<(), String> {
    if stored == fresh {
        Ok(())
    } else {
        Err(format!(
            "{what} is not what the run's own configuration makes"
        ))
    }
}

/// A checkpoint's genome: `n` finite genes.
pub(crate) fn check_genome(what: &str, genome: &[f64], n: usize) -> Result<(), String> {
    if genome.len() != n {
        return Err(format!("{what} has {} genes, not {n}", genome.len()));
    }
    if genome.iter().any(|x| !x.is_finite()) {
        return Err(format!("{what} has a gene that is not finite"));
    }
    Ok(())
}

/// A checkpoint's genomes: each of `n` finite genes.
pub(crate) fn check_genomes(what: &str, genomes: &[Vec<f64>], n: usize) -> Result<(), String> {
    for (k, g) in genomes.iter().enumerate() {
        check_genome(&format!("{what} {k}"), g, n)?;
    }
    Ok(())
}

/// A checkpoint's body genome: finite, and one that the scene's
/// `variation` accepts (its own check of a body, which decodes it).
pub(crate) fn check_body(
    what: &str,
    genome: &[f64],
    variation: Option<&dyn Variation>,
) -> Result<(), String> {
    check_genome(what, genome, genome.len())?;
    match variation {
        Some(v) => v
            .check(genome)
            .map_err(|why| format!("{what} is not a body of the scene's [morphology]: {why}")),
        None => Err(format!(
            "{what} is a body, but the scene has no [morphology]"
        )),
    }
}

/// A checkpoint's list of `len` numbers, each finite (and above 0 if
/// `positive`).
pub(crate) fn check_numbers(
    what: &str,
    x: &[f64],
    len: usize,
    positive: bool,
) -> Result<(), String> {
    if x.len() != len {
        return Err(format!("{what}: {} numbers, not {len}", x.len()));
    }
    if x.iter().any(|v| !v.is_finite() || (positive && *v <= 0.0)) {
        return Err(format!(
            "{what}: a number that is not finite{}",
            if positive { " and above 0" } else { "" }
        ));
    }
    Ok(())
}

/// Checks a `tell` against the population asked.
pub fn check_told(asked: usize, told: usize) -> Result<(), String> {
    if asked == 0 {
        Err("tell without ask: ask for a population first".into())
    } else if asked != told {
        Err(format!(
            "told {told} fitness values for a population of {asked}"
        ))
    } else {
        Ok(())
    }
}
