//! `animats.evaluate` and `Evaluator`: fitness of many genomes at once, in
//! parallel on every core with the GIL released, bit-identical to `animats
//! evaluate` (each evaluation is a pure function of its genome).

use crate::scene::{no_evolve, Scene};
use crate::{on, pool, runtime_error, scene_error, value_error};
use animats_engine::Shown;
use animats_evolve::screen::Screen;
use animats_evolve::{Outcome, Problem, ProblemSpec};
use animats_scene::evaluate::{score_all, stoppable, Batches, Make, INTERRUPTED};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::cell::{Cell, RefCell};
use std::path::PathBuf;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// What Python names as a problem: a `Scene`, a scene file's path, or
/// `"roobot"` (the thesis's hopping gait, 20 s at 8 ms).
pub(crate) fn problem_spec(what: &Bound<'_, PyAny>) -> PyResult<ProblemSpec> {
    if let Ok(scene) = what.cast::<Scene>() {
        let s = scene.get();
        if !s.is_evolvable() {
            return Err(no_evolve(&s.file));
        }
        return Ok(ProblemSpec {
            file: s.file.clone(),
            text: s.text.clone(),
        });
    }
    let path: PathBuf = what.extract().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(
            "expected an animats.Scene, a scene file's path, or \"roobot\"",
        )
    })?;
    if path.as_os_str() == "roobot" && !path.exists() {
        return Ok(ProblemSpec::thesis());
    }
    let file = path.display().to_string();
    let text = animats_scene::read(&path).map_err(scene_error)?;
    // What `animats evaluate` would warn of, as `animats.load` warns of it
    // (a mistake is raised where the problem is built).
    if let Ok(s) = animats_scene::parse(&text, &file) {
        crate::scene::warn(what.py(), &file, &s.warnings)?;
    }
    Ok(ProblemSpec { file, text })
}

pub(crate) fn build(spec: &ProblemSpec) -> PyResult<Box<dyn Problem>> {
    spec.build().map_err(scene_error)
}

/// The genomes Python hands over: a `(P, D)` float array, or (for a
/// problem whose bodies evolve, whose genomes differ in length) a list of
/// 1-D arrays.
pub(crate) fn rows(problem: &dyn Problem, genomes: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<f64>>> {
    let rows: Vec<Vec<f64>> = match genomes.extract::<PyReadonlyArray2<'_, f64>>() {
        Ok(array) => {
            let d = array.shape()[1];
            if d != problem.dim() && problem.variation().is_none() {
                return Err(value_error(format!(
                    "genomes have {d} columns; this problem's genome has {}",
                    problem.dim()
                )));
            }
            crate::elements(&array)
                .chunks(d.max(1))
                .map(<[f64]>::to_vec)
                .collect()
        }
        Err(_) => genomes.extract().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(
                "genomes must be a (P, D) float array, or a list of 1-D arrays (bodies)",
            )
        })?,
    };
    for (k, g) in rows.iter().enumerate() {
        if let Some(x) = g.iter().find(|x| !x.is_finite()) {
            return Err(value_error(format!(
                "genome {k} has a gene that is not finite: {x}"
            )));
        }
    }
    Ok(rows)
}

/// Holds each row to the problem's bounds: an error naming the first gene
/// outside them, or (`clip`) every such gene moved to its nearer bound.
fn within_bounds(problem: &dyn Problem, rows: &mut [Vec<f64>], clip: bool) -> PyResult<()> {
    if problem.relative_mutation() {
        return Ok(());
    }
    let Some(b) = problem.bounds() else {
        return Ok(());
    };
    for (k, row) in rows.iter_mut().enumerate() {
        for (i, x) in row.iter_mut().enumerate() {
            let (lo, hi) = (b.lo[i], b.hi[i]);
            if *x >= lo && *x <= hi {
                continue;
            }
            if clip {
                *x = x.clamp(lo, hi);
            } else {
                return Err(value_error(format!(
                    "genome {k}, gene {i} = {} is outside its bounds [{}, {}] (scene.bounds()); pass clip=True to clip genes into their bounds",
                    Shown(*x),
                    Shown(lo),
                    Shown(hi)
                )));
            }
        }
    }
    Ok(())
}

/// Evaluates each of `genomes` ([`rows`]) on `pool`.
/// `clip`: `None` for genomes a run made itself (not checked); else genes
/// outside the problem's bounds are refused (`Some(false)`) or clipped
/// into them (`Some(true)`). A problem that mutates by a fraction of each
/// gene (the thesis's hill climber) has no bounds to hold genes to.
pub(crate) fn outcomes(
    py: Python<'_>,
    problem: &dyn Problem,
    genomes: &Bound<'_, PyAny>,
    pool: &Option<rayon::ThreadPool>,
    clip: Option<bool>,
    screens: Option<&[Screen]>,
) -> PyResult<Vec<Outcome>> {
    let mut rows = rows(problem, genomes)?;
    if let Some(clip) = clip {
        within_bounds(problem, &mut rows, clip)?;
    }
    if rows.is_empty() {
        return Ok(Vec::new());
    }
    if let Some(s) = screens {
        if s.len() != rows.len() {
            return Err(value_error(format!(
                "{} screens for {} genomes",
                s.len(),
                rows.len()
            )));
        }
    }
    // A problem on a GPU evaluates the genomes as one batch, each with its
    // screen.
    let fine = |i: usize, o: &Outcome| screens.is_none_or(|s| s[i].fine(o));
    if let Some(batch) = py.detach(|| on(pool, || problem.evaluate_population(&rows, &fine))) {
        return batch.map_err(runtime_error);
    }
    let evaluate = |i: usize, g: &[f64]| match screens {
        Some(s) => problem.evaluate_screened(g, &s[i]),
        None => problem.evaluate(g),
    };
    // One genome on the global pool: evaluated on this thread (no other
    // woken), which takes the GIL back every `SLICE` of it to let Python
    // handle a signal; Ctrl-C ends it within 256 steps.
    if rows.len() == 1 && pool.is_none() {
        let (out, caught) = py.detach(|| {
            let caught: Rc<RefCell<Option<PyErr>>> = Rc::default();
            let asks = {
                let caught = caught.clone();
                let last = Cell::new(Instant::now());
                Rc::new(move || {
                    if caught.borrow().is_some() {
                        return true;
                    }
                    if last.get().elapsed() < crate::SLICE {
                        return false;
                    }
                    last.set(Instant::now());
                    match Python::attach(|py| py.check_signals()) {
                        Ok(()) => false,
                        Err(e) => {
                            *caught.borrow_mut() = Some(e);
                            true
                        }
                    }
                })
            };
            let out = stoppable(asks, || evaluate(0, &rows[0]));
            (out, caught.take())
        });
        if let Some(e) = caught {
            return Err(e);
        }
        return out.map(|o| vec![o]).map_err(runtime_error);
    }
    let stop = Arc::new(AtomicBool::new(false));
    let work = || {
        rows.par_iter()
            .enumerate()
            .map(|(i, g)| {
                // Ctrl-C: the evaluations not yet begun are skipped, those
                // under way end within 256 steps.
                if stop.load(Ordering::Relaxed) {
                    return Err(INTERRUPTED.to_string());
                }
                stoppable(asks(&stop), || evaluate(i, g))
            })
            // (The first genome's failure, whichever thread failed first.)
            .collect::<Vec<_>>()
            .into_iter()
            .collect::<Result<Vec<_>, _>>()
    };
    // Every call of more than one genome is watched: it costs nothing
    // measurable (two roobot genomes on the global pool, medians of five
    // runs: 358-388 us a call watched, 366-374 us not; a 2-core Intel
    // Xeon, 2026-12-03).
    crate::interruptible(py, pool, &stop, work)?.map_err(runtime_error)
}

/// The question [`stoppable`] asks of an evaluation under a Ctrl-C watch
/// ([`crate::interruptible`]'s `stop`).
fn asks(stop: &Arc<AtomicBool>) -> Rc<dyn Fn() -> bool> {
    let stop = stop.clone();
    Rc::new(move || stop.load(Ordering::Relaxed))
}

/// Screens sent as `Evolution.screens()` wrote them (JSON texts).
pub(crate) fn read_screens(texts: Option<Vec<String>>) -> PyResult<Option<Vec<Screen>>> {
    texts
        .map(|t| {
            t.iter()
                .map(|x| Screen::from_json(x).map_err(value_error))
                .collect()
        })
        .transpose()
}

/// `device`: `None` for "cpu", the GPU's batches for "cuda" (or
/// "cuda-fast": fused multiply-adds allowed, not the CPU's bits), each
/// opened once a process (the kernel is compiled then); a `RuntimeError`
/// says what is missing (driver, device, NVRTC).
pub(crate) fn device_batches(device: &str) -> PyResult<Option<Batches>> {
    type Opened = std::sync::OnceLock<Result<Batches, String>>;
    static GPU: Opened = std::sync::OnceLock::new();
    static FAST: Opened = std::sync::OnceLock::new();
    let (opened, mode) = match device {
        "cpu" => return Ok(None),
        "cuda" => (&GPU, animats_gpu::Mode::Strict),
        "cuda-fast" => (&FAST, animats_gpu::Mode::Fast),
        other => {
            return Err(value_error(format!(
                "device={other:?}: \"cpu\" (the engine), \"cuda\" (an NVIDIA GPU: the same bits) or \"cuda-fast\" (the GPU with fused multiply-adds)"
            )))
        }
    };
    opened
        .get_or_init(|| animats_gpu::Device::open_in(mode).map(animats_gpu::Device::into_batches))
        .clone()
        .map(Some)
        .map_err(|e| runtime_error(format!("device={device:?}: {e}")))
}

/// `animats.evaluate_scenes`: each complete scene text (any bodies, as a
/// researcher's own encoding writes them) evaluated by its `[evolve]`
/// table, in parallel on `threads` threads with the GIL released (or, with
/// `device="cuda"`, as batches on the GPU): the same bits as `animats
/// evaluate` on each. A text that is not a scene, or has no `[evolve]`
/// table, raises `SceneError` naming its index; one the GPU does not
/// evaluate, a `RuntimeError` naming the entry. What `animats evaluate`
/// would warn of is a `RuntimeWarning`, once for each message, naming the
/// scenes that gave it ([`warn_grouped`]).
#[pyfunction]
#[pyo3(signature = (texts, threads = None, device = "cpu"))]
pub fn evaluate_scenes<'py>(
    py: Python<'py>,
    texts: Vec<String>,
    threads: Option<usize>,
    device: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let pool = pool(threads)?;
    let files: Vec<String> = (0..texts.len()).map(|k| format!("<scene {k}>")).collect();
    if let Some(b) = device_batches(device)? {
        let mut warnings = Vec::with_capacity(texts.len());
        for (text, file) in texts.iter().zip(&files) {
            let scene = animats_scene::parse(text, file).map_err(|e| scene_error(e.to_string()))?;
            if scene.evolve.is_none() {
                return Err(scene_error(format!(
                    "{file}: the scene has no [evolve] table: nothing to evaluate"
                )));
            }
            warnings.push(scene.warnings);
        }
        warn_grouped(py, &warnings)?;
        let makes: Vec<_> = texts
            .iter()
            .zip(&files)
            .map(|(text, file)| move || animats_scene::parse(text, file).map_err(|e| e.to_string()))
            .collect();
        let makes: Vec<&Make<'_>> = makes.iter().map(|m| m as &Make<'_>).collect();
        let o = py
            .detach(|| on(&pool, || score_all(&makes, &|_, _| true, &*b.0)))
            .map_err(runtime_error)?;
        return outcome_dict(py, &o);
    }
    let stop = Arc::new(AtomicBool::new(false));
    let results: Vec<Result<(Outcome, Vec<String>), String>> =
        crate::interruptible(py, &pool, &stop, || {
            texts
                .par_iter()
                .zip(&files)
                .map(|(text, file)| {
                    if stop.load(Ordering::Relaxed) {
                        Err(INTERRUPTED.to_string())
                    } else {
                        stoppable(asks(&stop), || evaluate_text(text, file))
                    }
                })
                .collect()
        })?;
    let (o, warnings): (Vec<Outcome>, Vec<Vec<String>>) = results
        .into_iter()
        .collect::<Result<Vec<_>, String>>()
        .map_err(scene_error)?
        .into_iter()
        .unzip();
    warn_grouped(py, &warnings)?;
    outcome_dict(py, &o)
}

/// One scene text scored as `animats evaluate` scores its file, and what
/// it would warn of.
fn evaluate_text(text: &str, file: &str) -> Result<(Outcome, Vec<String>), String> {
    let scene = animats_scene::parse(text, file).map_err(|e| e.to_string())?;
    if scene.evolve.is_none() {
        return Err(format!(
            "{file}: the scene has no [evolve] table: nothing to evaluate"
        ));
    }
    // Robust, trials: as evolution scores it.
    let o = animats_scene::evaluate::score(|| {
        animats_scene::parse(text, file).map_err(|e| e.to_string())
    })?;
    Ok((o, scene.warnings))
}

/// Each distinct message among `warnings` (scene `k`'s at `k`), as one
/// `RuntimeWarning` naming the scenes that gave it, in the order first
/// given: `<scene 3>: …`, or `<scenes 0, 4 and 7>: …`, or, past
/// [`NAMED`] scenes, `<scenes 0, 1, 2, 3, 4 and 995 more>: …`. A batch of
/// bodies from one encoding often shares a warning (a step past the
/// springs' stability limit): one line for it, not one per body.
fn warn_grouped(py: Python<'_>, warnings: &[Vec<String>]) -> PyResult<()> {
    /// Scenes named in one warning before the rest are counted.
    const NAMED: usize = 5;
    let mut groups: Vec<(&str, Vec<usize>)> = Vec::new();
    for (k, ws) in warnings.iter().enumerate() {
        for w in ws {
            match groups.iter_mut().find(|(m, _)| *m == w.as_str()) {
                Some((_, scenes)) => {
                    if scenes.last() != Some(&k) {
                        scenes.push(k);
                    }
                }
                None => groups.push((w.as_str(), vec![k])),
            }
        }
    }
    for (message, scenes) in groups {
        let list = |ks: &[usize]| {
            ks.iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        };
        let who = match scenes.len() {
            1 => format!("<scene {}>", scenes[0]),
            n if n <= NAMED => format!("<scenes {} and {}>", list(&scenes[..n - 1]), scenes[n - 1]),
            n => format!("<scenes {} and {} more>", list(&scenes[..NAMED]), n - NAMED),
        };
        crate::scene::warn(py, &who, &[message.to_string()])?;
    }
    Ok(())
}

/// Fitness of each row of a `(P, D)` float64 array of genomes under a
/// scene's `[evolve]` evaluation (or the roobot's), in parallel.
/// With `measures`, a tuple: the fitness and the `(P, k)` array of the
/// scene's `[archive]` measures.
#[pyfunction]
#[pyo3(signature = (scene, genomes, threads = None, measures = false, clip = false, device = "cpu"))]
pub fn evaluate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    genomes: &Bound<'py, PyAny>,
    threads: Option<usize>,
    measures: bool,
    clip: bool,
    device: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let batches = device_batches(device)?;
    let problem = problem_spec(scene)?
        .build_on(batches)
        .map_err(scene_error)?;
    if measures && problem.grid().is_none() {
        return Err(value_error(
            "measures=True: the scene has no [archive] table naming its measures",
        ));
    }
    let pool = pool(threads)?;
    let o = outcomes(py, problem.as_ref(), genomes, &pool, Some(clip), None)?;
    let fitness = PyArray1::from_vec(py, o.iter().map(|o| o.fitness).collect());
    if measures {
        let k = problem.grid().map_or(0, |g| g.names.len());
        let m = measure_array(py, &o, k)?;
        Ok((fitness, m).into_pyobject(py)?.into_any())
    } else {
        Ok(fitness.into_any())
    }
}

/// The outcomes' measures as a `(P, k)` array.
fn measure_array<'py>(
    py: Python<'py>,
    o: &[Outcome],
    k: usize,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let flat: Vec<f64> = o
        .iter()
        .flat_map(|o| {
            let mut m = o.measures.clone();
            m.resize(k, f64::NAN);
            m
        })
        .collect();
    PyArray1::from_vec(py, flat).reshape([o.len(), k])
}

/// A problem built once and evaluated many times (a Ray actor holds one).
#[pyclass(module = "animats")]
pub struct Evaluator {
    problem: Box<dyn Problem>,
    pool: Option<rayon::ThreadPool>,
    roobot: bool,
}

#[pymethods]
impl Evaluator {
    /// `scene`: an `animats.Scene`, a path, or `"roobot"`; `threads`: the
    /// threads it evaluates on (default: every core); `device`: "cpu", or
    /// "cuda" to evaluate each call's genomes as batches on an NVIDIA GPU.
    #[new]
    #[pyo3(signature = (scene, threads = None, device = "cpu"))]
    fn new(scene: &Bound<'_, PyAny>, threads: Option<usize>, device: &str) -> PyResult<Evaluator> {
        let spec = problem_spec(scene)?;
        let batches = device_batches(device)?;
        Ok(Evaluator {
            problem: spec.build_on(batches).map_err(scene_error)?,
            pool: pool(threads)?,
            roobot: spec == ProblemSpec::thesis(),
        })
    }

    /// The genome's length.
    #[getter]
    fn dim(&self) -> usize {
        self.problem.dim()
    }

    /// True for the roobot (the thesis's scene).
    #[getter]
    fn roobot(&self) -> bool {
        self.roobot
    }

    /// Fitness of each row of `genomes`; genes outside the bounds are
    /// refused, or clipped with `clip=True`.
    #[pyo3(signature = (genomes, clip = false))]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        genomes: &Bound<'py, PyAny>,
        clip: bool,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let o = outcomes(
            py,
            self.problem.as_ref(),
            genomes,
            &self.pool,
            Some(clip),
            None,
        )?;
        Ok(PyArray1::from_vec(
            py,
            o.iter().map(|o| o.fitness).collect(),
        ))
    }

    /// Every outcome of each row: a dict of arrays `fitness`, `time`,
    /// `distance` and the list `ended` (what `Evolution.tell` takes).
    /// `screens`: one per row, as `Evolution.screens()` gives them (which
    /// rows a robust scene scores again at half the step); default: all.
    #[pyo3(signature = (genomes, clip = false, screens = None))]
    fn outcomes<'py>(
        &self,
        py: Python<'py>,
        genomes: &Bound<'py, PyAny>,
        clip: bool,
        screens: Option<Vec<String>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let screens = read_screens(screens)?;
        let o = outcomes(
            py,
            self.problem.as_ref(),
            genomes,
            &self.pool,
            Some(clip),
            screens.as_deref(),
        )?;
        outcome_dict(py, &o)
    }
}

pub(crate) fn outcome_dict<'py>(py: Python<'py>, o: &[Outcome]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(
        "fitness",
        PyArray1::from_vec(py, o.iter().map(|o| o.fitness).collect()),
    )?;
    d.set_item(
        "time",
        PyArray1::from_vec(py, o.iter().map(|o| o.time).collect()),
    )?;
    d.set_item(
        "distance",
        PyArray1::from_vec(py, o.iter().map(|o| o.distance).collect()),
    )?;
    d.set_item(
        "ended",
        o.iter().map(|o| o.ended.to_string()).collect::<Vec<_>>(),
    )?;
    // Scenes with an [archive]: their measures, a (P, k) array when every
    // scene has k of them, else one array per scene.
    let k = o.first().map_or(0, |o| o.measures.len());
    if o.iter().all(|x| x.measures.len() == k) {
        if k > 0 {
            d.set_item("measures", measure_array(py, o, k)?)?;
        }
    } else {
        let list: Vec<Bound<'py, PyArray1<f64>>> = o
            .iter()
            .map(|x| PyArray1::from_vec(py, x.measures.clone()))
            .collect();
        d.set_item("measures", list)?;
    }
    // Scenes whose fitness counts energy or a target: those figures (NaN
    // where a scene has none).
    for (key, get) in [
        (
            "energy",
            (|o: &Outcome| o.energy) as fn(&Outcome) -> Option<f64>,
        ),
        ("target_distance", |o: &Outcome| o.target_distance),
    ] {
        if o.iter().any(|x| get(x).is_some()) {
            let v = o.iter().map(|x| get(x).unwrap_or(f64::NAN)).collect();
            d.set_item(key, PyArray1::from_vec(py, v))?;
        }
    }
    Ok(d)
}
