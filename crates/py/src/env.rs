//! `Env` and `VecEnv`: a scene's environment (the roobot's is the thesis's
//! scene) stepped from Python (the Gymnasium wrappers in
//! `python/animats/gym.py` hold these).

use crate::evaluate::problem_spec;
use crate::{runtime_error, scene_error, value_error};
use animats_creatures::env::{Env as _, Transition};
use animats_creatures::vec_env::VecEnv as RustVecEnv;
use animats_evolve::ProblemSpec;
use animats_scene::env::SceneEnv;
use numpy::ndarray::Array2;
use numpy::PyUntypedArrayMethods;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use std::sync::Mutex;

type Dyn = Box<dyn animats_creatures::env::Env>;

/// How to make one copy: the scene, and the episode's length and step when
/// they are not the scene's.
#[derive(Clone)]
struct Recipe {
    scene: ProblemSpec,
    seconds: Option<f64>,
    dt: Option<f64>,
}

impl Recipe {
    fn new(what: &Bound<'_, PyAny>, seconds: Option<f64>, dt: Option<f64>) -> PyResult<Recipe> {
        Ok(Recipe {
            scene: problem_spec(what)?,
            seconds,
            dt,
        })
    }

    fn make(&self, noise: f64) -> PyResult<Dyn> {
        if !(noise >= 0.0 && noise.is_finite()) {
            return Err(value_error(format!(
                "noise must be a finite number ≥ 0, got {noise}"
            )));
        }
        let env = SceneEnv::parse(&self.scene.text, &self.scene.file, noise)
            .map_err(scene_error)?
            .with_timing(self.seconds, self.dt)
            .map_err(value_error)?;
        Ok(Box::new(env))
    }
}

fn obs<'py>(py: Python<'py>, e: &Dyn) -> Bound<'py, PyArray1<f64>> {
    let mut o = vec![0.0; e.observation_size()];
    e.observe(&mut o);
    PyArray1::from_vec(py, o)
}

/// One environment: actions are actuator levels in [0, 1], observations
/// sensor levels in [0, 1], the reward the increase of the fitness.
#[pyclass(module = "animats")]
pub struct Env {
    env: Mutex<Dyn>,
}

impl Env {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, Dyn>> {
        self.env
            .lock()
            .map_err(|_| runtime_error("the environment was poisoned by an earlier failure"))
    }
}

#[pymethods]
impl Env {
    /// `scene`: an `animats.Scene`, a path or "roobot". `noise`: each reset
    /// adds to every particle's velocity a uniform random vector of up to
    /// this (m/s per component), drawn from the reset's seed. `seconds` and
    /// `dt` change the episode's length (the `[evolve]` duration) and step
    /// (the scene's; the roobot's: 20 s at 8 ms).
    #[new]
    #[pyo3(signature = (scene, noise = 0.0, seconds = None, dt = None))]
    fn new(
        scene: &Bound<'_, PyAny>,
        noise: f64,
        seconds: Option<f64>,
        dt: Option<f64>,
    ) -> PyResult<Env> {
        let env = Recipe::new(scene, seconds, dt)?.make(noise)?;
        Ok(Env {
            env: Mutex::new(env),
        })
    }

    /// Starts a new episode; returns the first observation.
    #[pyo3(signature = (seed = 0))]
    fn reset<'py>(&self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let mut e = self.lock()?;
        e.reset(seed).map_err(runtime_error)?;
        Ok(obs(py, &e))
    }

    /// The observation now.
    fn observe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(obs(py, &*self.lock()?))
    }

    /// Applies `action` and advances one step: `(observation, reward,
    /// terminated, truncated)`.
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &self,
        py: Python<'py>,
        action: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, f64, bool, bool)> {
        let mut e = self.lock()?;
        let t = e.step(&crate::elements(&action)).map_err(value_error)?;
        Ok((obs(py, &e), t.reward, t.terminated, t.truncated))
    }

    /// What each observation is.
    #[getter]
    fn observation_names(&self) -> PyResult<Vec<String>> {
        Ok(self.lock()?.observation_names())
    }

    /// What each action drives.
    #[getter]
    fn action_names(&self) -> PyResult<Vec<String>> {
        Ok(self.lock()?.action_names())
    }

    /// Simulated seconds per step.
    #[getter]
    fn dt(&self) -> PyResult<f64> {
        Ok(self.lock()?.dt())
    }

    /// Steps in a whole episode.
    #[getter]
    fn max_steps(&self) -> PyResult<u64> {
        Ok(self.lock()?.max_steps())
    }

    /// Simulated time since the reset, s.
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.lock()?.time())
    }

    /// Every particle's position, m: an `(N, 3)` array (for drawing).
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let e = self.lock()?;
        let flat: Vec<f64> = e
            .world()
            .state()
            .pos
            .iter()
            .flat_map(|p| p.to_array())
            .collect();
        let a = Array2::from_shape_vec((flat.len() / 3, 3), flat).map_err(runtime_error)?;
        Ok(a.into_pyarray(py))
    }
}

/// `n` copies stepped in one call in Rust (in parallel for large `n`, the
/// GIL released); a copy whose episode ended is reset at the next `step`
/// (reward 0), as Gymnasium's vector environments do by default.
#[pyclass(module = "animats")]
pub struct VecEnv {
    env: Mutex<RustVecEnv<Dyn>>,
    transitions: Mutex<Vec<Transition>>,
}

type Stepped<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
);

impl VecEnv {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, RustVecEnv<Dyn>>> {
        self.env
            .lock()
            .map_err(|_| runtime_error("the environment was poisoned by an earlier failure"))
    }
}

fn observations<'py>(py: Python<'py>, v: &RustVecEnv<Dyn>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mut o = vec![0.0; v.len() * v.observation_size()];
    v.observe(&mut o);
    let a = Array2::from_shape_vec((v.len(), v.observation_size()), o).map_err(runtime_error)?;
    Ok(a.into_pyarray(py))
}

#[pymethods]
impl VecEnv {
    /// `n` copies of `scene` (an `animats.Scene`, a path or "roobot"),
    /// copy `k` reset with seed `seed + k`.
    #[new]
    #[pyo3(signature = (scene, n, seed = 0, noise = 0.0, seconds = None, dt = None))]
    fn new(
        py: Python<'_>,
        scene: &Bound<'_, PyAny>,
        n: usize,
        seed: u64,
        noise: f64,
        seconds: Option<f64>,
        dt: Option<f64>,
    ) -> PyResult<VecEnv> {
        if n == 0 || n > 1 << 20 {
            return Err(value_error(format!(
                "n must be between 1 and {}, got {n}",
                1 << 20
            )));
        }
        let recipe = Recipe::new(scene, seconds, dt)?;
        recipe.make(noise)?;
        let v = py
            .detach(|| RustVecEnv::new(n, seed, |_| recipe.make(noise).map_err(|e| e.to_string())))
            .map_err(value_error)?;
        Ok(VecEnv {
            env: Mutex::new(v),
            transitions: Mutex::new(vec![
                Transition {
                    reward: 0.0,
                    terminated: false,
                    truncated: false
                };
                n
            ]),
        })
    }

    /// Resets every copy (copy `k` with seed `seed + k`); returns the
    /// observations, `(n, observations)`.
    #[pyo3(signature = (seed = 0))]
    fn reset<'py>(&self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let mut v = self.lock()?;
        let env = &mut *v;
        py.detach(|| env.reset(seed)).map_err(runtime_error)?;
        observations(py, &v)
    }

    /// Steps every copy with its row of `actions` (`(n, actions)`):
    /// `(observations, rewards, terminated, truncated)`.
    fn step<'py>(
        &self,
        py: Python<'py>,
        actions: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Stepped<'py>> {
        let mut v = self.lock()?;
        let mut out = self
            .transitions
            .lock()
            .map_err(|_| runtime_error("poisoned"))?;
        let shape = actions.shape();
        if shape[0] != v.len() || shape[1] != v.action_size() {
            return Err(value_error(format!(
                "actions must be ({}, {}), got ({}, {})",
                v.len(),
                v.action_size(),
                shape[0],
                shape[1]
            )));
        }
        let a = &*crate::elements(&actions);
        let env = &mut *v;
        let t = &mut *out;
        py.detach(|| env.step(a, t)).map_err(value_error)?;
        let rewards = PyArray1::from_vec(py, out.iter().map(|t| t.reward).collect());
        let terminated = PyArray1::from_vec(py, out.iter().map(|t| t.terminated).collect());
        let truncated = PyArray1::from_vec(py, out.iter().map(|t| t.truncated).collect());
        Ok((observations(py, &v)?, rewards, terminated, truncated))
    }

    /// Copies.
    #[getter]
    fn num_envs(&self) -> PyResult<usize> {
        Ok(self.lock()?.len())
    }

    /// What each observation is.
    #[getter]
    fn observation_names(&self) -> PyResult<Vec<String>> {
        Ok(self.lock()?.first().observation_names())
    }

    /// What each action drives.
    #[getter]
    fn action_names(&self) -> PyResult<Vec<String>> {
        Ok(self.lock()?.first().action_names())
    }

    /// Simulated seconds per step.
    #[getter]
    fn dt(&self) -> PyResult<f64> {
        Ok(self.lock()?.first().dt())
    }

    /// Steps in a whole episode.
    #[getter]
    fn max_steps(&self) -> PyResult<u64> {
        Ok(self.lock()?.first().max_steps())
    }
}
