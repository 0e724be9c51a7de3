//! A scene as an environment ([`animats_creatures::env::Env`]): any scene
//! with actuators, sensors and an `[evolve]` table, with a program as its
//! brain. Actions: every actuator's level, in the scene's order (each moves
//! at most its `rate` allows; no controller runs). Observations: every
//! sensor's level. Reward: the increase over the step of the `[evolve]`
//! fitness (`time_weight × time + distance_weight × distance`); the episode
//! ends as the evaluation does (a `fail_on_touch` particle touching the
//! floor or a blow-up: terminated; `duration`: truncated), so an episode's
//! rewards add up to the fitness [`crate::evaluate::evaluate`] gives the same
//! run.

use crate::error::SceneError;
use crate::evaluate::{EvolveSpec, SceneProblem};
use crate::Scene;
use animats_creatures::env::{check_action, perturb, Env, Transition};
use animats_engine::DVec3;

/// A scene stepped by a program.
pub struct SceneEnv {
    problem: SceneProblem,
    noise: f64,
    scene: Scene,
    spec: EvolveSpec,
    actions: Vec<String>,
    observations: Vec<String>,
    start: DVec3,
    last: DVec3,
    steps: u64,
    fitness: f64,
    over: bool,
    /// The step, when it is not the scene's.
    dt: Option<f64>,
}

impl SceneEnv {
    /// Parses a scene's text (`file` names it in errors); the start's
    /// velocities are perturbed at each reset by up to `noise` m/s.
    pub fn parse(text: &str, file: &str, noise: f64) -> Result<SceneEnv, SceneError> {
        let problem = SceneProblem::parse(text, file)?;
        let scene = problem.fresh().map_err(|e| SceneError::file(file, e))?;
        let spec = scene
            .evolve
            .clone()
            .ok_or_else(|| SceneError::file(file, "the scene has no [evolve] table"))?;
        if scene.nervous.actuators.is_empty() {
            return Err(SceneError::file(
                file,
                "the scene has no [[actuator]]: an environment's actions are actuator levels",
            ));
        }
        if scene.nervous.sensors.is_empty() {
            return Err(SceneError::file(
                file,
                "the scene has no [[sensor]]: an environment's observations are sensor levels",
            ));
        }
        let actions = scene
            .nervous
            .actuators
            .iter()
            .map(|(n, _)| n.clone())
            .collect();
        let observations = scene
            .nervous
            .sensors
            .iter()
            .map(|(n, _)| n.clone())
            .collect();
        let mut env = SceneEnv {
            problem,
            noise,
            scene,
            spec,
            actions,
            observations,
            start: DVec3::ZERO,
            last: DVec3::ZERO,
            steps: 0,
            fitness: 0.0,
            over: false,
            dt: None,
        };
        env.reset(0).map_err(|e| SceneError::file(file, e))?;
        Ok(env)
    }

    /// Episodes of `seconds` (instead of the `[evolve]` duration) in steps
    /// of `dt` (instead of the scene's).
    pub fn with_timing(
        mut self,
        seconds: Option<f64>,
        dt: Option<f64>,
    ) -> Result<SceneEnv, String> {
        let positive = |name: &str, x: f64| {
            if x > 0.0 && x.is_finite() {
                Ok(x)
            } else {
                Err(format!("{name} must be a positive number, got {x}"))
            }
        };
        if let Some(s) = seconds {
            self.spec.duration = positive("seconds", s)?;
        }
        if let Some(d) = dt {
            self.dt = Some(positive("dt", d)?);
        }
        let steps = self.spec.duration / self.dt.unwrap_or(self.scene.dt);
        if steps > crate::evaluate::MAX_STEPS {
            return Err(format!(
                "an episode of {steps:.3e} steps, more than {:e}",
                crate::evaluate::MAX_STEPS
            ));
        }
        self.reset(0)?;
        Ok(self)
    }

    /// Reads and parses a scene file.
    pub fn load(path: &std::path::Path, noise: f64) -> Result<SceneEnv, SceneError> {
        let file = path.display().to_string();
        let text = crate::read(path)?;
        SceneEnv::parse(&text, &file, noise)
    }

    /// The scene as it stands (positions for drawing, tests).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The fitness so far (the sum of the rewards since the reset, but for
    /// rounding).
    pub fn fitness(&self) -> f64 {
        self.fitness
    }

    fn score(&self, blew_up: bool) -> f64 {
        let mut distance = (self.last - self.start).dot(self.spec.axis);
        if blew_up {
            distance = distance.min(0.0);
        }
        self.spec.time_weight * self.steps as f64 * self.scene.dt
            + self.spec.distance_weight * distance
    }
}

impl Env for SceneEnv {
    fn observation_size(&self) -> usize {
        self.observations.len()
    }
    fn action_size(&self) -> usize {
        self.actions.len()
    }
    fn observation_names(&self) -> Vec<String> {
        self.observations.clone()
    }
    fn action_names(&self) -> Vec<String> {
        self.actions.clone()
    }
    fn dt(&self) -> f64 {
        self.scene.dt
    }
    fn max_steps(&self) -> u64 {
        (self.spec.duration / self.scene.dt).round() as u64
    }

    fn reset(&mut self, seed: u64) -> Result<(), String> {
        let mut scene = self.problem.fresh()?;
        if let Some(dt) = self.dt {
            scene.dt = dt;
        }
        perturb(&mut scene.world, seed, self.noise)?;
        self.start = self.spec.centre(&scene.world);
        self.last = self.start;
        self.over = self.spec.ending(&scene.world).is_some();
        self.scene = scene;
        self.steps = 0;
        self.fitness = 0.0;
        Ok(())
    }

    fn observe(&self, out: &mut [f64]) {
        for (o, (_, s)) in out.iter_mut().zip(&self.scene.nervous.sensors) {
            *o = s.level(&self.scene.world);
        }
    }

    fn step(&mut self, action: &[f64]) -> Result<Transition, String> {
        check_action(&self.actions, action)?;
        if self.over {
            return Err("the episode has ended: call reset".into());
        }
        let dt = self.scene.dt;
        let mut blew_up = self.scene.step_driven(action, dt).is_err();
        if !blew_up {
            self.steps += 1;
            let c = self.spec.centre(&self.scene.world);
            if c.is_finite() {
                self.last = c;
            } else {
                blew_up = true;
            }
        }
        let fitness = self.score(blew_up);
        let reward = fitness - self.fitness;
        self.fitness = fitness;
        let terminated = blew_up || self.spec.ending(&self.scene.world).is_some();
        let t = Transition::after(reward, terminated, self.steps, self.max_steps());
        self.over = t.ends();
        Ok(t)
    }

    fn time(&self) -> f64 {
        self.scene.world.time()
    }

    fn world(&self) -> &animats_engine::World {
        &self.scene.world
    }
}
