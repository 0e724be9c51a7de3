//! `animats.load`, `Scene`, `World`, `Snapshot`.

use crate::{runtime_error, scene_error, value_error};
use animats_engine::Shown;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::Mutex;

/// Where a genome starts and its bounds.
type Genome = (Vec<f64>, Vec<(f64, f64)>);

/// A scene file, read and checked: what `animats simulate`, `evaluate` and
/// `evolve` take. Build worlds from it with `world()`.
#[pyclass(frozen, module = "animats")]
pub struct Scene {
    pub(crate) file: String,
    pub(crate) text: String,
    names: Vec<String>,
    dt: f64,
    duration: f64,
    actuators: Vec<String>,
    sensors: Vec<String>,
    controllers: Vec<String>,
    /// What `animats simulate` would warn of.
    warnings: Vec<String>,
    /// The `[evolve]` controller's start and bounds.
    evolve: Option<Genome>,
}

impl Scene {
    /// True when the scene has an `[evolve]` table.
    pub(crate) fn is_evolvable(&self) -> bool {
        self.evolve.is_some()
    }

    pub(crate) fn from_text(text: String, file: String) -> PyResult<Scene> {
        let s = animats_scene::parse(&text, &file).map_err(scene_error)?;
        let src = animats_scene::source::Source {
            file: &file,
            text: &text,
        };
        let bodies = animats_scene::parse_def(&src)
            .map_err(scene_error)?
            .morphology
            .is_some();
        let evolve = match &s.evolve {
            // Bodies evolve: the start is the scene's starting body, if it
            // names one; genomes have no bounds (nor a fixed length).
            Some(_) if bodies => {
                let p = animats_scene::morphology::MorphologyProblem::parse(&text, &file)
                    .map_err(scene_error)?;
                Some((
                    p.start().map(<[f64]>::to_vec).unwrap_or_default(),
                    Vec::new(),
                ))
            }
            Some(_) => {
                let p = animats_scene::evaluate::SceneProblem::parse(&text, &file)
                    .map_err(scene_error)?;
                Some((p.start().to_vec(), p.bounds().to_vec()))
            }
            None => None,
        };
        Ok(Scene {
            names: s.names.clone(),
            dt: s.dt,
            duration: s.duration,
            actuators: s.nervous.actuators.iter().map(|(n, _)| n.clone()).collect(),
            sensors: s.nervous.sensors.iter().map(|(n, _)| n.clone()).collect(),
            controllers: s
                .nervous
                .controllers
                .iter()
                .map(|c| c.name.clone())
                .collect(),
            warnings: s.warnings.clone(),
            evolve,
            file,
            text,
        })
    }

    /// Issues each of the scene's warnings as a Python `RuntimeWarning`
    /// ("FILE: message", as `animats simulate` prints them).
    fn warn(self, py: Python<'_>) -> PyResult<Scene> {
        warn(py, &self.file, &self.warnings)?;
        Ok(self)
    }
}

/// Issues `warnings` of the scene `file` as Python `RuntimeWarning`s
/// ("FILE: message", as `animats simulate` prints them).
pub(crate) fn warn(py: Python<'_>, file: &str, warnings: &[String]) -> PyResult<()> {
    let category = py.get_type::<pyo3::exceptions::PyRuntimeWarning>();
    for w in warnings {
        let text = std::ffi::CString::new(format!("{file}: {w}"))
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        PyErr::warn(py, &category, &text, 1)?;
    }
    Ok(())
}

/// Reads and checks the scene file at `path`. Raises `animats.SceneError`
/// (a `ValueError`) naming the file, line, entry and field of a mistake;
/// what is allowed but probably a mistake (a step past the springs'
/// stability limit) is a `RuntimeWarning`, and in `Scene.warnings`.
#[pyfunction]
pub fn load(py: Python<'_>, path: PathBuf) -> PyResult<Scene> {
    let file = path.display().to_string();
    let text = animats_scene::read(&path).map_err(scene_error)?;
    Scene::from_text(text, file)?.warn(py)
}

/// Checks a scene given as text; `file` names it in messages.
#[pyfunction]
#[pyo3(signature = (text, file = "<string>".to_string()))]
pub fn parse(py: Python<'_>, text: String, file: String) -> PyResult<Scene> {
    Scene::from_text(text, file)?.warn(py)
}

#[pymethods]
impl Scene {
    /// A fresh world built from the scene, at its start; with `genome`, the
    /// scene's `[evolve]` controllers (or, for a `[morphology]` scene, the
    /// body and brain) as that genome makes them: the creature an
    /// evolution found, to step and inspect.
    #[pyo3(signature = (genome = None))]
    fn world(&self, genome: Option<Vec<f64>>) -> PyResult<World> {
        let scene = match genome {
            None => animats_scene::parse(&self.text, &self.file).map_err(scene_error)?,
            Some(g) => {
                let text = self.best_toml(g)?;
                animats_scene::parse(&text, &self.file).map_err(scene_error)?
            }
        };
        Ok(World {
            scene: Mutex::new(scene),
        })
    }

    /// The scene's text with `genome` written in: the `[evolve]`
    /// controllers' keys hold its genes (a `[morphology]` scene: the body
    /// it develops into, as ordinary entries) — what `animats evolve`
    /// writes as `best.toml`, for a genome from `Optimiser.best()` or
    /// anywhere else. Write it to a file and `animats evaluate` it.
    fn best_toml(&self, genome: Vec<f64>) -> PyResult<String> {
        if self.evolve.is_none() {
            return Err(no_evolve(&self.file));
        }
        if let Some(x) = genome.iter().find(|x| !x.is_finite()) {
            return Err(value_error(format!(
                "genome has a gene that is not finite: {x}"
            )));
        }
        let spec = animats_evolve::ProblemSpec {
            file: self.file.clone(),
            text: self.text.clone(),
        };
        let problem = spec.build().map_err(scene_error)?;
        animats_evolve::Problem::scene_toml(
            problem.as_ref(),
            &genome,
            "written by animats.Scene.best_toml",
        )
        .map_err(value_error)
    }

    /// The scene file's name.
    #[getter]
    fn file(&self) -> &str {
        &self.file
    }

    /// The scene file's text.
    #[getter]
    fn text(&self) -> &str {
        &self.text
    }

    /// Each particle's name, in order.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.names.clone()
    }

    /// The step, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.dt
    }

    /// The `[world]` duration, s.
    #[getter]
    fn duration(&self) -> f64 {
        self.duration
    }

    /// Actuator names, in the scene's order (the order of levels).
    #[getter]
    fn actuators(&self) -> Vec<String> {
        self.actuators.clone()
    }

    /// Sensor names, in the scene's order.
    #[getter]
    fn sensors(&self) -> Vec<String> {
        self.sensors.clone()
    }

    /// Controller names, in the scene's order.
    #[getter]
    fn controllers(&self) -> Vec<String> {
        self.controllers.clone()
    }

    /// What `animats simulate` would warn of: a step past the springs'
    /// (or, for a `[morphology]` scene, the budgets') stability limit, a
    /// particle that starts inside the floor, an actuator whose built value
    /// lies outside its range. `load` and `parse` issue each as a
    /// `RuntimeWarning`.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// True when the scene has an `[evolve]` table.
    #[getter]
    fn evolvable(&self) -> bool {
        self.evolve.is_some()
    }

    /// The `[evolve]` controller's own parameters (where evolution starts).
    fn start<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (start, _) = self.evolve.as_ref().ok_or_else(|| no_evolve(&self.file))?;
        Ok(PyArray1::from_vec(py, start.clone()))
    }

    /// The genome's bounds, a `(D, 2)` array of (low, high).
    fn bounds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (_, b) = self.evolve.as_ref().ok_or_else(|| no_evolve(&self.file))?;
        let flat: Vec<f64> = b.iter().flat_map(|(lo, hi)| [*lo, *hi]).collect();
        let a = Array2::from_shape_vec((b.len(), 2), flat).map_err(runtime_error)?;
        Ok(a.into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        format!(
            "<animats.Scene {:?}: {} particles, {} actuators, {} sensors{}>",
            self.file,
            self.names.len(),
            self.actuators.len(),
            self.sensors.len(),
            if self.evolve.is_some() {
                ", [evolve]"
            } else {
                ""
            }
        )
    }
}

pub(crate) fn no_evolve(file: &str) -> PyErr {
    scene_error(format!(
        "{file}: the scene has no [evolve] table (docs/SCENES.md)"
    ))
}

/// A running scene: its world, creatures and controllers. Stepping
/// releases the GIL.
#[pyclass(module = "animats")]
pub struct World {
    scene: Mutex<animats_scene::Scene>,
}

/// The state of a world at one instant (positions, velocities, the
/// parameters actuators drive, actuator levels, and the controllers' and
/// creatures' own state: an FSM's current state, a CTRNN's activations):
/// restored, the world steps on as it did from there, bit for bit.
#[pyclass(frozen, module = "animats")]
pub struct Snapshot {
    inner: animats_scene::SceneSnapshot,
}

#[pymethods]
impl Snapshot {
    /// Simulated time of the snapshot, s.
    #[getter]
    fn time(&self) -> f64 {
        self.inner.world.time
    }
}

impl World {
    /// Sets one vector per particle from an `(N, 3)` array, all or none.
    fn set_vec3s(
        &self,
        a: numpy::PyReadonlyArray2<'_, f64>,
        what: &str,
        set: impl Fn(
            &mut animats_engine::World,
            animats_engine::ParticleId,
            animats_engine::DVec3,
        ) -> Result<(), animats_engine::ModelError>,
    ) -> PyResult<()> {
        let mut s = self.lock()?;
        let n = s.world.len();
        if a.shape() != [n, 3] {
            return Err(value_error(format!(
                "{what} must be an ({n}, 3) array, got {:?}",
                a.shape()
            )));
        }
        let flat = crate::elements(&a);
        if let Some(k) = flat.iter().position(|x| !x.is_finite()) {
            return Err(value_error(format!(
                "{what}[{}, {}] is not finite: {}",
                k / 3,
                k % 3,
                flat[k]
            )));
        }
        let ids: Vec<_> = s.world.particle_ids().collect();
        for (p, v) in ids.into_iter().zip(flat.chunks(3)) {
            set(
                &mut s.world,
                p,
                animats_engine::DVec3::new(v[0], v[1], v[2]),
            )
            .map_err(|e| value_error(format!("{what}: {e}")))?;
        }
        s.rearm_guard();
        Ok(())
    }

    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, animats_scene::Scene>> {
        crate::lock(&self.scene, "world")
    }
}

fn vec3s<'py>(
    py: Python<'py>,
    v: impl Iterator<Item = [f64; 3]>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = v.flatten().collect();
    let n = flat.len() / 3;
    let a = Array2::from_shape_vec((n, 3), flat).map_err(runtime_error)?;
    Ok(a.into_pyarray(py))
}

/// The most steps one `World.step` call takes (`animats simulate`'s bound).
const MAX_STEPS: u64 = 1_000_000_000_000;

#[pymethods]
impl World {
    /// Advances `n` steps of the scene's `dt` (controllers act before each),
    /// at most 10¹² a call. Raises `RuntimeError` if the simulation blows
    /// up, naming the particle and the time. Ctrl-C stops a long call
    /// between two steps (`KeyboardInterrupt`): the world stands after the
    /// last step taken, the same bits as one stepped that far.
    #[pyo3(signature = (n = 1))]
    fn step(&self, py: Python<'_>, n: u64) -> PyResult<()> {
        if n > MAX_STEPS {
            return Err(value_error(format!(
                "n = {n} steps is too many (at most 1e12 a call)"
            )));
        }
        let mut s = self.lock()?;
        let scene = &mut *s;
        let dt = scene.dt;
        let mut left = n;
        while left > 0 {
            let begun = std::time::Instant::now();
            let more = || begun.elapsed() < crate::SLICE;
            left -= py
                .detach(|| scene.steps_while(left, dt, more))
                .map_err(runtime_error)?;
            if left > 0 {
                py.check_signals()?;
            }
        }
        Ok(())
    }

    /// Simulated time, s.
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.lock()?.world.time())
    }

    /// The step, s.
    #[getter]
    fn dt(&self) -> PyResult<f64> {
        Ok(self.lock()?.dt)
    }

    /// Each particle's name, in order (the rows of `positions()`).
    #[getter]
    fn names(&self) -> PyResult<Vec<String>> {
        Ok(self.lock()?.names.clone())
    }

    /// Positions, m: an `(N, 3)` float64 array (a copy).
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let s = self.lock()?;
        vec3s(py, s.world.state().pos.iter().map(|p| p.to_array()))
    }

    /// Velocities, m/s: an `(N, 3)` float64 array (a copy).
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let s = self.lock()?;
        vec3s(py, s.world.state().vel.iter().map(|p| p.to_array()))
    }

    /// Sets every actuator's level (scene order, clamped to [0, 1]);
    /// controllers overwrite those they drive at the next step.
    fn set_actuators(&self, levels: Vec<f64>) -> PyResult<()> {
        if let Some(i) = levels.iter().position(|l| !l.is_finite()) {
            return Err(value_error(format!(
                "level {i} is not finite: {}",
                levels[i]
            )));
        }
        let mut s = self.lock()?;
        let scene = &mut *s;
        scene
            .nervous
            .set_levels(&mut scene.world, &levels)
            .map_err(value_error)
    }

    /// Every actuator's level, in the scene's order.
    fn actuators<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(
            py,
            self.lock()?.nervous.actuator_levels(),
        ))
    }

    /// Every sensor's level, in the scene's order.
    fn sensors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let s = self.lock()?;
        Ok(PyArray1::from_vec(py, s.nervous.sensor_levels(&s.world)))
    }

    /// The world's state now; `restore` returns to it bit for bit.
    fn snapshot(&self) -> PyResult<Snapshot> {
        Ok(Snapshot {
            inner: self.lock()?.snapshot(),
        })
    }

    /// Returns to a snapshot of this world (or of one built from the same
    /// scene).
    fn restore(&self, snapshot: &Snapshot) -> PyResult<()> {
        self.lock()?.restore(&snapshot.inner).map_err(value_error)
    }

    /// Each particle's mass, kg: an `(N,)` array (a fixed particle's is
    /// the mass it was given).
    fn masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(
            py,
            self.lock()?.world.particles().mass.clone(),
        ))
    }

    /// Each particle's radius, m: an `(N,)` array.
    fn radii<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(
            py,
            self.lock()?.world.particles().radius.clone(),
        ))
    }

    /// The springs now: a dict of arrays `a`, `b` (the ends' particle
    /// indices), `length` (m, now), `rest_length` (m; a muscle's moves),
    /// `stiffness` (N/m) and `damping` (N s/m), one entry per spring.
    fn springs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let s = self.lock()?;
        let pos = &s.world.state().pos;
        let (mut a, mut b, mut length, mut rest, mut k, mut c) = (
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
        );
        for spring in s.world.forces().springs.iter() {
            let (i, j) = spring.ends();
            a.push(i.index() as i64);
            b.push(j.index() as i64);
            length.push((pos[j.index()] - pos[i.index()]).length());
            rest.push(spring.rest_length);
            k.push(spring.stiffness);
            c.push(spring.damping);
        }
        let d = pyo3::types::PyDict::new(py);
        d.set_item("a", PyArray1::from_vec(py, a))?;
        d.set_item("b", PyArray1::from_vec(py, b))?;
        d.set_item("length", PyArray1::from_vec(py, length))?;
        d.set_item("rest_length", PyArray1::from_vec(py, rest))?;
        d.set_item("stiffness", PyArray1::from_vec(py, k))?;
        d.set_item("damping", PyArray1::from_vec(py, c))?;
        Ok(d)
    }

    /// Which particles touch the floor now: an `(N,)` bool array, true
    /// where a particle's surface is within `tolerance` m of the ground
    /// (y = 0, or the `[terrain]`'s surface), as `touch` sensors and the
    /// `feet` measure ask; all false in a scene without a `[floor]`.
    #[pyo3(signature = (tolerance = 1e-6))]
    fn contacts<'py>(
        &self,
        py: Python<'py>,
        tolerance: f64,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        if !(tolerance >= 0.0 && tolerance.is_finite()) {
            return Err(value_error(format!(
                "tolerance must be a finite number of metres ≥ 0, got {}",
                Shown(tolerance)
            )));
        }
        let s = self.lock()?;
        let w = &s.world;
        let floor = w.terrain().is_some();
        let on: Vec<bool> = w
            .particle_ids()
            .map(|p| floor && w.touches_ground(p, tolerance))
            .collect();
        Ok(PyArray1::from_vec(py, on))
    }

    /// Sets every particle's position, m, from an `(N, 3)` array
    /// (velocities and everything else kept).
    fn set_positions(&self, positions: numpy::PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        self.set_vec3s(positions, "positions", |w, p, x| w.set_position(p, x))
    }

    /// Sets every particle's velocity, m/s, from an `(N, 3)` array (a fixed
    /// particle's stays 0).
    fn set_velocities(&self, velocities: numpy::PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        self.set_vec3s(velocities, "velocities", |w, p, v| w.set_velocity(p, v))
    }

    /// Total energy (kinetic + potential), J.
    fn energy(&self) -> PyResult<f64> {
        Ok(self.lock()?.world.energy().total())
    }

    fn __repr__(&self) -> PyResult<String> {
        let s = self.lock()?;
        Ok(format!(
            "<animats.World: {} particles at t = {} s>",
            s.world.len(),
            s.world.time()
        ))
    }
}
