//! `Env` and `VecEnv`: a scene's environment (the roobot's is the thesis's
//! scene) stepped from Python (the Gymnasium wrappers in
//! `python/animats/gym.py` hold these).

use crate::evaluate::problem_spec;
use crate::{runtime_error, scene_error, value_error};
use animats_creatures::env::{Env as _, Transition};
use animats_creatures::vec_env::VecEnv as RustVecEnv;
use animats_evolve::ProblemSpec;
use animats_scene::env::{Observation, SceneEnv};
use numpy::ndarray::{Array2, Array3};
use numpy::PyUntypedArrayMethods;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use std::sync::Mutex;

/// How to make one copy: the scene, the episode's length and step when
/// they are not the scene's, the physics steps per action (or the rate to
/// act at) and what is observed (`None`: the scene's sensors, or its state
/// if it has none).
#[derive(Clone)]
struct Recipe {
    scene: ProblemSpec,
    seconds: Option<f64>,
    dt: Option<f64>,
    frame_skip: Option<u32>,
    act_hz: Option<f64>,
    observation: Option<Observation>,
}

impl Recipe {
    fn new(
        what: &Bound<'_, PyAny>,
        seconds: Option<f64>,
        dt: Option<f64>,
        frame_skip: Option<u32>,
        act_hz: Option<f64>,
        observation: Option<&str>,
    ) -> PyResult<Recipe> {
        if let Some(hz) = act_hz {
            if !(hz > 0.0 && hz.is_finite()) {
                return Err(value_error(format!(
                    "act_hz must be > 0, got {}",
                    animats_engine::Shown(hz)
                )));
            }
        }
        Ok(Recipe {
            scene: problem_spec(what)?,
            seconds,
            dt,
            frame_skip,
            act_hz,
            observation: observation
                .map(str::parse)
                .transpose()
                .map_err(value_error)?,
        })
    }

    fn make_scene(&self, noise: f64) -> PyResult<SceneEnv> {
        if !(noise >= 0.0 && noise.is_finite()) {
            return Err(value_error(format!(
                "noise must be a finite number ≥ 0, got {}",
                animats_engine::Shown(noise)
            )));
        }
        let env = SceneEnv::parse(&self.scene.text, &self.scene.file, noise)
            .map_err(scene_error)?
            .with_timing(self.seconds, self.dt)
            .map_err(value_error)?;
        let skip = match (self.frame_skip, self.act_hz) {
            (Some(k), _) => k,
            (None, Some(hz)) => env.frame_skip_for(hz).map_err(value_error)?,
            (None, None) => 1,
        };
        let observation = self.observation.unwrap_or(env.observation());
        env.with_actions(skip, observation).map_err(value_error)
    }
}

/// What the software renderer draws of the scene now, and the camera
/// `distance` m from the centre of the `[evolve]` particles.
fn picture(env: &SceneEnv, distance: f64) -> (animats_render::Picture, animats_render::Camera) {
    let scene = env.scene();
    let pos = &scene.world.state().pos;
    let drawing = animats_view::Drawing::of(scene, distance);
    let bells = drawing.bell_shapes(pos, &[]);
    let picture = animats_render::picture(&drawing, pos, &bells, &scene.nervous.actuator_levels());
    let centre = env.watched_centre();
    let target = animats_engine::DVec3::new(centre.x, centre.y.max(0.0), centre.z);
    (picture, animats_render::Camera::framing(target, distance))
}

/// `width` × `height` checked: 16 to 4096 pixels each.
fn picture_size(width: u32, height: u32) -> PyResult<()> {
    if !(16..=4096).contains(&width) || !(16..=4096).contains(&height) {
        return Err(value_error(format!(
            "width and height must be between 16 and 4096 pixels, got {width} × {height}"
        )));
    }
    Ok(())
}

/// The camera's distance that frames `start` (the body at the reset) in
/// a picture of `width` × `height`: `animats render`'s snug framing.
fn framing(start: &[(animats_engine::DVec3, f64)], width: u32, height: u32) -> f64 {
    let aspect = f64::from(width) / f64::from(height);
    animats_view::snug(start.iter().copied(), 50.0, aspect).map_or(3.0, |(_, d)| d)
}

fn obs<'py>(py: Python<'py>, e: &dyn animats_creatures::env::Env) -> Bound<'py, PyArray1<f64>> {
    let mut o = vec![0.0; e.observation_size()];
    e.observe(&mut o);
    PyArray1::from_vec(py, o)
}

/// One environment: actions are actuator levels in [0, 1], observations
/// sensor levels in [0, 1] (or the body's state), the reward the increase
/// of the fitness.
#[pyclass(module = "animats")]
pub struct Env {
    env: Mutex<SceneEnv>,
    /// The moving spheres (centre, radius) at the reset, which `render`
    /// frames.
    body: Mutex<Vec<(animats_engine::DVec3, f64)>>,
}

/// The moving spheres of `env`'s world now, (centre, radius).
fn body(env: &SceneEnv) -> Vec<(animats_engine::DVec3, f64)> {
    let w = &env.scene().world;
    let p = w.particles();
    w.particle_ids()
        .filter(|id| p.inv_mass[id.index()] > 0.0)
        .map(|id| (w.position(id), p.radius[id.index()]))
        .collect()
}

impl Env {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, SceneEnv>> {
        crate::lock(&self.env, "environment")
    }
}

#[pymethods]
impl Env {
    /// `scene`: an `animats.Scene`, a path or "roobot". `noise`: each reset
    /// adds to every particle's velocity a uniform random vector of up to
    /// this (m/s per component), drawn from the reset's seed. `seconds` and
    /// `dt` change the episode's length (the `[evolve]` duration) and step
    /// (the scene's; the roobot's: 20 s at 8 ms). Each action is held for
    /// `frame_skip` physics steps (or as many as make about `act_hz`
    /// actions a simulated second; default 1). `observation`: "sensors",
    /// "state" or "both" (default: the sensors, or the state of a scene
    /// without any).
    #[new]
    #[pyo3(signature = (scene, noise = 0.0, seconds = None, dt = None, frame_skip = None, act_hz = None, observation = None))]
    fn new(
        scene: &Bound<'_, PyAny>,
        noise: f64,
        seconds: Option<f64>,
        dt: Option<f64>,
        frame_skip: Option<u32>,
        act_hz: Option<f64>,
        observation: Option<&str>,
    ) -> PyResult<Env> {
        let env =
            Recipe::new(scene, seconds, dt, frame_skip, act_hz, observation)?.make_scene(noise)?;
        Ok(Env {
            body: Mutex::new(body(&env)),
            env: Mutex::new(env),
        })
    }

    /// Each observation's (low, high).
    #[getter]
    fn observation_bounds(&self) -> PyResult<Vec<(f64, f64)>> {
        Ok(self.lock()?.observation_bounds())
    }

    /// Physics steps per action.
    #[getter]
    fn frame_skip(&self) -> PyResult<u32> {
        Ok(self.lock()?.frame_skip())
    }

    /// The centre's distance along the `[evolve]` axis since the reset, m.
    #[getter]
    fn distance(&self) -> PyResult<f64> {
        Ok(self.lock()?.distance())
    }

    /// The actuators' positive work since the reset, J.
    #[getter]
    fn energy(&self) -> PyResult<f64> {
        Ok(self.lock()?.energy())
    }

    /// Why the episode ended (`timeout`, `touch NAME`, `stretch A-B`,
    /// `blow-up`), or None while it goes on.
    #[getter]
    fn ended(&self) -> PyResult<Option<String>> {
        Ok(self.lock()?.ended().map(ToString::to_string))
    }

    /// The scene now, drawn by the software renderer (`animats render`'s):
    /// a `(height, width, 3)` uint8 array, the camera following the
    /// `[evolve]` particles and framing the body as it was at the reset
    /// (`animats render`'s snug framing).
    #[pyo3(signature = (width = 480, height = 320))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        width: u32,
        height: u32,
    ) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
        picture_size(width, height)?;
        let distance = {
            let start = self.body.lock().map_err(|_| runtime_error("poisoned"))?;
            framing(&start, width, height)
        };
        let (picture, camera) = picture(&*self.lock()?, distance);
        let rgb = py.detach(|| animats_render::render(&picture, &camera, width, height).rgb);
        let a = Array3::from_shape_vec((height as usize, width as usize, 3), rgb)
            .map_err(runtime_error)?;
        Ok(a.into_pyarray(py))
    }

    /// Starts a new episode; returns the first observation.
    #[pyo3(signature = (seed = 0))]
    fn reset<'py>(&self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let mut e = self.lock()?;
        e.reset(seed).map_err(runtime_error)?;
        *self.body.lock().map_err(|_| runtime_error("poisoned"))? = body(&e);
        Ok(obs(py, &*e))
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
        Ok((obs(py, &*e), t.reward, t.terminated, t.truncated))
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
    env: Mutex<RustVecEnv<SceneEnv>>,
    transitions: Mutex<Vec<Transition>>,
    /// The moving spheres (centre, radius) of a copy at its reset, which
    /// `render` frames: the same for every copy and every reset (a reset's
    /// noise is in the velocities only).
    body: Vec<(animats_engine::DVec3, f64)>,
    /// A Ctrl-C stopped the last step or reset part way: some copies moved
    /// on, others not, until a reset.
    part_done: std::sync::atomic::AtomicBool,
}

/// Copies reset, or copies × physics steps stepped, from which a Ctrl-C
/// is listened for (a walker's step is about a microsecond, its reset
/// 10 µs: below this, tens of milliseconds at most).
const LONG: usize = 1 << 14;

type Stepped<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
);

impl VecEnv {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, RustVecEnv<SceneEnv>>> {
        crate::lock(&self.env, "environment")
    }

    /// `work` (a step or reset of every copy, told to stop by its flag)
    /// with the GIL released; if it is `long`, a Ctrl-C stops it part way
    /// and marks the copies part done. (Listening costs a hand-over to
    /// another thread, 25 µs a call: more than a step of a few copies.)
    fn interruptible(
        &self,
        py: Python<'_>,
        long: bool,
        work: impl FnOnce(&std::sync::atomic::AtomicBool) -> Result<(), String> + Send,
    ) -> PyResult<Result<(), String>> {
        use std::sync::atomic::Ordering;
        let stop = std::sync::atomic::AtomicBool::new(false);
        if !long {
            return Ok(py.detach(|| work(&stop)));
        }
        let out = crate::interruptible(py, &None, &stop, || work(&stop));
        if out.is_err() {
            self.part_done.store(true, Ordering::Relaxed);
        }
        out
    }
}

fn observations<'py>(
    py: Python<'py>,
    v: &RustVecEnv<SceneEnv>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mut o = vec![0.0; v.len() * v.observation_size()];
    v.observe(&mut o);
    let a = Array2::from_shape_vec((v.len(), v.observation_size()), o).map_err(runtime_error)?;
    Ok(a.into_pyarray(py))
}

#[pymethods]
impl VecEnv {
    /// `n` copies of `scene` (an `animats.Scene`, a path or "roobot"),
    /// copy `k` reset with seed `seed + k`; the rest as `Env`'s.
    #[new]
    #[pyo3(signature = (scene, n, seed = 0, noise = 0.0, seconds = None, dt = None, frame_skip = None, act_hz = None, observation = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scene: &Bound<'_, PyAny>,
        n: usize,
        seed: u64,
        noise: f64,
        seconds: Option<f64>,
        dt: Option<f64>,
        frame_skip: Option<u32>,
        act_hz: Option<f64>,
        observation: Option<&str>,
    ) -> PyResult<VecEnv> {
        if n == 0 || n > 1 << 20 {
            return Err(value_error(format!(
                "n must be between 1 and {}, got {n}",
                1 << 20
            )));
        }
        let recipe = Recipe::new(scene, seconds, dt, frame_skip, act_hz, observation)?;
        recipe.make_scene(noise)?;
        // Made in parallel, the GIL released; Ctrl-C stops the making
        // (about 0.2 ms a walker on one core: minutes for a million).
        let stop = std::sync::atomic::AtomicBool::new(false);
        let v = crate::interruptible(py, &None, &stop, || {
            RustVecEnv::new(n, seed, |_| {
                if stop.load(std::sync::atomic::Ordering::Relaxed) {
                    return Err("interrupted".to_string());
                }
                recipe.make_scene(noise).map_err(|e| e.to_string())
            })
        })?
        .map_err(value_error)?;
        Ok(VecEnv {
            body: body(v.first()),
            env: Mutex::new(v),
            part_done: std::sync::atomic::AtomicBool::new(false),
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
        let long = env.len() >= LONG;
        self.interruptible(py, long, |stop| env.reset_unless(seed, stop))?
            .map_err(runtime_error)?;
        self.part_done
            .store(false, std::sync::atomic::Ordering::Relaxed);
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
        let mut out = crate::lock(&self.transitions, "environment")?;
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
        if self.part_done.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(value_error(
                "a Ctrl-C stopped the last step or reset part way, some copies moved on and others not: call reset",
            ));
        }
        let a = &*crate::elements(&actions);
        let env = &mut *v;
        let t = &mut *out;
        let long = env.len() as u64 * u64::from(env.first().frame_skip()) >= LONG as u64;
        self.interruptible(py, long, |stop| env.step_unless(a, t, stop))?
            .map_err(value_error)?;
        let rewards = PyArray1::from_vec(py, out.iter().map(|t| t.reward).collect());
        let terminated = PyArray1::from_vec(py, out.iter().map(|t| t.terminated).collect());
        let truncated = PyArray1::from_vec(py, out.iter().map(|t| t.truncated).collect());
        Ok((observations(py, &v)?, rewards, terminated, truncated))
    }

    /// The copies numbered in `copies` (default: every copy) now, drawn
    /// as `Env.render` draws one: a `(copies, height, width, 3)` uint8
    /// array, each picture following its copy's `[evolve]` particles and
    /// framing the body as it stands at a reset. The pictures are drawn in
    /// parallel, the GIL released.
    #[pyo3(signature = (width = 480, height = 320, copies = None))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        width: u32,
        height: u32,
        copies: Option<Vec<i64>>,
    ) -> PyResult<Bound<'py, numpy::PyArray4<u8>>> {
        use rayon::prelude::*;
        picture_size(width, height)?;
        let distance = framing(&self.body, width, height);
        let pictures = {
            let v = self.lock()?;
            let n = v.len();
            let copies = copies.unwrap_or_else(|| (0..n as i64).collect());
            copies
                .iter()
                .map(|&k| {
                    usize::try_from(k)
                        .ok()
                        .and_then(|k| v.get(k))
                        .map(|e| picture(e, distance))
                        .ok_or_else(|| {
                            value_error(format!(
                                "copies: there is no copy {k} (copies 0 to {})",
                                n - 1
                            ))
                        })
                })
                .collect::<PyResult<Vec<_>>>()?
        };
        let k = pictures.len();
        let rgb: Vec<u8> = py.detach(|| {
            let frames: Vec<Vec<u8>> = pictures
                .par_iter()
                .map(|(picture, camera)| animats_render::render(picture, camera, width, height).rgb)
                .collect();
            frames.concat()
        });
        let a =
            numpy::ndarray::Array4::from_shape_vec((k, height as usize, width as usize, 3), rgb)
                .map_err(runtime_error)?;
        Ok(a.into_pyarray(py))
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

    /// Each observation's (low, high).
    #[getter]
    fn observation_bounds(&self) -> PyResult<Vec<(f64, f64)>> {
        Ok(self.lock()?.first().observation_bounds())
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
