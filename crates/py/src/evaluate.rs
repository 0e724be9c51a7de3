//! `animats.evaluate` and `Evaluator`: fitness of many genomes at once, in
//! parallel on every core with the GIL released, bit-identical to `animats
//! evaluate` (each evaluation is a pure function of its genome).

use crate::scene::{no_evolve, Scene};
use crate::{on, pool, runtime_error, scene_error, value_error};
use animats_evolve::{Outcome, Problem, ProblemSpec};
use numpy::{PyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::path::PathBuf;

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
    Ok(ProblemSpec { file, text })
}

pub(crate) fn build(spec: &ProblemSpec) -> PyResult<Box<dyn Problem>> {
    spec.build().map_err(scene_error)
}

/// Evaluates each row of `genomes` (contiguous, `(P, D)`) on `pool`.
pub(crate) fn outcomes(
    py: Python<'_>,
    problem: &dyn Problem,
    genomes: &PyReadonlyArray2<'_, f64>,
    pool: &Option<rayon::ThreadPool>,
) -> PyResult<Vec<Outcome>> {
    let shape = genomes.shape();
    let (p, d) = (shape[0], shape[1]);
    if d != problem.dim() {
        return Err(value_error(format!(
            "genomes have {d} columns; this problem's genome has {}",
            problem.dim()
        )));
    }
    let flat = &*crate::elements(genomes);
    if let Some(i) = flat.iter().position(|x| !x.is_finite()) {
        return Err(value_error(format!(
            "genome {} has a gene that is not finite: {}",
            i / d.max(1),
            flat[i]
        )));
    }
    if p == 0 {
        return Ok(Vec::new());
    }
    py.detach(|| {
        on(pool, || {
            flat.par_chunks(d)
                .map(|g| problem.evaluate(g))
                .collect::<Result<Vec<_>, _>>()
        })
    })
    .map_err(runtime_error)
}

/// Fitness of each row of a `(P, D)` float64 array of genomes under a
/// scene's `[evolve]` evaluation (or the roobot's), in parallel.
#[pyfunction]
#[pyo3(signature = (scene, genomes, threads = None))]
pub fn evaluate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    genomes: PyReadonlyArray2<'py, f64>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let problem = build(&problem_spec(scene)?)?;
    let pool = pool(threads)?;
    let o = outcomes(py, problem.as_ref(), &genomes, &pool)?;
    Ok(PyArray1::from_vec(
        py,
        o.iter().map(|o| o.fitness).collect(),
    ))
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
    /// threads it evaluates on (default: every core).
    #[new]
    #[pyo3(signature = (scene, threads = None))]
    fn new(scene: &Bound<'_, PyAny>, threads: Option<usize>) -> PyResult<Evaluator> {
        let spec = problem_spec(scene)?;
        Ok(Evaluator {
            problem: build(&spec)?,
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

    /// Fitness of each row of `genomes`.
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        genomes: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let o = outcomes(py, self.problem.as_ref(), &genomes, &self.pool)?;
        Ok(PyArray1::from_vec(
            py,
            o.iter().map(|o| o.fitness).collect(),
        ))
    }

    /// Every outcome of each row: a dict of arrays `fitness`, `time`,
    /// `distance` and the list `ended` (what `Evolution.tell` takes).
    fn outcomes<'py>(
        &self,
        py: Python<'py>,
        genomes: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let o = outcomes(py, self.problem.as_ref(), &genomes, &self.pool)?;
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
    Ok(d)
}
