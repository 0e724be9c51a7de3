//! Environments driven from outside, in the shape reinforcement learning
//! uses (Gymnasium's): actions are actuator levels in [0, 1], observations
//! sensor levels in [0, 1], and the reward of a step is the increase of the
//! thesis's fitness, so that an episode's rewards add up to the fitness an
//! evaluation of the same run gives. The roobot's (`roobot/env.rs`) and a
//! scene's (`animats_scene::env`) implement [`Env`];
//! [`crate::vec_env::VecEnv`] steps many copies at once.

/// What one step of an environment gave.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transition {
    /// The increase of the fitness over the step.
    pub reward: f64,
    /// The episode ended by the task's own rule (a fall, a touch, a blow-up).
    pub terminated: bool,
    /// The episode reached its time limit.
    pub truncated: bool,
}

impl Transition {
    /// A step's transition: `terminated` by the task's rule, else truncated
    /// once `steps` reaches `max_steps`.
    pub fn after(reward: f64, terminated: bool, steps: u64, max_steps: u64) -> Transition {
        Transition {
            reward,
            terminated,
            truncated: !terminated && steps >= max_steps,
        }
    }

    /// True when the episode is over.
    pub fn ends(&self) -> bool {
        self.terminated || self.truncated
    }
}

/// An environment: one world, reset and stepped by a program.
pub trait Env: Send {
    /// Observations per step.
    fn observation_size(&self) -> usize;
    /// Actions per step.
    fn action_size(&self) -> usize;
    /// What each observation is.
    fn observation_names(&self) -> Vec<String>;
    /// What each action drives.
    fn action_names(&self) -> Vec<String>;
    /// Each observation's (low, high) bounds; sensor levels: (0, 1).
    fn observation_bounds(&self) -> Vec<(f64, f64)> {
        vec![(0.0, 1.0); self.observation_size()]
    }
    /// Simulated seconds per step.
    fn dt(&self) -> f64;
    /// Steps in a whole episode (the time limit).
    fn max_steps(&self) -> u64;
    /// Starts a new episode. `seed` draws the start's noise, if the
    /// environment adds any; the same seed gives the same episode.
    fn reset(&mut self, seed: u64) -> Result<(), String>;
    /// Writes the observation now into `out` (`observation_size` long).
    fn observe(&self, out: &mut [f64]);
    /// Applies `action` (`action_size` finite levels, clamped to [0, 1]) and
    /// advances one step. Stepping an episode that has ended is an error.
    fn step(&mut self, action: &[f64]) -> Result<Transition, String>;
    /// Simulated time since the reset, s.
    fn time(&self) -> f64;
    /// The world as it stands (positions for drawing, tests).
    fn world(&self) -> &animats_engine::World;
}

/// Checks an action's length and that every level is finite.
pub fn check_action<S: AsRef<str>>(names: &[S], action: &[f64]) -> Result<(), String> {
    if action.len() != names.len() {
        let list: Vec<&str> = names.iter().map(|n| n.as_ref()).collect();
        return Err(format!(
            "an action has {} levels ({}), got {}",
            names.len(),
            list.join(", "),
            action.len()
        ));
    }
    match action.iter().position(|a| !a.is_finite()) {
        Some(i) => Err(format!(
            "the action's level for `{}` is not finite: {}",
            names[i].as_ref(),
            action[i]
        )),
        None => Ok(()),
    }
}

/// Adds to every moving particle's velocity a uniform random vector of
/// components in [-noise, noise) drawn from `seed`'s stream (MuJoCo's
/// environments perturb their start in the same way); nothing when `noise`
/// is 0.
pub fn perturb(world: &mut animats_engine::World, seed: u64, noise: f64) -> Result<(), String> {
    if noise == 0.0 {
        return Ok(());
    }
    if !(noise > 0.0 && noise.is_finite()) {
        return Err(format!(
            "reset noise must be a finite number ≥ 0, got {noise}"
        ));
    }
    let mut rng = crate::random::Random::for_entry(seed, 0);
    let ids: Vec<_> = world.particle_ids().collect();
    for p in ids {
        let kick = animats_engine::DVec3::new(
            rng.between(-noise, noise),
            rng.between(-noise, noise),
            rng.between(-noise, noise),
        );
        let v = world.velocity(p) + kick;
        world.set_velocity(p, v).map_err(|e| e.to_string())?;
    }
    Ok(())
}

impl<E: Env + ?Sized> Env for Box<E> {
    fn observation_size(&self) -> usize {
        (**self).observation_size()
    }
    fn action_size(&self) -> usize {
        (**self).action_size()
    }
    fn observation_names(&self) -> Vec<String> {
        (**self).observation_names()
    }
    fn action_names(&self) -> Vec<String> {
        (**self).action_names()
    }
    fn observation_bounds(&self) -> Vec<(f64, f64)> {
        (**self).observation_bounds()
    }
    fn dt(&self) -> f64 {
        (**self).dt()
    }
    fn max_steps(&self) -> u64 {
        (**self).max_steps()
    }
    fn reset(&mut self, seed: u64) -> Result<(), String> {
        (**self).reset(seed)
    }
    fn observe(&self, out: &mut [f64]) {
        (**self).observe(out)
    }
    fn step(&mut self, action: &[f64]) -> Result<Transition, String> {
        (**self).step(action)
    }
    fn time(&self) -> f64 {
        (**self).time()
    }
    fn world(&self) -> &animats_engine::World {
        (**self).world()
    }
}
