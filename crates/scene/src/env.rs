//! A scene as an environment ([`animats_creatures::env::Env`]): any scene
//! with actuators and an `[evolve]` table, with a program as its brain.
//! Actions: every actuator's level, in the scene's order (each moves at
//! most its `rate` allows; no controller runs), held for `frame_skip`
//! physics steps. Observations ([`Observation`]): every sensor's level, the
//! body's state, or both. Reward: the increase over the action's steps of
//! the `[evolve]` fitness (`time_weight × time + distance_weight × distance
//! − energy_weight × work − target_weight × distance to target`; its
//! `terms` and `trials` are not part of it); the episode ends as the
//! evaluation does (a `fail_on_touch` particle touching the floor or a
//! blow-up: terminated; `duration`: truncated), so an episode's rewards add
//! up to the fitness [`crate::evaluate::evaluate`] gives the same run.

use crate::error::SceneError;
use crate::evaluate::{Ended, EvolveSpec, SceneProblem};
use crate::work::Work;
use crate::Scene;
use animats_creatures::env::{check_action, perturb, Env, Transition};
use animats_creatures::sensors::probe::touches_floor;
use animats_engine::{DVec3, ParticleId};

/// What an environment observes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Observation {
    /// Every sensor's level, in [0, 1].
    #[default]
    Sensors,
    /// The body's state: the centre of mass's height and velocity, every
    /// moving particle's position and velocity relative to it, every
    /// spring's length and whether each moving particle touches the floor.
    State,
    /// The sensors, then the state.
    Both,
}

impl std::str::FromStr for Observation {
    type Err = String;
    fn from_str(s: &str) -> Result<Observation, String> {
        match s {
            "sensors" => Ok(Observation::Sensors),
            "state" => Ok(Observation::State),
            "both" => Ok(Observation::Both),
            _ => Err(format!(
                "observation must be \"sensors\", \"state\" or \"both\", got {s:?}"
            )),
        }
    }
}

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
    fitness: f64,
    over: bool,
    /// The step, when it is not the scene's.
    dt: Option<f64>,
    /// Physics steps per action.
    frame_skip: u32,
    /// What is observed.
    observation: Observation,
    /// The moving particles (the state's).
    moving: Vec<ParticleId>,
    /// The actuators' positive work since the reset.
    work: Work,
    /// Physics steps since the reset.
    physics_steps: u64,
    /// Why the episode ended, once it has.
    ended: Option<Ended>,
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
        let inv = &scene.world.particles().inv_mass;
        let moving = scene
            .world
            .particle_ids()
            .filter(|p| inv[p.index()] > 0.0)
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
            fitness: 0.0,
            over: false,
            dt: None,
            frame_skip: 1,
            observation: Observation::Sensors,
            moving,
            work: Work::default(),
            physics_steps: 0,
            ended: None,
        };
        // A scene without sensors observes its state.
        if env.scene.nervous.sensors.is_empty() {
            env.observation = Observation::State;
            env.observations = env.names();
        }
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
        let step = self.dt.unwrap_or(self.scene.dt);
        let steps = self.spec.duration / step;
        if steps.round() < 1.0 {
            return Err(format!(
                "an episode of {} s is shorter than half a step of {} s: nothing to step",
                animats_engine::Shown(self.spec.duration),
                animats_engine::Shown(step)
            ));
        }
        if steps > crate::evaluate::MAX_STEPS {
            return Err(format!(
                "an episode of {steps:.3e} steps, more than {:e}",
                crate::evaluate::MAX_STEPS
            ));
        }
        self.reset(0)?;
        Ok(self)
    }

    /// Each action held for `frame_skip` physics steps (≥ 1), and what
    /// is observed. A scene without sensors can only observe its state.
    pub fn with_actions(
        mut self,
        frame_skip: u32,
        observation: Observation,
    ) -> Result<SceneEnv, String> {
        if frame_skip == 0 {
            return Err("frame_skip must be at least 1".into());
        }
        let steps = self.physics_limit();
        if u64::from(frame_skip) > steps {
            return Err(format!(
                "frame_skip {frame_skip} holds each action longer than the episode ({} s, {steps} steps of {} s)",
                animats_engine::Shown(self.spec.duration),
                animats_engine::Shown(self.scene.dt)
            ));
        }
        if observation != Observation::State && self.scene.nervous.sensors.is_empty() {
            return Err(
                "the scene has no [[sensor]]: observe its state (observation = \"state\"), or give it sensors".into(),
            );
        }
        self.frame_skip = frame_skip;
        self.observation = observation;
        self.observations = self.names();
        self.reset(0)?;
        Ok(self)
    }

    /// The physics steps per action that make the agent act at about
    /// `hz` times a simulated second with the scene's step (every step if
    /// `hz` is faster than the steps); refused if one action would last
    /// longer than the episode.
    pub fn frame_skip_for(&self, hz: f64) -> Result<u32, String> {
        let skip = (1.0 / hz / self.scene.dt).round();
        if !(hz > 0.0 && skip <= self.physics_limit() as f64) {
            return Err(format!(
                "act_hz {} asks for an action every {} s, longer than the episode ({} s)",
                animats_engine::Shown(hz),
                animats_engine::Shown(1.0 / hz),
                animats_engine::Shown(self.spec.duration)
            ));
        }
        if skip > f64::from(u32::MAX) {
            return Err(format!(
                "act_hz {} asks for an action every {skip:e} steps, more than frame_skip's {}",
                animats_engine::Shown(hz),
                u32::MAX
            ));
        }
        Ok((skip as u32).max(1))
    }

    /// The names of the observations, in order.
    fn names(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.observation != Observation::State {
            out.extend(self.scene.nervous.sensors.iter().map(|(n, _)| n.clone()));
        }
        if self.observation != Observation::Sensors {
            let name = |p: &ParticleId| self.scene.name(*p).to_string();
            out.push("centre y".into());
            out.extend(["centre vx", "centre vy", "centre vz"].map(String::from));
            for axis in ["x", "y", "z"] {
                out.extend(self.moving.iter().map(|p| format!("{axis} {}", name(p))));
            }
            for axis in ["vx", "vy", "vz"] {
                out.extend(self.moving.iter().map(|p| format!("{axis} {}", name(p))));
            }
            for (k, s) in self.scene.world.forces().springs.iter().enumerate() {
                let (a, b) = s.ends();
                out.push(format!("length {k} {}-{}", name(&a), name(&b)));
            }
            out.extend(self.moving.iter().map(|p| format!("contact {}", name(p))));
        }
        out
    }

    /// The state's values, appended to `out` in the order of [`Self::names`].
    fn state(&self, out: &mut Vec<f64>) {
        let w = &self.scene.world;
        let (pos, vel, mass) = (&w.state().pos, &w.state().vel, &w.particles().mass);
        let (mut c, mut v, mut m) = (DVec3::ZERO, DVec3::ZERO, 0.0);
        for p in &self.moving {
            let i = p.index();
            c += pos[i] * mass[i];
            v += vel[i] * mass[i];
            m += mass[i];
        }
        if m > 0.0 {
            (c, v) = (c / m, v / m);
        }
        out.push(c.y);
        out.extend([v.x, v.y, v.z]);
        for k in 0..3 {
            out.extend(self.moving.iter().map(|p| pos[p.index()][k] - c[k]));
        }
        for k in 0..3 {
            out.extend(self.moving.iter().map(|p| vel[p.index()][k] - v[k]));
        }
        for s in w.forces().springs.iter() {
            let (a, b) = s.ends();
            out.push((pos[a.index()] - pos[b.index()]).length());
        }
        let floor = w.terrain().is_some();
        out.extend(
            self.moving
                .iter()
                .map(|p| f64::from(u8::from(floor && touches_floor(w, *p)))),
        );
    }

    /// What it observes.
    pub fn observation(&self) -> Observation {
        self.observation
    }

    /// Physics steps per action.
    pub fn frame_skip(&self) -> u32 {
        self.frame_skip
    }

    /// The centre of the `[evolve]` particles now.
    pub fn watched_centre(&self) -> DVec3 {
        self.spec.centre(&self.scene.world)
    }

    /// Whether the episode's physics steps are all taken.
    pub fn physics_done(&self) -> bool {
        self.physics_steps >= self.physics_limit() || self.over
    }

    /// The distance the centre has gone along the axis since the reset, m.
    pub fn distance(&self) -> f64 {
        (self.last - self.start).dot(self.spec.axis)
    }

    /// The actuators' positive work since the reset, J.
    pub fn energy(&self) -> f64 {
        self.work.positive
    }

    /// Why the episode ended, once it has.
    pub fn ended(&self) -> Option<&Ended> {
        self.ended.as_ref()
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
        let mut fitness = self.spec.time_weight * self.physics_steps as f64 * self.scene.dt
            + self.spec.distance_weight * distance;
        if self.spec.energy_weight != 0.0 {
            fitness -= self.spec.energy_weight * self.work.positive;
        }
        if let Some((t, w)) = self.spec.target {
            fitness -= w * (self.last - t).length();
        }
        fitness
    }
}

impl SceneEnv {
    /// Physics steps in a whole episode.
    fn physics_limit(&self) -> u64 {
        (self.spec.duration / self.scene.dt).round() as u64
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
    fn observation_bounds(&self) -> Vec<(f64, f64)> {
        let sensors = match self.observation {
            Observation::State => 0,
            _ => self.scene.nervous.sensors.len(),
        };
        let mut b = vec![(0.0, 1.0); sensors];
        b.resize(self.observations.len(), (f64::NEG_INFINITY, f64::INFINITY));
        if self.observation != Observation::Sensors {
            // Contacts: 0 or 1.
            let n = self.observations.len();
            for x in &mut b[n - self.moving.len()..] {
                *x = (0.0, 1.0);
            }
        }
        b
    }
    fn dt(&self) -> f64 {
        self.scene.dt * f64::from(self.frame_skip)
    }
    fn max_steps(&self) -> u64 {
        self.physics_limit().div_ceil(u64::from(self.frame_skip))
    }

    fn reset(&mut self, seed: u64) -> Result<(), String> {
        let mut scene = self.problem.fresh()?;
        if let Some(dt) = self.dt {
            scene.dt = dt;
        }
        perturb(&mut scene.world, seed, self.noise)?;
        self.start = self.spec.centre(&scene.world);
        self.last = self.start;
        self.ended = self.spec.ending(&scene.world);
        self.over = self.ended.is_some();
        self.scene = scene;
        self.physics_steps = 0;
        self.work = Work::default();
        self.fitness = 0.0;
        Ok(())
    }

    fn observe(&self, out: &mut [f64]) {
        let mut v = Vec::with_capacity(out.len());
        if self.observation != Observation::State {
            v.extend(
                self.scene
                    .nervous
                    .sensors
                    .iter()
                    .map(|(_, s)| s.level(&self.scene.world)),
            );
        }
        if self.observation != Observation::Sensors {
            self.state(&mut v);
        }
        for (o, x) in out.iter_mut().zip(v) {
            *o = x;
        }
    }

    fn step(&mut self, action: &[f64]) -> Result<Transition, String> {
        check_action(&self.actions, action)?;
        if self.over {
            return Err("the episode has ended: call reset".into());
        }
        let dt = self.scene.dt;
        let limit = self.physics_limit();
        let mut blew_up = false;
        let mut ending = None;
        for _ in 0..self.frame_skip {
            self.work.before(&self.scene);
            if self.scene.step_driven(action, dt).is_err() {
                blew_up = true;
                break;
            }
            self.work.after(&self.scene, dt);
            self.physics_steps += 1;
            let c = self.spec.centre(&self.scene.world);
            if !c.is_finite() {
                blew_up = true;
                break;
            }
            self.last = c;
            ending = self.spec.ending(&self.scene.world);
            if ending.is_some() || self.physics_steps >= limit {
                break;
            }
        }
        let fitness = self.score(blew_up);
        let reward = fitness - self.fitness;
        self.fitness = fitness;
        if blew_up {
            ending = Some(Ended::BlowUp);
        }
        let terminated = ending.is_some();
        let t = Transition {
            reward,
            terminated,
            truncated: !terminated && self.physics_steps >= limit,
        };
        if t.truncated {
            ending = Some(Ended::Timeout);
        }
        self.ended = ending;
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
