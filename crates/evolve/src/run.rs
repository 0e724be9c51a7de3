//! An evolution run: independent lanes, each with its own optimiser over one
//! problem (a scene's `[evolve]` controller: the thesis's roobot is one),
//! advanced generation by generation.
//!
//! A generation asks each lane's optimiser for its population and evaluates
//! it in parallel (lanes in parallel too, on the current rayon pool). The
//! thesis's hill climber asks one candidate (generation 1 evaluates the
//! starting parameters themselves, as in Table 6). Every evaluation is a pure
//! function of its genome and every optimiser draws from streams named by
//! (seed, lane, generation), so the log, the best and the checkpoint are the
//! same bits whatever the number of threads.

use crate::optimiser::body_ga::Variation;
use crate::optimiser::{AnyOptimiser, Optimiser, OptimiserKind, Setup};
use crate::problem::{BodyEvolution, Outcome, Problem, SceneEvolution};
use crate::screen::Screen;
use animats_scene::def::LogName;
use animats_scene::evaluate::{SceneProblem, MAX_LANES};
use animats_scene::morphology::MorphologyProblem;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// What is evolved: a scene's `[evolve]` controller. The text is kept, so
/// a resumed run evaluates the scene it started with even if the file has
/// changed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename = "scene")]
pub struct ProblemSpec {
    /// The scene file, as named (for messages and relative paths).
    pub file: String,
    /// Its text.
    pub text: String,
}

impl ProblemSpec {
    /// The thesis's evolution of hopping gaits: the built-in
    /// `scenes/hop_evolver.toml` (what `roobot` names).
    pub fn thesis() -> ProblemSpec {
        ProblemSpec {
            file: animats_scene::HOP_EVOLVER_FILE.into(),
            text: animats_scene::HOP_EVOLVER.into(),
        }
    }

    /// Parses and checks a scene whose controller evolves (a
    /// `[morphology]` scene is refused: see [`ProblemSpec::build`]).
    pub fn parse(&self) -> Result<SceneProblem, String> {
        SceneProblem::parse(&self.text, &self.file).map_err(|e| e.to_string())
    }

    /// True if the scene has a `[morphology]` table: its bodies evolve.
    pub fn has_morphology(&self) -> Result<bool, String> {
        let src = animats_scene::source::Source {
            file: &self.file,
            text: &self.text,
        };
        let def = animats_scene::parse_def(&src).map_err(|e| e.to_string())?;
        Ok(def.morphology.is_some())
    }

    /// Builds the problem: a `[morphology]` scene's bodies, else its
    /// `[evolve]` controller.
    pub fn build(&self) -> Result<Box<dyn Problem>, String> {
        self.build_on(None)
    }

    /// [`ProblemSpec::build`], its evaluations run in `batches` (a GPU's)
    /// where given.
    pub fn build_on(
        &self,
        batches: Option<animats_scene::evaluate::Batches>,
    ) -> Result<Box<dyn Problem>, String> {
        if self.has_morphology()? {
            let m = MorphologyProblem::parse(&self.text, &self.file).map_err(|e| e.to_string())?;
            Ok(Box::new(BodyEvolution(m.on(batches))))
        } else {
            Ok(Box::new(SceneEvolution(self.parse()?.on(batches))))
        }
    }
}

/// What a run was asked to do; fixed for its lifetime (a resumed run keeps
/// it, but for the number of generations).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Config {
    /// Independent lanes.
    pub lanes: usize,
    /// Generations per lane to reach.
    pub generations: u64,
    /// Seed of every random stream.
    pub seed: u64,
    /// The strategy of every lane.
    pub optimiser: OptimiserKind,
    /// Candidates per generation; `None`: the optimiser's default.
    pub population: Option<usize>,
    /// CMA-ES's IPOP restarts (0: none).
    #[serde(default)]
    pub restarts: u32,
    /// What is evolved.
    pub problem: ProblemSpec,
    /// What `log.csv` holds (the scene's `[evolve] log`).
    #[serde(default)]
    pub log: LogMode,
}

/// What `log.csv` holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LogMode {
    /// A row per lane per generation.
    #[default]
    Generations,
    /// A row per improvement, with its genes (the thesis's Table 6).
    Improvements,
}

/// What a user may choose for a new run; `None` takes the default
/// ([`Config::new`] says which). The command line and Python both fill it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Choices {
    /// Lanes (default: the scene's `[evolve] lanes`, else 1).
    pub lanes: Option<usize>,
    /// Generations per lane (default 100).
    pub generations: Option<u64>,
    /// Seed (default 1).
    pub seed: Option<u64>,
    /// Optimiser (default: the scene's `[evolve] optimiser`, else CMA-ES;
    /// body-ga for a `[morphology]` scene).
    pub optimiser: Option<OptimiserKind>,
    /// Candidates per generation (default: the optimiser's).
    pub population: Option<usize>,
    /// CMA-ES's restarts (default 0; only for CMA-ES).
    pub restarts: Option<u32>,
}

/// Generations a run has unless told.
pub const DEFAULT_GENERATIONS: u64 = 100;

impl Config {
    /// A run of `problem` as `choices` say, the rest defaulted; refused
    /// (naming the field) if the scene or a choice is not valid.
    pub fn new(problem: ProblemSpec, choices: &Choices) -> Result<Config, String> {
        let built = problem.build()?;
        let spec = built
            .spec()
            .ok_or("the problem is not a scene with an [evolve] table")?;
        let bodies = built.variation().is_some();
        let written = match &spec.optimiser {
            Some(name) => {
                Some(OptimiserKind::parse(name).map_err(|e| format!("[evolve] optimiser: {e}"))?)
            }
            None => None,
        };
        let optimiser = choices.optimiser.or(written).unwrap_or(if bodies {
            OptimiserKind::BodyGa
        } else {
            OptimiserKind::CmaEs
        });
        let qd = optimiser.qd().is_some();
        if bodies && !(optimiser == OptimiserKind::BodyGa || optimiser == OptimiserKind::MapElites)
        {
            return Err(format!(
                "optimiser: a [morphology] scene's bodies evolve with body-ga or map-elites, not {} (its genomes change shape as bodies grow)",
                optimiser.name()
            ));
        }
        if !bodies && optimiser == OptimiserKind::BodyGa {
            return Err(
                "optimiser: body-ga evolves bodies: give it a scene with a [morphology] table"
                    .into(),
            );
        }
        if qd && built.grid().is_none() {
            return Err(format!(
                "optimiser: {} fills an archive: the scene needs an [archive] table naming its measures, bins and ranges (docs/DIVERSITY.md)",
                optimiser.name()
            ));
        }
        if qd && choices.lanes.is_some_and(|l| l != 1) {
            return Err(format!(
                "lanes: a {} run fills one archive; widen it with more emitters (`[archive] emitters`) or a larger --population",
                optimiser.name()
            ));
        }
        if bodies && !qd && spec.log == LogName::Improvements {
            return Err(
                "[evolve] log: a [morphology] scene logs generations (its genomes have no fixed columns)"
                    .into(),
            );
        }
        if choices.restarts.is_some() && optimiser != OptimiserKind::CmaEs {
            return Err(format!(
                "restarts: are for the cma-es optimiser, not {}",
                optimiser.name()
            ));
        }
        let config = Config {
            lanes: if qd {
                1
            } else {
                choices.lanes.or(spec.lanes).unwrap_or(1)
            },
            generations: choices.generations.unwrap_or(DEFAULT_GENERATIONS),
            seed: choices.seed.unwrap_or(1),
            optimiser,
            population: choices.population,
            restarts: choices.restarts.unwrap_or(0),
            // A quality-diversity run logs every generation: its archive's
            // statistics change when its best does not.
            log: match spec.log {
                LogName::Improvements if !qd => LogMode::Improvements,
                _ => LogMode::Generations,
            },
            problem,
        };
        config.validate()?;
        Ok(config)
    }

    /// The thesis's experiment (`animats evolve` without a scene): `lanes`
    /// hill-climbing lanes from Appendix B's initial parameters, 20 s
    /// evaluations at 8 ms (`scenes/hop_evolver.toml`).
    pub fn thesis(lanes: usize, generations: u64, seed: u64) -> Config {
        Config {
            lanes,
            generations,
            seed,
            optimiser: OptimiserKind::HillClimber,
            population: None,
            restarts: 0,
            problem: ProblemSpec::thesis(),
            log: LogMode::Improvements,
        }
    }

    /// Checks the configuration; the error names the field.
    pub fn validate(&self) -> Result<(), String> {
        if self.lanes == 0 || self.lanes > MAX_LANES {
            return Err(format!(
                "lanes: must be between 1 and {MAX_LANES}, got {}",
                self.lanes
            ));
        }
        Ok(())
    }

    /// Lane `lane`'s optimiser as the run starts it.
    pub fn fresh_optimiser(
        &self,
        problem: &dyn Problem,
        lane: usize,
    ) -> Result<AnyOptimiser, String> {
        AnyOptimiser::with_archive(
            &self.setup(problem, lane),
            problem.grid(),
            problem.variation().is_some(),
        )
    }

    /// The optimiser of lane `lane` for `problem`.
    pub fn setup(&self, problem: &dyn Problem, lane: usize) -> Setup {
        let bounds = if self.optimiser == OptimiserKind::HillClimber && problem.relative_mutation()
        {
            None
        } else {
            problem.bounds()
        };
        Setup {
            kind: self.optimiser,
            start: problem.start(),
            bounds,
            population: self.population,
            seed: self.seed,
            lane,
            sigma: None,
            restarts: self.restarts,
        }
    }
}

/// The size of a generation's best body (a `[morphology]` run's log).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodyRow {
    /// Particles.
    pub particles: usize,
    /// Springs, muscles included.
    pub springs: usize,
    /// Muscles.
    pub muscles: usize,
    /// kg.
    pub mass: f64,
}

/// One lane's generation: a row of the full log.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LogRow {
    /// Lane, 0-based.
    pub lane: usize,
    /// Generation, 1-based.
    pub generation: u64,
    /// Evaluations this lane has done, this generation's included.
    pub evaluations: u64,
    /// The generation's best fitness.
    pub fitness: f64,
    /// The lane's best fitness so far.
    pub best_fitness: f64,
    /// Time survived by the generation's best, s.
    pub time: f64,
    /// Its distance, m.
    pub distance: f64,
    /// Why its evaluation ended.
    pub ended: String,
    /// The new best genome, when this generation improved on the lane's best.
    pub improved: Option<Vec<f64>>,
    /// A `[morphology]` run: the generation's best body's size.
    #[serde(default)]
    pub body: Option<BodyRow>,
    /// A `[morphology]` run: variations the lane has refused so far.
    #[serde(default)]
    pub refused: Option<u64>,
    /// A quality-diversity run: its archive after this generation.
    #[serde(default)]
    pub archive: Option<ArchiveRow>,
}

/// A quality-diversity run's archive after a generation (pyribs's stats).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArchiveRow {
    /// Elites.
    pub elites: usize,
    /// Occupied share of the cells.
    pub coverage: f64,
    /// Σ (objective − `[archive] qd_offset`) over the elites.
    pub qd_score: f64,
    /// The best objective ever inserted.
    pub obj_max: f64,
}

/// The best a lane has found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Best {
    /// The genome.
    pub genome: Vec<f64>,
    /// Its fitness.
    pub fitness: f64,
    /// Time survived, s (the roobot's time upright).
    pub time: f64,
    /// Distance, m.
    pub distance: f64,
    /// Why its evaluation ended.
    pub ended: String,
}

/// Where one lane stands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Lane {
    /// Lane, 0-based.
    pub lane: usize,
    /// Generations completed.
    pub generation: u64,
    /// Evaluations done.
    pub evaluations: u64,
    /// Its optimiser's whole state.
    pub optimiser: AnyOptimiser,
    /// The best so far (`None` before the first generation).
    pub best: Option<Best>,
    /// With `[archive] overlap`: the next generation, asked before the
    /// last was told, not yet evaluated.
    #[serde(default)]
    pub ahead: Option<Ahead>,
}

/// A generation asked ahead (`[archive] overlap`): its genomes and the
/// screen of the archive it was asked from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ahead {
    /// The genomes.
    pub population: Vec<Vec<f64>>,
    /// Which of them need a robust scene's finer runs.
    pub screen: Screen,
}

/// `lane`'s next generation and its screen: the one asked ahead, if any;
/// and, when its optimiser overlaps generations, the one after it asked
/// now, before this one is told (every path — [`State::advance`] on any
/// threads, [`State::ask`] — asks and tells a lane's generations in this
/// one order).
fn ask_lane(
    lane: &mut Lane,
    variation: Option<&dyn Variation>,
) -> Result<(Vec<Vec<f64>>, Screen), String> {
    let ask = |lane: &mut Lane| ask_one(lane, variation);
    let now = match lane.ahead.take() {
        // The one after it first: refused (asked twice untold), the lane
        // stays as it was.
        Some(a) if lane.optimiser.overlaps() => match ask(lane) {
            Ok(next) => {
                lane.ahead = Some(next);
                a
            }
            Err(e) => {
                lane.ahead = Some(a);
                return Err(e);
            }
        },
        Some(a) => a,
        None => {
            let now = ask(lane)?;
            if lane.optimiser.overlaps() {
                lane.ahead = Some(ask(lane)?);
            }
            now
        }
    };
    Ok((now.population, now.screen))
}

/// One ask of `lane`'s optimiser, with the screen of its archive as it
/// stands.
fn ask_one(lane: &mut Lane, variation: Option<&dyn Variation>) -> Result<Ahead, String> {
    let population = lane.optimiser.ask_with(variation)?;
    Ok(Ahead {
        population,
        screen: lane.optimiser.screen(),
    })
}

/// Everything needed to continue a run: what a checkpoint stores.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// The run's configuration.
    pub config: Config,
    /// Each lane.
    pub lanes: Vec<Lane>,
    /// One row per lane per generation (or per improvement, as
    /// [`Config::log`] says), in (generation, lane) order.
    pub log: Vec<LogRow>,
    /// Evaluations done so far.
    pub evaluations: u64,
}

impl State {
    /// A fresh run.
    pub fn new(config: Config) -> Result<State, String> {
        config.validate()?;
        let problem = config.problem.build()?;
        let lanes = (0..config.lanes)
            .map(|lane| {
                Ok(Lane {
                    lane,
                    generation: 0,
                    evaluations: 0,
                    optimiser: config.fresh_optimiser(problem.as_ref(), lane)?,
                    best: None,
                    ahead: None,
                })
            })
            .collect::<Result<_, String>>()?;
        Ok(State {
            config,
            lanes,
            log: Vec::new(),
            evaluations: 0,
        })
    }

    /// Continues this run (read from a checkpoint) as `choices` say: only
    /// the generations may change, and not to fewer than are done.
    pub fn resume(&mut self, choices: &Choices) -> Result<(), String> {
        let c = &self.config;
        if choices.lanes.is_some_and(|l| l != c.lanes)
            || choices.seed.is_some_and(|s| s != c.seed)
            || choices.optimiser.is_some_and(|o| o != c.optimiser)
            || choices.population.is_some_and(|p| Some(p) != c.population)
            || choices.restarts.is_some_and(|r| r != c.restarts)
        {
            return Err(format!(
                "a resumed run keeps its scene, optimiser ({}), population, restarts, lanes ({}) and seed ({}); give only the generations",
                c.optimiser.name(),
                c.lanes,
                c.seed
            ));
        }
        if let Some(g) = choices.generations {
            if g < self.generation() {
                return Err(format!(
                    "generations: {g} is fewer than the {} already done",
                    self.generation()
                ));
            }
            self.config.generations = g;
        }
        Ok(())
    }

    /// Checks a state read back from a checkpoint is consistent.
    pub fn validate(&self) -> Result<(), String> {
        self.config.validate()?;
        if self.lanes.len() != self.config.lanes {
            return Err(format!(
                "{} lanes stored for a run of {}",
                self.lanes.len(),
                self.config.lanes
            ));
        }
        for (i, l) in self.lanes.iter().enumerate() {
            if l.lane != i || l.optimiser.kind() != self.config.optimiser {
                return Err(format!("lane {i} is malformed"));
            }
            if l.generation != l.optimiser.generation() {
                return Err(format!("lane {i}: its optimiser is at another generation"));
            }
            if l.generation > 0 && l.best.is_none() {
                return Err(format!("lane {i} has generations but no best"));
            }
            if let Some(a) = l.optimiser.archive() {
                a.validate().map_err(|e| format!("lane {i}: {e}"))?;
            }
        }
        if self.log.iter().any(|r| r.lane >= self.lanes.len()) {
            return Err("a log row names a lane that does not exist".into());
        }
        // Each lane's optimiser against the one the run's own scene and
        // settings make: a state edited into another shape is refused here,
        // not met part way through a generation.
        let problem = self.config.problem.build()?;
        let variation = problem.variation();
        for l in &self.lanes {
            let fresh = self.config.fresh_optimiser(problem.as_ref(), l.lane)?;
            l.optimiser
                .check_state(&fresh, variation)
                .map_err(|e| format!("lane {}'s optimiser: {e}", l.lane))?;
            let lane = |e: String| format!("lane {}: {e}", l.lane);
            let genome = |what: &str, g: &[f64]| match variation {
                Some(_) => crate::optimiser::check_body(what, g, variation),
                None => crate::optimiser::check_genome(what, g, problem.dim()),
            };
            if let Some(b) = &l.best {
                genome("its best", &b.genome).map_err(lane)?;
            }
            if let Some(a) = &l.ahead {
                for (k, g) in a.population.iter().enumerate() {
                    genome(&format!("candidate {k} asked ahead"), g).map_err(lane)?;
                }
            }
        }
        Ok(())
    }

    /// A body GA run's refused variations, all lanes together, by reason,
    /// and the children that kept their parent after every retry; `None`
    /// for a run of any other optimiser.
    pub fn refusals(&self) -> Option<(std::collections::BTreeMap<String, u64>, u64)> {
        let mut by = std::collections::BTreeMap::new();
        let mut kept = 0;
        for l in &self.lanes {
            let (r, k) = l.optimiser.refusals()?;
            for (reason, n) in r {
                *by.entry(reason.clone()).or_insert(0) += n;
            }
            kept += k;
        }
        Some((by, kept))
    }

    /// A body GA run's `n` best bodies now alive, every lane's together
    /// (their genomes, fitness and lane), best first (the lower lane, then
    /// the earlier, among equals), each genome once; `None` for a run of
    /// any other optimiser.
    pub fn best_bodies(&self, n: usize) -> Option<Vec<(Vec<f64>, f64, usize)>> {
        let mut all = Vec::new();
        for l in &self.lanes {
            match &l.optimiser {
                AnyOptimiser::BodyGa(o) => {
                    all.extend(o.parents().iter().map(|(g, f)| (g.clone(), *f, l.lane)))
                }
                _ => return None,
            }
        }
        all.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.2.cmp(&b.2)));
        let mut out: Vec<(Vec<f64>, f64, usize)> = Vec::with_capacity(n.min(all.len()));
        for body in all {
            if out.len() == n {
                break;
            }
            if !out.iter().any(|o| o.0 == body.0) {
                out.push(body);
            }
        }
        Some(out)
    }

    /// Generations completed by every lane.
    pub fn generation(&self) -> u64 {
        self.lanes.iter().map(|l| l.generation).min().unwrap_or(0)
    }

    /// True when every lane has reached the configured generations.
    pub fn done(&self) -> bool {
        self.generation() >= self.config.generations
    }

    /// Best fitness over all lanes so far.
    pub fn best_fitness(&self) -> Option<f64> {
        self.lanes
            .iter()
            .filter_map(|l| l.best.as_ref().map(|b| b.fitness))
            .max_by(f64::total_cmp)
    }

    /// The lane holding the best fitness (the first of equals).
    pub fn best_lane(&self) -> Option<&Lane> {
        let mut top: Option<(&Lane, f64)> = None;
        for l in &self.lanes {
            if let Some(b) = &l.best {
                if top.is_none_or(|(_, f)| b.fitness > f) {
                    top = Some((l, b.fitness));
                }
            }
        }
        top.map(|(l, _)| l)
    }

    /// Advances every lane by up to `generations` generations (not past the
    /// configured total); lanes and each generation's evaluations in
    /// parallel on the current rayon pool, each thread taking the free lane
    /// that has done the fewest generations of the batch.
    pub fn advance(&mut self, generations: u64) -> Result<(), String> {
        let problem = self.config.problem.build()?;
        self.advance_with(problem.as_ref(), generations)
    }

    /// [`State::advance`] with the problem already built from
    /// `self.config.problem` (a long run builds it once, not per batch).
    pub fn advance_with(&mut self, problem: &dyn Problem, generations: u64) -> Result<(), String> {
        self.advance_traced(problem, generations, None)
    }

    /// [`State::advance_with`], its work recorded by `tracer` (as one batch)
    /// when given: the same results, bit for bit.
    pub fn advance_traced(
        &mut self,
        problem: &dyn Problem,
        generations: u64,
        tracer: Option<&crate::schedule::Tracer>,
    ) -> Result<(), String> {
        self.advance_by_while(problem, generations, tracer, &|| true, None)
    }

    /// [`State::advance_traced`], but past each lane's first generation a
    /// thread takes another only while `more()` says so: a run stopped
    /// early (Python's Ctrl-C) stands at whole generations, its lanes
    /// perhaps at different ones, and goes on from there to the same bits
    /// as one never stopped (see [`State::advance_while`]). `seen` hears
    /// of each lane's generation as it ends (progress).
    pub fn advance_by_while(
        &mut self,
        problem: &dyn Problem,
        generations: u64,
        tracer: Option<&crate::schedule::Tracer>,
        more: &(dyn Fn() -> bool + Sync),
        seen: Option<&(dyn Fn(&LogRow) + Sync)>,
    ) -> Result<(), String> {
        let goals: Vec<u64> = self
            .lanes
            .iter()
            .map(|l| l.generation.saturating_add(generations))
            .collect();
        self.advance_towards(problem, &goals, tracer, more, seen)
    }

    /// [`State::advance_by_while`] with each lane's own goal: lane `k`
    /// towards generation `goals[k]` (never past the configured total),
    /// each lane not there by at least one generation, then on while
    /// `more()` says so. Python's `Evolution.run` saves a checkpoint
    /// between these, towards the goals it set at its start.
    pub fn advance_towards(
        &mut self,
        problem: &dyn Problem,
        goals: &[u64],
        tracer: Option<&crate::schedule::Tracer>,
        more: &(dyn Fn() -> bool + Sync),
        seen: Option<&(dyn Fn(&LogRow) + Sync)>,
    ) -> Result<(), String> {
        if goals.len() != self.lanes.len() {
            return Err(format!(
                "{} goals for {} lanes",
                goals.len(),
                self.lanes.len()
            ));
        }
        let target = self.config.generations;
        let todo: Vec<u64> = self
            .lanes
            .iter()
            .zip(goals)
            .map(|(l, &g)| g.min(target).saturating_sub(l.generation))
            .collect();
        let rows = advance_lanes(&mut self.lanes, &todo, problem, tracer, more, seen)?;
        if let Some(t) = tracer {
            t.next_batch();
        }
        self.extend_log(rows);
        Ok(())
    }

    /// Advances every lane towards the configured total with no lane
    /// waiting for another: each unfinished lane by at least one
    /// generation, then on while `more()` says so (checked before each
    /// further generation a thread takes); `seen` hears of each lane's
    /// generation as it ends (progress). When it returns the lanes may
    /// stand at different generations; each lane's generations still run
    /// in order, so the log, the best and a checkpoint taken now or later
    /// are the same bits on any number of threads. Its work is one batch
    /// of `tracer`'s. `animats evolve` advances a run by these, saving
    /// its checkpoint between them.
    pub fn advance_while(
        &mut self,
        problem: &dyn Problem,
        tracer: Option<&crate::schedule::Tracer>,
        more: &(dyn Fn() -> bool + Sync),
        seen: &(dyn Fn(&LogRow) + Sync),
    ) -> Result<(), String> {
        let target = self.config.generations;
        let todo: Vec<u64> = self
            .lanes
            .iter()
            .map(|l| target.saturating_sub(l.generation))
            .collect();
        let rows = advance_lanes(&mut self.lanes, &todo, problem, tracer, more, Some(seen))?;
        if let Some(t) = tracer {
            t.next_batch();
        }
        self.extend_log(rows);
        Ok(())
    }

    /// The next generation of every lane not yet at the configured total,
    /// to be evaluated elsewhere (another process, a cluster) and handed
    /// back to [`State::tell`]. A run advanced by `ask`/`tell` writes the
    /// same log, bit for bit, as one advanced by [`State::advance`].
    pub fn ask(&mut self) -> Result<Generation, String> {
        let target = self.config.generations;
        let problem = self.bodies()?;
        let variation = problem.as_ref().and_then(|p| p.variation());
        let (lanes, screens) = self
            .lanes
            .iter_mut()
            .filter(|l| l.generation < target)
            .map(|l| {
                let (population, screen) = ask_lane(l, variation)?;
                Ok(((l.lane, population), screen))
            })
            .collect::<Result<Vec<_>, String>>()?
            .into_iter()
            .unzip();
        Ok(Generation { lanes, screens })
    }

    /// The problem, built, when its bodies evolve (asking and telling need
    /// its variation and its bodies' sizes); `None` otherwise.
    fn bodies(&self) -> Result<Option<Box<dyn Problem>>, String> {
        if self.config.optimiser == OptimiserKind::BodyGa
            || self.config.optimiser == OptimiserKind::MapElites
        {
            self.config.problem.build().map(Some)
        } else {
            Ok(None)
        }
    }

    /// Takes the outcomes of `generation`'s genomes, in the order of
    /// [`Generation::genomes`].
    pub fn tell(&mut self, generation: &Generation, outcomes: &[Outcome]) -> Result<(), String> {
        let asked = generation.len();
        if outcomes.len() != asked {
            return Err(format!(
                "{} outcomes told for a generation of {asked} genomes",
                outcomes.len()
            ));
        }
        let problem = self.bodies()?;
        let mut rows = Vec::with_capacity(generation.lanes.len());
        let mut at = 0;
        for (lane, population) in &generation.lanes {
            let (lane, n) = (*lane, population.len());
            let l = self
                .lanes
                .get_mut(lane)
                .ok_or_else(|| format!("lane {lane} does not exist"))?;
            rows.push(record(
                l,
                problem.as_deref(),
                population,
                &outcomes[at..at + n],
            )?);
            at += n;
        }
        self.extend_log(rows);
        Ok(())
    }

    fn extend_log(&mut self, mut rows: Vec<LogRow>) {
        self.evaluations = self.lanes.iter().map(|l| l.evaluations).sum();
        // A log of improvements (Table 6's shape) keeps only those: a long
        // run keeps few rows in memory and in its checkpoint.
        if self.config.log == LogMode::Improvements {
            rows.retain(|r| r.improved.is_some());
        }
        // Lanes advanced by `advance_while` need not stand level: the log
        // is kept in (generation, lane) order as a whole (a sort that finds
        // the old rows already in order, so about linear).
        self.log.extend(rows);
        self.log.sort_by_key(|r| (r.generation, r.lane));
    }

    /// `best.toml`, as `animats evolve` writes it: the whole scene with the
    /// best lane's genome written in. `None` before the first generation.
    pub fn best_toml(&self) -> Result<Option<String>, String> {
        match self.best_lane() {
            Some(lane) => self.lane_toml(lane.lane),
            None => Ok(None),
        }
    }

    /// Lane `lane`'s best as a whole scene (`lanes/K.toml`); `None` before
    /// its first generation or for a lane that does not exist.
    pub fn lane_toml(&self, lane: usize) -> Result<Option<String>, String> {
        let Some(l) = self.lanes.get(lane) else {
            return Ok(None);
        };
        let Some(best) = &l.best else {
            return Ok(None);
        };
        let problem = self.config.problem.build()?;
        let what = if problem.variation().is_some() {
            "body and brain"
        } else {
            "controller"
        };
        let comment = format!(
            "{} with the best {what} of lane {lane} of `animats evolve` ({}, seed {}, {} lanes, generation {}):\nfitness {}, distance {} m, time {} s, ended: {}.\nReproduce it with `animats evaluate FILE`; watch it with `animats view FILE`.",
            self.config.problem.file,
            self.config.optimiser.name(),
            self.config.seed,
            self.config.lanes,
            self.generation(),
            best.fitness,
            best.distance,
            best.time,
            best.ended
        );
        problem.scene_toml(&best.genome, &comment).map(Some)
    }

    /// `log.csv`: one row per lane per generation, or, for a log of
    /// improvements, the thesis's Table 6 shape: one row per improvement
    /// with its genes (`p0`, `p1`...; `time_up` is the time survived).
    /// Numbers in their shortest round-trip form.
    pub fn log_csv(&self) -> String {
        let mut b = ryu::Buffer::new();
        let mut out = String::new();
        if self.config.log == LogMode::Improvements {
            out.push_str("lane,generation,fitness,time_up,distance");
            let genes = self
                .lanes
                .iter()
                .find_map(|l| l.best.as_ref())
                .map_or(0, |b| b.genome.len());
            for i in 0..genes {
                out.push_str(&format!(",p{i}"));
            }
            out.push('\n');
            for r in &self.log {
                let Some(params) = &r.improved else { continue };
                out.push_str(&format!("{},{}", r.lane, r.generation));
                for x in [r.fitness, r.time, r.distance].iter().chain(params) {
                    out.push(',');
                    out.push_str(b.format(*x));
                }
                out.push('\n');
            }
        } else {
            let bodies = self.log.iter().any(|r| r.body.is_some())
                || self.config.optimiser == OptimiserKind::BodyGa;
            let qd = self.config.optimiser.qd().is_some();
            out.push_str("lane,generation,evaluations,fitness,best_fitness,time,distance,ended");
            if bodies {
                out.push_str(",particles,springs,muscles,mass,refused");
            }
            if qd {
                out.push_str(",elites,coverage,qd_score,obj_max");
            }
            out.push('\n');
            for r in &self.log {
                out.push_str(&format!("{},{},{}", r.lane, r.generation, r.evaluations));
                for x in [r.fitness, r.best_fitness, r.time, r.distance] {
                    out.push(',');
                    out.push_str(b.format(x));
                }
                out.push(',');
                out.push_str(&r.ended);
                if bodies {
                    match &r.body {
                        Some(s) => {
                            out.push_str(&format!(",{},{},{},", s.particles, s.springs, s.muscles));
                            out.push_str(b.format(s.mass));
                        }
                        None => out.push_str(",,,,"),
                    }
                    out.push_str(&format!(",{}", r.refused.unwrap_or(0)));
                }
                if qd {
                    match &r.archive {
                        Some(a) => {
                            out.push_str(&format!(",{}", a.elites));
                            for x in [a.coverage, a.qd_score, a.obj_max] {
                                out.push(',');
                                out.push_str(b.format(x));
                            }
                        }
                        None => out.push_str(",,,,"),
                    }
                }
                out.push('\n');
            }
        }
        out
    }

    /// The archive of a quality-diversity run (its one lane's).
    pub fn archive(&self) -> Option<&crate::archive::GridArchive> {
        self.lanes.first().and_then(|l| l.optimiser.archive())
    }

    /// Every elite of a quality-diversity run as a whole scene
    /// (`elites/<index>.toml`), with its cell index, in the order the
    /// cells were first filled: `animats evaluate` reproduces each one's
    /// fitness and measures bit for bit. Empty for any other run. Made
    /// side by side on the caller's rayon pool.
    pub fn elite_tomls(&self) -> Result<Vec<(u64, String)>, String> {
        use rayon::prelude::*;
        let Some(archive) = self.archive() else {
            return Ok(Vec::new());
        };
        // Built once for all the elites.
        let problem = self.config.problem.build()?;
        let made: Vec<Result<(u64, String), String>> = archive
            .elites()
            .par_iter()
            .map(|e| Ok((e.index, self.elite_scene(problem.as_ref(), archive, e)?)))
            .collect();
        made.into_iter().collect()
    }

    /// One elite of the archive as a whole scene, as [`State::elite_tomls`]
    /// writes it.
    pub fn elite_toml(&self, elite: &crate::archive::Elite) -> Result<String, String> {
        let archive = self
            .archive()
            .ok_or("the run keeps no archive: it has no elites")?;
        let problem = self.config.problem.build()?;
        self.elite_scene(problem.as_ref(), archive, elite)
    }

    /// `e` as a whole scene of `problem`, its comment naming its cell,
    /// measures and scores.
    fn elite_scene(
        &self,
        problem: &dyn Problem,
        archive: &crate::archive::GridArchive,
        e: &crate::archive::Elite,
    ) -> Result<String, String> {
        let cell: Vec<String> = archive
            .unravel(e.index)
            .iter()
            .map(|c| c.to_string())
            .collect();
        let measures: Vec<String> = archive
            .grid
            .names
            .iter()
            .zip(&e.measures)
            .map(|(n, m)| format!("{n} = {m}"))
            .collect();
        let comment = format!(
            "{} with elite {} (cell [{}]) of `animats evolve` ({}, seed {}, generation {}):\nfitness {}, distance {} m, time {} s, ended: {}; measures: {}.\nReproduce it with `animats evaluate FILE --json`; watch it with `animats view FILE`.",
            self.config.problem.file,
            e.index,
            cell.join(", "),
            self.config.optimiser.name(),
            self.config.seed,
            self.generation(),
            e.objective,
            e.distance,
            e.time,
            e.ended,
            measures.join(", ")
        );
        problem.scene_toml(&e.genome, &comment)
    }

    /// `archive.csv`: one row per occupied cell, in cell order, with
    /// pyribs's columns (`index`, `objective`, `measures_0`…), then
    /// `threshold`, `time`, `distance`, `ended` and the genome
    /// (`solution_0`…; a body's genomes differ in length: its own).
    pub fn archive_csv(&self) -> Option<String> {
        let archive = self.archive()?;
        let mut b = ryu::Buffer::new();
        let k = archive.grid.names.len();
        let genes = archive
            .elites()
            .iter()
            .map(|e| e.genome.len())
            .max()
            .unwrap_or(0);
        let mut out = String::from("index,objective");
        for i in 0..k {
            out.push_str(&format!(",measures_{i}"));
        }
        out.push_str(",threshold,time,distance,ended");
        for i in 0..genes {
            out.push_str(&format!(",solution_{i}"));
        }
        out.push('\n');
        let mut elites: Vec<&crate::archive::Elite> = archive.elites().iter().collect();
        elites.sort_by_key(|e| e.index);
        for e in elites {
            out.push_str(&e.index.to_string());
            for x in std::iter::once(&e.objective).chain(&e.measures).chain([
                &e.threshold,
                &e.time,
                &e.distance,
            ]) {
                out.push(',');
                out.push_str(b.format(*x));
            }
            out.push(',');
            out.push_str(&e.ended);
            for x in &e.genome {
                out.push(',');
                out.push_str(b.format(*x));
            }
            out.push('\n');
        }
        Some(out)
    }

    /// Best fitness of each lane after each generation (a step function of
    /// the log), for plots.
    pub fn fitness_curves(&self) -> Vec<Vec<(u64, f64)>> {
        let mut curves = vec![Vec::new(); self.lanes.len()];
        for r in &self.log {
            if r.improved.is_some() {
                curves[r.lane].push((r.generation, r.best_fitness));
            }
        }
        for (curve, lane) in curves.iter_mut().zip(&self.lanes) {
            if let (Some(&(_, f)), true) = (curve.last(), lane.generation > 0) {
                curve.push((lane.generation, f));
            }
        }
        curves
    }
}

/// Advances lane `k` by `todo[k]` generations, on every thread of the
/// current rayon pool, one generation at a time: a thread that has finished
/// a generation takes next the free lane that has done the fewest (the
/// lowest-numbered among equals). A lane's generations still run one after
/// another, each a pure function of the one before, so the results do not
/// depend on which thread runs what; but no thread waits for another at the
/// end of a lane's share, as it would with a lane per task (the thesis's six
/// lanes on two threads, lanes of unequal cost: 4.66 s against 4.0 s for
/// half the work of one thread). No thread ever blocks: one that finds every
/// unfinished lane taken stops, since what is left is sequential.
///
/// Past each lane's first generation, a thread takes another only while
/// `more()` says so; `seen` hears of each generation's row as it ends.
fn advance_lanes(
    lanes: &mut [Lane],
    todo: &[u64],
    problem: &dyn Problem,
    tracer: Option<&crate::schedule::Tracer>,
    more: &(dyn Fn() -> bool + Sync),
    seen: Option<&(dyn Fn(&LogRow) + Sync)>,
) -> Result<Vec<LogRow>, String> {
    use std::sync::Mutex;
    // One lane that overlaps its generations, evaluated here: its
    // generations in flight together.
    if let ([lane], [todo]) = (&mut *lanes, todo) {
        if lane.optimiser.overlaps() && !problem.in_batches() && *todo > 0 {
            return advance_overlapped(lane, *todo, problem, tracer, more, seen);
        }
    }
    struct Slot<'a> {
        /// `None` while a thread advances it.
        lane: Option<&'a mut Lane>,
        done: u64,
        todo: u64,
    }
    struct Board<'a> {
        slots: Vec<Slot<'a>>,
        rows: Vec<LogRow>,
        /// The first error, by lane.
        error: Option<(usize, String)>,
    }
    let board = Mutex::new(Board {
        slots: lanes
            .iter_mut()
            .zip(todo)
            .map(|(lane, &todo)| Slot {
                lane: Some(lane),
                done: 0,
                todo,
            })
            .collect(),
        rows: Vec::new(),
        error: None,
    });
    let work = || loop {
        let taken = {
            let Ok(mut b) = board.lock() else { return };
            if b.error.is_some() {
                return;
            }
            let next = b
                .slots
                .iter()
                .enumerate()
                .filter(|(_, s)| s.lane.is_some() && s.done < s.todo)
                .min_by_key(|(k, s)| (s.done, *k))
                .map(|(k, s)| (k, s.done));
            let Some((k, done)) = next else { return };
            // The fewest done first: a lane past its first generation
            // means every free lane is, so `more` decides for all.
            if done > 0 && !more() {
                return;
            }
            b.slots[k].lane.take().map(|lane| (k, lane))
        };
        let Some((k, lane)) = taken else { return };
        let result = advance_lane(lane, problem, 1, tracer);
        let Ok(mut b) = board.lock() else { return };
        match result {
            Ok(rows) => {
                if let Some(seen) = seen {
                    rows.iter().for_each(seen);
                }
                b.rows.extend(rows)
            }
            Err(e) => {
                if b.error.as_ref().is_none_or(|(j, _)| k < *j) {
                    b.error = Some((k, e));
                }
            }
        }
        let slot = &mut b.slots[k];
        slot.done += 1;
        slot.lane = Some(lane);
    };
    let threads = rayon::current_num_threads().min(lanes_len(todo)).max(1);
    (0..threads).into_par_iter().for_each(|_| work());
    let board = board
        .into_inner()
        .map_err(|_| "an evaluation panicked".to_string())?;
    match board.error {
        Some((_, e)) => Err(e),
        None => Ok(board.rows),
    }
}

/// How many lanes have generations to do.
fn lanes_len(todo: &[u64]) -> usize {
    todo.iter().filter(|&&n| n > 0).count()
}

/// Generations of one lane; rows in generation order; each piece of work
/// recorded by `tracer` if given.
fn advance_lane(
    lane: &mut Lane,
    problem: &dyn Problem,
    n: u64,
    tracer: Option<&crate::schedule::Tracer>,
) -> Result<Vec<LogRow>, String> {
    use crate::schedule::Piece;
    let mut rows = Vec::with_capacity(n as usize);
    for _ in 0..n {
        let (k, g) = (lane.lane, lane.generation);
        let (population, screen) = traced_ask(problem, tracer, k, g, |v| ask_lane(lane, v))?;
        let batch = problem.evaluate_population(&population, &|_, o| screen.fine(o));
        let outcomes: Vec<Outcome> = match batch {
            Some(batch) => batch?,
            None => longest_first(problem, &population, &|i, position, genome| {
                let began = std::time::Instant::now();
                let o = problem.evaluate_screened(genome, &screen);
                if let Some(t) = tracer {
                    t.done_evaluation(k, g, i, position, began);
                }
                o
            })?,
        };
        let began = std::time::Instant::now();
        rows.push(record(lane, Some(problem), &population, &outcomes)?);
        if let Some(t) = tracer {
            t.done(k, g, Piece::Tell, began);
        }
    }
    Ok(rows)
}

/// `ask(variation)` for lane `k`'s generation `g`, its time recorded by
/// `tracer` if given: the ask as one piece, each child's making (in
/// parallel, inside the ask) as one of its own.
fn traced_ask<T>(
    problem: &dyn Problem,
    tracer: Option<&crate::schedule::Tracer>,
    k: usize,
    g: u64,
    ask: impl FnOnce(Option<&dyn Variation>) -> Result<T, String>,
) -> Result<T, String> {
    use crate::schedule::Piece;
    let began = std::time::Instant::now();
    let timed = tracer.and(problem.variation()).map(|inner| Timed {
        inner,
        made: std::sync::Mutex::new(None),
    });
    let variation = match &timed {
        Some(t) => Some(t as &dyn Variation),
        None => problem.variation(),
    };
    let out = ask(variation)?;
    if let Some(t) = tracer {
        let made = timed.and_then(|t| t.made.into_inner().ok().flatten());
        let children = made.as_ref().map_or(0.0, |m| m.1);
        t.done_part(k, g, Piece::Ask, began, children);
        for (i, &s) in made.iter().flat_map(|m| m.0.iter()).enumerate() {
            t.done_seconds(k, g, Piece::Vary(i), s);
        }
    }
    Ok(out)
}

/// Up to `todo` generations of one lane whose optimiser overlaps them
/// (`[archive] overlap`), the next generation evaluated while the last
/// still is: each evaluation a task of the current rayon pool (a
/// generation's longest first), each generation told, in order, by the
/// thread that ends its last evaluation, which then asks the generation
/// after the next. The optimiser asks and tells in the order of
/// [`ask_lane`], so the log and the best are those of [`advance_lane`] on
/// any threads. A generation is started only while `more()` says so; the
/// one asked last waits in [`Lane::ahead`].
fn advance_overlapped(
    lane: &mut Lane,
    todo: u64,
    problem: &dyn Problem,
    tracer: Option<&crate::schedule::Tracer>,
    more: &(dyn Fn() -> bool + Sync),
    seen: Option<&(dyn Fn(&LogRow) + Sync)>,
) -> Result<Vec<LogRow>, String> {
    use std::sync::atomic::AtomicBool;
    use std::sync::Mutex;
    let k = lane.lane;
    let (first, last) = (lane.generation, lane.generation + todo);
    let start = Flight::new(
        first,
        traced_ask(problem, tracer, k, first, |v| ask_lane(lane, v))?,
    );
    let next = match lane.ahead.take() {
        Some(a) if first + 1 < last && more() => {
            Some(Flight::new(first + 1, (a.population, a.screen)))
        }
        other => {
            lane.ahead = other;
            None
        }
    };
    let ctx = Overlapped {
        pipe: Mutex::new(Pipe {
            lane: Some(lane),
            ended: Default::default(),
            next_in_flight: next.is_some(),
            rows: Vec::new(),
            error: None,
        }),
        stop: AtomicBool::new(false),
        problem,
        tracer,
        more,
        seen,
        k,
        last,
    };
    rayon::in_place_scope_fifo(|scope| {
        ctx.launch(scope, start);
        if let Some(next) = next {
            ctx.launch(scope, next);
        }
    });
    let p = ctx
        .pipe
        .into_inner()
        .map_err(|_| "an evaluation panicked".to_string())?;
    match p.error {
        Some(e) => Err(e),
        None => Ok(p.rows),
    }
}

/// A generation in flight ([`advance_overlapped`]).
struct Flight {
    generation: u64,
    population: Vec<Vec<f64>>,
    screen: Screen,
    outcomes: Vec<std::sync::OnceLock<Result<Outcome, String>>>,
    left: std::sync::atomic::AtomicUsize,
}

impl Flight {
    fn new(
        generation: u64,
        (population, screen): (Vec<Vec<f64>>, Screen),
    ) -> std::sync::Arc<Flight> {
        std::sync::Arc::new(Flight {
            generation,
            outcomes: (0..population.len())
                .map(|_| std::sync::OnceLock::new())
                .collect(),
            left: std::sync::atomic::AtomicUsize::new(population.len()),
            population,
            screen,
        })
    }
}

/// What the telling thread works on ([`advance_overlapped`]).
struct Pipe<'a> {
    /// `None` while a thread tells.
    lane: Option<&'a mut Lane>,
    /// Generations whose evaluations have all ended, not yet told.
    ended: std::collections::BTreeMap<u64, std::sync::Arc<Flight>>,
    /// Whether the generation after the one told last is in flight.
    next_in_flight: bool,
    rows: Vec<LogRow>,
    error: Option<String>,
}

/// [`advance_overlapped`]'s run.
struct Overlapped<'a> {
    pipe: std::sync::Mutex<Pipe<'a>>,
    /// Set on an error: evaluations not yet started are skipped.
    stop: std::sync::atomic::AtomicBool,
    problem: &'a dyn Problem,
    tracer: Option<&'a crate::schedule::Tracer>,
    more: &'a (dyn Fn() -> bool + Sync),
    seen: Option<&'a (dyn Fn(&LogRow) + Sync)>,
    k: usize,
    /// The first generation not to start.
    last: u64,
}

impl<'a> Overlapped<'a> {
    /// Starts every evaluation of `f`, its longest first.
    fn launch<'s>(&'s self, scope: &rayon::ScopeFifo<'s>, f: std::sync::Arc<Flight>)
    where
        'a: 's,
    {
        use std::sync::atomic::Ordering;
        if f.population.is_empty() {
            // Nothing to evaluate: told at once (and refused there).
            self.ended(scope, f);
            return;
        }
        for (position, i) in start_order(self.problem, &f.population)
            .into_iter()
            .enumerate()
        {
            let f = f.clone();
            scope.spawn_fifo(move |scope| {
                let outcome = if self.stop.load(Ordering::Relaxed) {
                    Err("not evaluated: the run stopped".into())
                } else {
                    let began = std::time::Instant::now();
                    let o = self.problem.evaluate_screened(&f.population[i], &f.screen);
                    if let Some(t) = self.tracer {
                        t.done_evaluation(self.k, f.generation, i, position, began);
                    }
                    o
                };
                let _ = f.outcomes[i].set(outcome);
                if f.left.fetch_sub(1, Ordering::AcqRel) == 1 {
                    self.ended(scope, f);
                }
            });
        }
    }

    /// Generation `f`'s evaluations have all ended. The first thread to
    /// find the lane free takes it and tells every generation that can be
    /// told, in order, each followed by the ask of the generation after
    /// the next (started if the batch goes on, else kept ahead); it holds
    /// no lock while it tells or asks (an ask makes its children on the
    /// pool, and a thread waiting for them may end another generation).
    fn ended<'s>(&'s self, scope: &rayon::ScopeFifo<'s>, f: std::sync::Arc<Flight>)
    where
        'a: 's,
    {
        use crate::schedule::Piece;
        use std::sync::atomic::Ordering;
        let lane = {
            let Ok(mut p) = self.pipe.lock() else { return };
            p.ended.insert(f.generation, f);
            p.lane.take()
        };
        // Another thread is telling: it will find this generation.
        let Some(lane) = lane else { return };
        let fail = |e: String| {
            if let Ok(mut p) = self.pipe.lock() {
                p.error.get_or_insert(e);
            }
            self.stop.store(true, Ordering::Relaxed);
        };
        loop {
            let told = lane.generation;
            let (f, next_in_flight) = {
                let Ok(mut p) = self.pipe.lock() else { return };
                let f = if p.error.is_none() {
                    p.ended.remove(&told)
                } else {
                    None
                };
                match f {
                    Some(f) => (f, std::mem::take(&mut p.next_in_flight)),
                    None => {
                        p.lane = Some(lane);
                        return;
                    }
                }
            };
            let outcomes: Result<Vec<Outcome>, String> = f
                .outcomes
                .iter()
                .map(|o| {
                    o.get()
                        .cloned()
                        .unwrap_or_else(|| Err("an evaluation was never run".into()))
                })
                .collect();
            let began = std::time::Instant::now();
            let row = outcomes.and_then(|o| record(lane, Some(self.problem), &f.population, &o));
            let row = match row {
                Ok(row) => row,
                Err(e) => {
                    fail(e);
                    continue;
                }
            };
            if let Some(t) = self.tracer {
                t.done(self.k, told, Piece::Tell, began);
            }
            if let Some(seen) = self.seen {
                seen(&row);
            }
            if let Ok(mut p) = self.pipe.lock() {
                p.rows.push(row);
            }
            if !next_in_flight {
                continue;
            }
            // The generation after the next, asked before the next is told.
            let g = told + 2;
            let asked = traced_ask(self.problem, self.tracer, self.k, g, |v| ask_one(lane, v));
            match asked {
                Ok(a) if g < self.last && (self.more)() => {
                    if let Ok(mut p) = self.pipe.lock() {
                        p.next_in_flight = true;
                    }
                    self.launch(scope, Flight::new(g, (a.population, a.screen)));
                }
                Ok(a) => lane.ahead = Some(a),
                Err(e) => fail(e),
            }
        }
    }
}

/// The order a generation's evaluations start in: the longest first where
/// the problem can guess their costs ([`Problem::cost`]; ties, and
/// problems that cannot guess, in the population's order).
fn start_order(problem: &dyn Problem, population: &[Vec<f64>]) -> Vec<usize> {
    let costs: Vec<Option<f64>> = population.iter().map(|g| problem.cost(g)).collect();
    let mut order: Vec<usize> = (0..population.len()).collect();
    if costs.iter().all(Option::is_some) {
        let c = |i: usize| costs[i].unwrap_or(0.0);
        order.sort_by(|&a, &b| c(b).total_cmp(&c(a)).then(a.cmp(&b)));
    }
    order
}

/// A problem's variation that notes how long its children took to make
/// (for the schedule model), and otherwise is the problem's own.
struct Timed<'a> {
    inner: &'a dyn Variation,
    /// Each child's seconds and the wall time of making them all.
    made: std::sync::Mutex<Option<(Vec<f64>, f64)>>,
}

impl Variation for Timed<'_> {
    fn start(&self) -> Option<Vec<f64>> {
        self.inner.start()
    }
    fn random(&self, rng: &mut crate::optimiser::Random) -> Vec<f64> {
        self.inner.random(rng)
    }
    fn mutate(&self, parent: &[f64], rng: &mut crate::optimiser::Random) -> Vec<f64> {
        self.inner.mutate(parent, rng)
    }
    fn crossover(&self, a: &[f64], b: &[f64], rng: &mut crate::optimiser::Random) -> Vec<f64> {
        self.inner.crossover(a, b, rng)
    }
    fn check(&self, genome: &[f64]) -> Result<(), &'static str> {
        self.inner.check(genome)
    }
    fn made(&self, children: &[f64], wall: f64) {
        if let Ok(mut m) = self.made.lock() {
            let (all, total) = m.get_or_insert_with(Default::default);
            all.extend_from_slice(children);
            *total += wall;
        }
    }
}

/// An evaluation of candidate `index`, the `position`-th its generation
/// starts, of `genome`: `evaluate(index, position, genome)`.
type EvaluateAt<'a> = dyn Fn(usize, usize, &[f64]) -> Result<Outcome, String> + Sync + 'a;

/// Evaluates every genome of `population` with `evaluate(index, position,
/// genome)` on the current rayon pool, the longest first where the problem
/// can guess their costs ([`Problem::cost`]; ties, and problems that
/// cannot guess, in the population's order): each free thread takes the
/// next evaluation in that order, so the last to start are the shortest and
/// the generation's end waits less for a long one started late (Graham's
/// longest-processing-time rule). Each evaluation is a pure function of its
/// genome: the outcomes, in the population's order, are the same whatever
/// the order and the threads. The first error in the population's order is
/// returned.
fn longest_first(
    problem: &dyn Problem,
    population: &[Vec<f64>],
    evaluate: &EvaluateAt<'_>,
) -> Result<Vec<Outcome>, String> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::OnceLock;
    let n = population.len();
    let order = start_order(problem, population);
    let next = AtomicUsize::new(0);
    let slots: Vec<OnceLock<Result<Outcome, String>>> = (0..n).map(|_| OnceLock::new()).collect();
    let threads = rayon::current_num_threads().min(n).max(1);
    (0..threads).into_par_iter().for_each(|_| loop {
        let position = next.fetch_add(1, Ordering::Relaxed);
        let Some(&i) = order.get(position) else {
            return;
        };
        let _ = slots[i].set(evaluate(i, position, &population[i]));
    });
    slots
        .into_iter()
        .map(|s| {
            s.into_inner()
                .unwrap_or_else(|| Err("an evaluation was never run".into()))
        })
        .collect()
}

/// Tells `lane`'s optimiser how its `population` fared and keeps its best:
/// one generation's log row.
fn record(
    lane: &mut Lane,
    problem: Option<&dyn Problem>,
    population: &[Vec<f64>],
    outcomes: &[Outcome],
) -> Result<LogRow, String> {
    if population.is_empty() || population.len() != outcomes.len() {
        return Err(format!(
            "lane {}: {} outcomes for a generation of {} genomes",
            lane.lane,
            outcomes.len(),
            population.len()
        ));
    }
    let fitness: Vec<f64> = outcomes.iter().map(|o| o.fitness).collect();
    lane.optimiser.tell_outcomes(outcomes)?;
    lane.generation += 1;
    lane.evaluations += population.len() as u64;
    // The generation's best (the first of equals).
    let mut top = 0;
    for (i, f) in fitness.iter().enumerate() {
        if crate::optimiser::sane(*f) > crate::optimiser::sane(fitness[top]) {
            top = i;
        }
    }
    let o = &outcomes[top];
    let f = crate::optimiser::sane(o.fitness);
    let improved = lane.best.as_ref().is_none_or(|b| f > b.fitness);
    let ended = o.ended.to_string();
    if improved {
        lane.best = Some(Best {
            genome: population[top].clone(),
            fitness: f,
            time: o.time,
            distance: o.distance,
            ended: ended.clone(),
        });
    }
    let body = problem
        .and_then(|p| p.stats(&population[top]))
        .map(|s| BodyRow {
            particles: s.particles,
            springs: s.springs,
            muscles: s.muscles,
            mass: s.mass,
        });
    Ok(LogRow {
        lane: lane.lane,
        generation: lane.generation,
        evaluations: lane.evaluations,
        fitness: o.fitness,
        best_fitness: lane.best.as_ref().map_or(o.fitness, |b| b.fitness),
        time: o.time,
        distance: o.distance,
        ended,
        improved: improved.then(|| population[top].clone()),
        body,
        refused: lane.optimiser.refused(),
        archive: lane.optimiser.archive().map(|a| {
            let s = a.stats();
            ArchiveRow {
                elites: s.elites,
                coverage: s.coverage,
                qd_score: s.qd_score,
                obj_max: s.obj_max.unwrap_or(f64::NAN),
            }
        }),
    })
}

/// One generation of a run handed out by [`State::ask`]: each lane's
/// population.
#[derive(Clone, Debug, PartialEq)]
pub struct Generation {
    /// (lane, its population), in lane order.
    pub lanes: Vec<(usize, Vec<Vec<f64>>)>,
    /// Each lane's [`Screen`]: which of its genomes need a robust scene's
    /// half-step run. Evaluate genome `i` with
    /// [`Problem::evaluate_screened`] and [`Generation::screen`]`(i)` to
    /// write the log that [`State::advance`] writes.
    pub screens: Vec<Screen>,
}

impl Generation {
    /// Genomes in all.
    pub fn len(&self) -> usize {
        self.lanes.iter().map(|(_, p)| p.len()).sum()
    }

    /// True when every lane is done: nothing to evaluate.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The screen of genome `i` (in the order of
    /// [`Generation::genomes`]): its lane's.
    pub fn screen(&self, mut i: usize) -> &Screen {
        for ((_, p), s) in self.lanes.iter().zip(&self.screens) {
            if i < p.len() {
                return s;
            }
            i -= p.len();
        }
        static ALL: Screen = Screen::All;
        &ALL
    }

    /// Every genome, lane by lane.
    pub fn genomes(&self) -> impl Iterator<Item = &[f64]> {
        self.lanes
            .iter()
            .flat_map(|(_, p)| p.iter().map(|g| g.as_slice()))
    }
}
