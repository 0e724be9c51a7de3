//! The roobot as an environment ([`crate::env::Env`]): the world and end
//! rule of its fitness evaluation (`evaluate.rs`), with a program in the
//! FSM's place. Actions: the leg's, hip's and ankle's levels (the hip motor
//! acts only in flight and the ankle only in stance, as for every roobot
//! controller). Observations: its four sensors. Reward: the increase of
//! `time upright + 50 × forward distance of the hip` over the step, so an
//! episode's rewards add up to the evaluation's fitness.

use super::evaluate::{ended, evaluation_world, EvalSettings};
use super::{HopParams, Roobot};
use crate::env::{check_action, perturb, Env, Transition};
use animats_engine::World;

/// What each action drives.
pub const ACTIONS: [&str; 3] = ["leg", "hip", "ankle"];

/// What each observation is (the sensors' levels, in [0, 1]).
pub const OBSERVATIONS: [&str; 4] = [
    "foot height",
    "leg angle",
    "hip forward speed",
    "time till touchdown",
];

/// The roobot's evaluation, stepped by a program.
pub struct RoobotEnv {
    settings: EvalSettings,
    noise: f64,
    world: World,
    roobot: Roobot,
    x0: f64,
    steps: u64,
    fitness: f64,
    over: bool,
}

impl RoobotEnv {
    /// An environment evaluated as `settings` says (the thesis's: 20 s at
    /// 8 ms, RK4), its start's velocities perturbed by up to `noise` m/s.
    pub fn new(settings: EvalSettings, noise: f64) -> Result<RoobotEnv, String> {
        if !(settings.dt > 0.0 && settings.dt.is_finite()) {
            return Err(format!("dt must be a positive number, got {}", settings.dt));
        }
        if !(settings.seconds > 0.0 && settings.seconds.is_finite()) {
            return Err(format!(
                "seconds must be a positive number, got {}",
                settings.seconds
            ));
        }
        if settings.seconds / settings.dt > 1e12 {
            return Err("an episode of more than 1e12 steps".into());
        }
        let (world, roobot) =
            evaluation_world(HopParams::INITIAL, &settings).map_err(|e| e.to_string())?;
        let mut env = RoobotEnv {
            settings,
            noise,
            x0: 0.0,
            world,
            roobot,
            steps: 0,
            fitness: 0.0,
            over: false,
        };
        env.reset(0)?;
        Ok(env)
    }

    /// The roobot.
    pub fn roobot(&self) -> &Roobot {
        &self.roobot
    }

    /// The fitness so far (the sum of the rewards since the reset, but for
    /// rounding).
    pub fn fitness(&self) -> f64 {
        self.fitness
    }

    fn hip_x(&self) -> f64 {
        self.world
            .position(self.roobot.body.hip)
            .dot(self.roobot.body.forward)
    }
}

impl Env for RoobotEnv {
    fn observation_size(&self) -> usize {
        OBSERVATIONS.len()
    }
    fn action_size(&self) -> usize {
        ACTIONS.len()
    }
    fn observation_names(&self) -> Vec<String> {
        OBSERVATIONS.iter().map(|s| s.to_string()).collect()
    }
    fn action_names(&self) -> Vec<String> {
        ACTIONS.iter().map(|s| s.to_string()).collect()
    }
    fn dt(&self) -> f64 {
        self.settings.dt
    }
    fn max_steps(&self) -> u64 {
        (self.settings.seconds / self.settings.dt).round() as u64
    }

    fn reset(&mut self, seed: u64) -> Result<(), String> {
        let (mut world, roobot) =
            evaluation_world(HopParams::INITIAL, &self.settings).map_err(|e| e.to_string())?;
        perturb(&mut world, seed, self.noise)?;
        self.world = world;
        self.roobot = roobot;
        self.x0 = self.hip_x();
        self.steps = 0;
        self.fitness = 0.0;
        self.over = ended(&self.world, &self.roobot, &self.settings).is_some();
        Ok(())
    }

    fn observe(&self, out: &mut [f64]) {
        let s = self.roobot.sensors.read(&self.world);
        for (o, x) in out
            .iter_mut()
            .zip([s.height, s.angle, s.speed, s.touchdown])
        {
            *o = x;
        }
    }

    fn step(&mut self, action: &[f64]) -> Result<Transition, String> {
        check_action(&ACTIONS, action)?;
        if self.over {
            return Err("the episode has ended: call reset".into());
        }
        let r = &mut self.roobot;
        r.leg.set_level(&mut self.world, action[0]);
        r.hip.set_level(&mut self.world, action[1]);
        r.ankle.set_level(&mut self.world, action[2]);
        let down = r.foot_down(&self.world);
        r.gate_motors(&mut self.world, down);
        let blew_up = self.world.step(self.settings.dt).is_err();
        if !blew_up {
            self.steps += 1;
        }
        // The evaluation's fitness had the run ended here (evaluate.rs).
        let fitness = self.steps as f64 * self.settings.dt + 50.0 * (self.hip_x() - self.x0);
        let reward = if fitness.is_finite() {
            let r = fitness - self.fitness;
            self.fitness = fitness;
            r
        } else {
            0.0
        };
        let terminated = blew_up
            || !fitness.is_finite()
            || ended(&self.world, &self.roobot, &self.settings).is_some();
        let t = Transition::after(reward, terminated, self.steps, self.max_steps());
        self.over = t.ends();
        Ok(t)
    }

    fn time(&self) -> f64 {
        self.world.time()
    }

    fn world(&self) -> &World {
        &self.world
    }
}
