//! `Optimiser` (one lane's ask/tell strategy) and `Evolution` (a whole
//! `animats evolve` run: lanes, log, best), both the Rust ones: the same
//! seed gives the same candidates, log and best.toml as the command line.

use crate::evaluate::{build, outcome_dict, outcomes, problem_spec};
use crate::{pool, runtime_error, value_error};
use animats_evolve::optimiser::{Bounds, Optimiser as _};
use animats_evolve::run::Generation;
use animats_evolve::screen::Screen;
use animats_evolve::{
    AnyOptimiser, Choices, Config, OptimiserKind, Outcome, ProblemSpec, Setup, State,
};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

fn kind(name: &str) -> PyResult<OptimiserKind> {
    OptimiserKind::parse(name).map_err(value_error)
}

fn matrix<'py>(
    py: Python<'py>,
    rows: &[Vec<f64>],
    d: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    let a = Array2::from_shape_vec((rows.len(), d), flat).map_err(runtime_error)?;
    Ok(a.into_pyarray(py))
}

/// One lane's optimiser: `ask()` a population, `tell(fitness)`; maximises.
#[pyclass(module = "animats")]
pub struct Optimiser {
    inner: AnyOptimiser,
    dim: usize,
    asked: bool,
    /// The problem it was made for, if any (for `best_toml`).
    problem: Option<animats_evolve::ProblemSpec>,
}

#[pymethods]
impl Optimiser {
    /// `kind`: "hill-climber", "ga" or "cma-es". Give `problem` (an
    /// `animats.Scene`, a path or "roobot") to start from its parameters
    /// within its bounds exactly as `animats evolve` does, or `dim` / `start`
    /// (and optionally `bounds`, a `(D, 2)` array) for a problem of your own.
    /// `lane` picks the random stream (and the hill climber's step size) as
    /// the lanes of `animats evolve` do.
    #[new]
    #[pyo3(signature = (kind, dim = None, seed = 0, *, start = None, bounds = None, population = None, lane = 0, sigma = None, restarts = 0, problem = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        kind: &str,
        dim: Option<usize>,
        seed: u64,
        start: Option<PyReadonlyArray1<'_, f64>>,
        bounds: Option<PyReadonlyArray2<'_, f64>>,
        population: Option<usize>,
        lane: usize,
        sigma: Option<f64>,
        restarts: u32,
        problem: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Optimiser> {
        let kind = self::kind(kind)?;
        let spec = problem.map(problem_spec).transpose()?;
        let mut setup = match &spec {
            Some(spec) => {
                let problem = build(spec)?;
                let config = Config {
                    optimiser: kind,
                    population,
                    restarts,
                    seed,
                    ..Config::thesis(lane + 1, 1, seed)
                };
                config.setup(problem.as_ref(), lane)
            }
            None => Setup {
                kind,
                start: Vec::new(),
                bounds: None,
                population,
                seed,
                lane,
                sigma,
                restarts,
            },
        };
        setup.lane = lane;
        if let Some(s) = start {
            setup.start = s.as_array().to_vec();
        } else if setup.start.is_empty() {
            let d = dim.ok_or_else(|| value_error("give dim, start or problem"))?;
            // (Checked before the zeros are made: 2**40 of them hung.)
            if d > animats_evolve::optimiser::MAX_GENES {
                return Err(value_error(format!(
                    "dim: {d} genes, more than any optimiser takes ({})",
                    animats_evolve::optimiser::MAX_GENES
                )));
            }
            setup.start = vec![0.0; d];
        }
        if let Some(d) = dim {
            if d != setup.start.len() {
                return Err(value_error(format!(
                    "dim is {d} but the start has {} genes",
                    setup.start.len()
                )));
            }
        }
        if let Some(b) = bounds {
            let b = b.as_array();
            if b.ncols() != 2 {
                return Err(value_error("bounds must be a (D, 2) array of (low, high)"));
            }
            setup.bounds = Some(Bounds {
                lo: b.column(0).to_vec(),
                hi: b.column(1).to_vec(),
            });
        }
        if sigma.is_some() {
            setup.sigma = sigma;
        }
        let dim = setup.start.len();
        Ok(Optimiser {
            inner: AnyOptimiser::new(&setup).map_err(value_error)?,
            dim,
            asked: false,
            problem: spec,
        })
    }

    /// The next population, a `(P, D)` array.
    fn ask<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        if self.asked {
            return Err(value_error("tell the fitness of the last population first"));
        }
        let pop = self.inner.ask();
        self.asked = true;
        matrix(py, &pop, self.dim)
    }

    /// The fitness of each row of the last `ask()` (higher is better;
    /// NaN counts as the worst).
    fn tell(&mut self, fitness: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        if !self.asked {
            return Err(value_error("ask for a population first"));
        }
        self.inner
            .tell(&fitness.as_array().to_vec())
            .map_err(value_error)?;
        self.asked = false;
        Ok(())
    }

    /// Generations told so far.
    #[getter]
    fn generation(&self) -> u64 {
        self.inner.generation()
    }

    /// The genome's length.
    #[getter]
    fn dim(&self) -> usize {
        self.dim
    }

    /// The kind's name.
    #[getter]
    fn kind(&self) -> &'static str {
        self.inner.kind().name()
    }

    /// The best genome told so far and its fitness, or None.
    fn best<'py>(&self, py: Python<'py>) -> Option<(Bound<'py, PyArray1<f64>>, f64)> {
        self.inner
            .best()
            .map(|(g, f)| (PyArray1::from_vec(py, g.to_vec()), f))
    }

    /// The scene with the best genome so far written in, as `animats
    /// evolve` writes `best.toml` (None before anything was told); only for
    /// an optimiser made with `problem`.
    fn best_toml(&self) -> PyResult<Option<String>> {
        let spec = self.problem.as_ref().ok_or_else(|| {
            value_error("this optimiser has no problem: make it with problem=SCENE, or use scene.best_toml(genome)")
        })?;
        let Some((genome, fitness)) = self.inner.best() else {
            return Ok(None);
        };
        let problem = build(spec)?;
        let comment = format!(
            "{} with the best genome of an animats.Optimiser ({}, generation {}): fitness {fitness}",
            spec.file,
            self.inner.kind().name(),
            self.inner.generation()
        );
        animats_evolve::Problem::scene_toml(problem.as_ref(), genome, &comment)
            .map(Some)
            .map_err(runtime_error)
    }
}

/// A whole evolution run, as `animats evolve [SCENE]` makes it: lanes, the
/// log, the best. `run()` advances it here; `ask()`/`tell()` hand each
/// generation out to be evaluated elsewhere (`animats.distributed`).
///
/// A second thread may use it while `run()` works: `generation`,
/// `evaluations`, `best_fitness` and `done` then say how far the run has
/// got (each lane's generations as they end); every other call waits for
/// the run to end, as a `World`'s do for its step.
#[pyclass(frozen, module = "animats")]
pub struct Evolution {
    inner: Mutex<Inner>,
    /// Each lane's progress, kept beside the run: what the getters read.
    progress: Mutex<Vec<LaneProgress>>,
    /// The configured generations of every lane.
    generations: u64,
}

/// The run itself, behind [`Evolution`]'s lock.
struct Inner {
    state: State,
    problem: Box<dyn animats_evolve::Problem>,
    pending: Option<Generation>,
}

/// One lane's generations and evaluations done, and its best so far.
#[derive(Clone, Copy)]
struct LaneProgress {
    generation: u64,
    evaluations: u64,
    best: Option<f64>,
}

/// Every lane's progress as `state` stands.
fn progress_of(state: &State) -> Vec<LaneProgress> {
    state
        .lanes
        .iter()
        .map(|l| LaneProgress {
            generation: l.generation,
            evaluations: l.evaluations,
            best: l.best.as_ref().map(|b| b.fitness),
        })
        .collect()
}

impl Evolution {
    fn lock(&self) -> PyResult<MutexGuard<'_, Inner>> {
        crate::lock(&self.inner, "evolution")
    }

    /// Brings the progress up to `state`.
    fn sync(&self, state: &State) {
        if let Ok(mut p) = self.progress.lock() {
            *p = progress_of(state);
        }
    }

    /// A run of `state`, its problem built to evaluate on `device`.
    fn of(state: State, device: &str) -> PyResult<Evolution> {
        let batches = crate::evaluate::device_batches(device)?;
        let problem = state
            .config
            .problem
            .build_on(batches)
            .map_err(crate::scene_error)?;
        Ok(Evolution {
            progress: Mutex::new(progress_of(&state)),
            generations: state.config.generations,
            inner: Mutex::new(Inner {
                state,
                problem,
                pending: None,
            }),
        })
    }

    /// The progress (a copy; the lock is held for no longer).
    fn lanes(&self) -> Vec<LaneProgress> {
        self.progress.lock().map(|p| p.clone()).unwrap_or_default()
    }
}

#[pymethods]
impl Evolution {
    /// `scene`: an `animats.Scene`, a path, or "roobot" (the default). The
    /// other arguments are `animats evolve`'s, with its defaults (`device`:
    /// "cpu", or "cuda" for `run` to evaluate each generation on an NVIDIA
    /// GPU).
    #[new]
    #[pyo3(signature = (scene = None, *, lanes = None, generations = 100, seed = 1, optimiser = None, population = None, restarts = 0, device = "cpu"))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments
    fn new(
        scene: Option<&Bound<'_, PyAny>>,
        lanes: Option<usize>,
        generations: u64,
        seed: u64,
        optimiser: Option<&str>,
        population: Option<usize>,
        restarts: u32,
        device: &str,
    ) -> PyResult<Evolution> {
        let spec = match scene {
            Some(s) => problem_spec(s)?,
            None => ProblemSpec::thesis(),
        };
        if !(1..=100_000_000).contains(&generations) {
            return Err(value_error("generations must be between 1 and 100000000"));
        }
        let choices = Choices {
            lanes,
            generations: Some(generations),
            seed: Some(seed),
            optimiser: optimiser.map(kind).transpose()?,
            population,
            restarts: (restarts > 0).then_some(restarts),
        };
        let config = Config::new(spec, &choices).map_err(value_error)?;
        Evolution::of(State::new(config).map_err(value_error)?, device)
    }

    /// The next generation of every lane not yet done: `(genomes, lanes)`,
    /// a `(N, D)` array (a list of N 1-D arrays when bodies evolve: their
    /// genomes differ in length) and each one's lane. Evaluate every one
    /// and `tell`.
    fn ask<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Vec<usize>)> {
        let mut guard = self.lock()?;
        let me = &mut *guard;
        if me.pending.is_some() {
            return Err(value_error(
                "tell the outcomes of the last generation first",
            ));
        }
        let g = me.state.ask().map_err(runtime_error)?;
        let d = me.problem.dim();
        let rows: Vec<Vec<f64>> = g.genomes().map(|x| x.to_vec()).collect();
        let lanes = g
            .lanes
            .iter()
            .flat_map(|(l, p)| std::iter::repeat_n(*l, p.len()))
            .collect();
        me.pending = Some(g);
        if me.problem.variation().is_some() {
            let list: Vec<Bound<'py, PyArray1<f64>>> = rows
                .into_iter()
                .map(|r| PyArray1::from_vec(py, r))
                .collect();
            return Ok((list.into_pyobject(py)?.into_any(), lanes));
        }
        Ok((matrix(py, &rows, d)?.into_any(), lanes))
    }

    /// The outcomes of the last `ask()`'s rows: a dict with `fitness`,
    /// `time`, `distance` (arrays) and `ended` (strings), and for a
    /// quality-diversity run `measures` (`(P, k)`), as `Evaluator.outcomes`
    /// gives.
    fn tell(&self, outcomes: &Bound<'_, PyDict>) -> PyResult<()> {
        let get = |k: &str| -> PyResult<Bound<'_, PyAny>> {
            outcomes
                .get_item(k)?
                .ok_or_else(|| value_error(format!("the outcomes have no `{k}`")))
        };
        let fitness: Vec<f64> = get("fitness")?.extract()?;
        let time: Vec<f64> = get("time")?.extract()?;
        let distance: Vec<f64> = get("distance")?.extract()?;
        let ended: Vec<String> = get("ended")?.extract()?;
        let measures: Vec<Vec<f64>> = match outcomes.get_item("measures")? {
            None => Vec::new(),
            Some(m) => match m.extract::<numpy::PyReadonlyArray2<f64>>() {
                Ok(a) => a
                    .as_array()
                    .rows()
                    .into_iter()
                    .map(|r| r.to_vec())
                    .collect(),
                Err(_) => m.extract()?,
            },
        };
        let n = fitness.len();
        if !measures.is_empty() && measures.len() != n {
            return Err(value_error("measures and fitness differ in length"));
        }
        if time.len() != n || distance.len() != n || ended.len() != n {
            return Err(value_error(
                "fitness, time, distance and ended differ in length",
            ));
        }
        let o: Vec<Outcome> = (0..n)
            .map(|i| {
                Ok(Outcome {
                    fitness: fitness[i],
                    time: time[i],
                    distance: distance[i],
                    ended: ended[i]
                        .parse()
                        .map_err(|e| value_error(format!("ended[{i}]: {e}")))?,
                    measures: measures.get(i).cloned().unwrap_or_default(),
                    energy: None,
                    target_distance: None,
                    terms: Vec::new(),
                })
            })
            .collect::<PyResult<_>>()?;
        let mut guard = self.lock()?;
        let me = &mut *guard;
        let g = me
            .pending
            .as_ref()
            .ok_or_else(|| value_error("ask for a generation first"))?;
        if g.len() != n {
            return Err(value_error(format!(
                "{n} outcomes told for a generation of {} genomes",
                g.len()
            )));
        }
        // Outcomes refused leave the generation asked, to be told again.
        me.state.tell(g, &o).map_err(value_error)?;
        me.pending = None;
        self.sync(&me.state);
        Ok(())
    }

    /// Evaluates the outcomes of a generation here (what `tell` takes).
    #[pyo3(signature = (genomes, threads = None))]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        genomes: &Bound<'py, PyAny>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let pool = pool(threads)?;
        let me = self.lock()?;
        // The genomes last asked: each screened as its lane's optimiser
        // says, as `run` evaluates them.
        let screens: Option<Vec<Screen>> = me.pending.as_ref().and_then(|g| {
            let n = genomes.len().ok()?;
            (n == g.len()).then(|| (0..n).map(|i| g.screen(i).clone()).collect())
        });
        let o = outcomes(
            py,
            me.problem.as_ref(),
            genomes,
            &pool,
            None,
            screens.as_deref(),
        )?;
        outcome_dict(py, &o)
    }

    /// One screen per genome of the last `ask()` (JSON texts): which a
    /// robust scene scores again at half the step. Hand them to
    /// `Evaluator.outcomes(genomes, screens=...)` wherever the genomes are
    /// evaluated, to write the log `run()` writes.
    fn screens(&self) -> PyResult<Vec<String>> {
        let me = self.lock()?;
        let g = me
            .pending
            .as_ref()
            .ok_or_else(|| value_error("ask for a generation first"))?;
        Ok((0..g.len()).map(|i| g.screen(i).to_json()).collect())
    }

    /// Advances every lane by up to `generations` generations (default:
    /// to the end) here, in parallel, the GIL released. Ctrl-C stops it
    /// (`KeyboardInterrupt`) once each thread's generation in flight
    /// ends: the run stands at whole generations, and `run()` goes on to
    /// the same results as a run never stopped. With `checkpoint` (a
    /// directory), the run is saved there as `save` saves it, as `animats
    /// evolve` does: every `checkpoint_every` seconds (all lanes stopping
    /// at whole generations for it), on Ctrl-C and at the end, so that
    /// `Evolution.resume(checkpoint)` goes on from the last save.
    #[pyo3(signature = (generations = None, threads = None, *, checkpoint = None, checkpoint_every = 5.0))]
    fn run(
        &self,
        py: Python<'_>,
        generations: Option<u64>,
        threads: Option<usize>,
        checkpoint: Option<PathBuf>,
        checkpoint_every: f64,
    ) -> PyResult<()> {
        if checkpoint_every.is_nan() || checkpoint_every < 0.0 {
            return Err(value_error(format!(
                "checkpoint_every must be at least 0 seconds, got {checkpoint_every}"
            )));
        }
        let every = std::time::Duration::try_from_secs_f64(checkpoint_every)
            .unwrap_or(std::time::Duration::MAX);
        let mut guard = self.lock()?;
        if guard.pending.is_some() {
            return Err(value_error(
                "tell the outcomes of the last generation first",
            ));
        }
        let pool = pool(threads)?;
        let n = generations.unwrap_or(guard.state.config.generations);
        let Inner { state, problem, .. } = &mut *guard;
        let problem = problem.as_ref();
        // Each lane's goal, kept across the stretches between saves.
        let goals: Vec<u64> = state
            .lanes
            .iter()
            .map(|l| l.generation.saturating_add(n))
            .collect();
        let reached = |state: &State| {
            state
                .lanes
                .iter()
                .zip(&goals)
                .all(|(l, &g)| l.generation >= g.min(state.config.generations))
        };
        let stop = std::sync::atomic::AtomicBool::new(false);
        let progress = &self.progress;
        let seen = |row: &animats_evolve::run::LogRow| {
            if let Ok(mut p) = progress.lock() {
                if let Some(lane) = p.get_mut(row.lane) {
                    *lane = LaneProgress {
                        generation: row.generation,
                        evaluations: row.evaluations,
                        best: Some(row.best_fitness),
                    };
                }
            }
        };
        loop {
            let begun = std::time::Instant::now();
            let more = || {
                !stop.load(std::sync::atomic::Ordering::Relaxed)
                    && (checkpoint.is_none() || begun.elapsed() < every)
            };
            let ran = crate::interruptible(py, &pool, &stop, || {
                state.advance_towards(problem, &goals, None, &more, Some(&seen))
            });
            self.sync(state);
            // A failed evaluation is not saved; after Ctrl-C the run stands
            // at whole generations, and is.
            let interrupted = match ran {
                Ok(Err(e)) => return Err(runtime_error(e)),
                Ok(Ok(())) => None,
                Err(interrupt) => Some(interrupt),
            };
            if let Some(dir) = &checkpoint {
                save_files(state, dir)?;
            }
            if let Some(interrupt) = interrupted {
                return Err(interrupt);
            }
            if reached(state) {
                return Ok(());
            }
        }
    }

    /// True when every lane has done its generations.
    #[getter]
    fn done(&self) -> bool {
        self.generation() >= self.generations
    }

    /// Generations every lane has completed (during a `run()` in another
    /// thread: so far).
    #[getter]
    fn generation(&self) -> u64 {
        self.lanes().iter().map(|l| l.generation).min().unwrap_or(0)
    }

    /// Evaluations so far.
    #[getter]
    fn evaluations(&self) -> u64 {
        self.lanes().iter().map(|l| l.evaluations).sum()
    }

    /// The genome's length.
    #[getter]
    fn dim(&self) -> PyResult<usize> {
        Ok(self.lock()?.problem.dim())
    }

    /// The best fitness over all lanes so far, or None.
    #[getter]
    fn best_fitness(&self) -> Option<f64> {
        self.lanes()
            .iter()
            .filter_map(|l| l.best)
            .max_by(f64::total_cmp)
    }

    /// The run's settings as `animats evolve` stores them, as a dict.
    #[getter]
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let me = self.lock()?;
        let c = &me.state.config;
        let d = PyDict::new(py);
        d.set_item("lanes", c.lanes)?;
        d.set_item("generations", c.generations)?;
        d.set_item("seed", c.seed)?;
        d.set_item("optimiser", c.optimiser.name())?;
        d.set_item("population", c.population)?;
        d.set_item("restarts", c.restarts)?;
        d.set_item("scene", &c.problem.file)?;
        Ok(d)
    }

    /// The problem as text a worker can rebuild: `(file, scene text)`.
    fn problem_text(&self) -> PyResult<(String, String)> {
        let me = self.lock()?;
        let p = &me.state.config.problem;
        Ok((p.file.clone(), p.text.clone()))
    }

    /// `log.csv`, exactly as `animats evolve` writes it.
    fn log_csv(&self) -> PyResult<String> {
        Ok(self.lock()?.state.log_csv())
    }

    /// `best.toml`, exactly as `animats evolve` writes it (None before the
    /// first generation).
    fn best_toml(&self) -> PyResult<Option<String>> {
        self.lock()?.state.best_toml().map_err(runtime_error)
    }

    /// The checks `animats evolve` runs at the end of a run: the best at
    /// a quarter of the step with its own integrator and with another, and
    /// where it keeps less than 80 % of its fitness in either, the next 16
    /// best (other lanes' bests, the archive's elites) until one keeps it
    /// in both (docs/BODIES.md, Honest evaluation). Returns a dict:
    /// `best`, a list of the best's checks (`integrator`, `dt`, `fitness`,
    /// `distance`, `share` of the logged fitness or None); `checked`, the
    /// candidate that passed (`label`, `file`, `fitness`, `shares`, `toml`:
    /// `checked.toml`'s text) or None; `lines`, what `animats evolve`
    /// prints of it (without `out`, no line says where the file went).
    /// With `out`, writes `out/checked.toml` (created whole or not at all)
    /// or, where none passed, removes an earlier one. None before the
    /// first generation.
    #[pyo3(signature = (out = None))]
    fn check<'py>(
        &self,
        py: Python<'py>,
        out: Option<PathBuf>,
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let me = self.lock()?;
        let state = &me.state;
        let report = py
            .detach(|| animats_evolve::check::check(state))
            .map_err(runtime_error)?;
        let Some(report) = report else {
            return Ok(None);
        };
        let checked = report.checked_toml();
        if let Some(out) = &out {
            let file = out.join("checked.toml");
            match &checked {
                Some(text) => {
                    std::fs::create_dir_all(out).map_err(|e| {
                        pyo3::exceptions::PyOSError::new_err(format!("{}: {e}", out.display()))
                    })?;
                    animats_files::write_atomically(&file, text.as_bytes())
                        .map_err(pyo3::exceptions::PyOSError::new_err)?;
                }
                None => match std::fs::remove_file(&file) {
                    Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                        return Err(pyo3::exceptions::PyOSError::new_err(format!(
                            "{}: {e}",
                            file.display()
                        )));
                    }
                    _ => {}
                },
            }
        }
        let d = PyDict::new(py);
        let mut best = Vec::new();
        for c in &report.best {
            let e = PyDict::new(py);
            e.set_item("integrator", c.integrator.name())?;
            e.set_item("dt", c.dt)?;
            e.set_item("fitness", c.evaluation.fitness)?;
            e.set_item("distance", c.evaluation.distance)?;
            e.set_item("share", c.share)?;
            best.push(e);
        }
        d.set_item("best", best)?;
        match (&report.verdict, checked) {
            (animats_evolve::check::Verdict::Checked(c), Some(toml)) => {
                let e = PyDict::new(py);
                e.set_item("label", &c.label)?;
                e.set_item("file", &c.file)?;
                e.set_item("fitness", c.fitness)?;
                e.set_item("shares", c.shares.clone())?;
                e.set_item("toml", toml)?;
                d.set_item("checked", e)?;
            }
            _ => d.set_item("checked", py.None())?,
        }
        d.set_item("lines", report.lines(out.as_deref()))?;
        Ok(Some(d))
    }

    /// Writes `log.csv`, `best.toml` and a quality-diversity run's
    /// `archive.csv` into `directory` (created if needed), then
    /// `checkpoint.json`, each file whole or not at all, as `animats
    /// evolve` writes them: `Evolution.resume(directory)` or `animats
    /// evolve --resume directory` continue the run from there to the same
    /// bits as a run never stopped. Refused while a generation is asked
    /// and not yet told.
    fn save(&self, directory: PathBuf) -> PyResult<()> {
        let me = self.lock()?;
        if me.pending.is_some() {
            return Err(value_error(
                "tell the outcomes of the last generation first: a run is saved between generations",
            ));
        }
        save_files(&me.state, &directory)
    }

    /// The run saved in `directory` (its `checkpoint.json`, written by
    /// `save` or by `animats evolve`), to go on with `run()` or
    /// `ask()`/`tell()`: it keeps its scene, optimiser, lanes and seed;
    /// `generations` may raise its total (never below those done).
    #[staticmethod]
    #[pyo3(signature = (directory, *, generations = None, device = "cpu"))]
    fn resume(directory: PathBuf, generations: Option<u64>, device: &str) -> PyResult<Evolution> {
        if let Some(g) = generations {
            if !(1..=100_000_000).contains(&g) {
                return Err(value_error("generations must be between 1 and 100000000"));
            }
        }
        let path = directory.join(animats_evolve::checkpoint::FILE);
        if !path.exists() {
            return Err(pyo3::exceptions::PyFileNotFoundError::new_err(format!(
                "{}: no checkpoint here (`Evolution.save` or `animats evolve` writes one)",
                path.display()
            )));
        }
        let mut state = animats_evolve::checkpoint::load(&path).map_err(value_error)?;
        let choices = Choices {
            generations,
            ..Choices::default()
        };
        state
            .resume(&choices)
            .map_err(|e| value_error(format!("{}: {e}", directory.display())))?;
        Evolution::of(state, device)
    }
}

/// `state`'s files in `directory` (created if needed), as `animats evolve`
/// writes them during a run (`checkpoint::run_files`), each whole or not
/// at all.
fn save_files(state: &State, directory: &std::path::Path) -> PyResult<()> {
    std::fs::create_dir_all(directory).map_err(|e| {
        pyo3::exceptions::PyOSError::new_err(format!("{}: {e}", directory.display()))
    })?;
    for (name, text) in animats_evolve::checkpoint::run_files(state).map_err(runtime_error)? {
        animats_files::write_atomically(&directory.join(name), text.as_bytes())
            .map_err(|e| pyo3::exceptions::PyOSError::new_err(e.to_string()))?;
    }
    Ok(())
}
