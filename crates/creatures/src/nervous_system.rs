//! The sensors, actuators and controllers a scene file declares, wired
//! together: once per step, before the world advances, every sensor is read,
//! then each controller (in the order declared) turns its inputs' levels
//! into its outputs' levels, and the actuators drive their parameters.
//!
//! An actuator may have a top speed (`rate`, levels per second): a
//! controller's order then moves it at most `rate × dt` per step, as a
//! muscle cannot change its length at once.
//!
//! Each actuator is driven by at most one controller; one that none drives
//! stays at its level (which a program may set, [`NervousSystem::set_levels`]).

use crate::actuators::AnyActuator;
use crate::brain::Brain;
use crate::controller::Actor;
use crate::sensor::{unit, Sensor};
use crate::sensors::ScaledSensor;
use animats_engine::World;

/// A controller and what it is wired to.
pub struct Wired {
    /// Its name in the scene.
    pub name: String,
    /// The brain.
    pub brain: Box<dyn Brain>,
    /// Indices of its input sensors.
    pub inputs: Vec<usize>,
    /// Indices of the actuators it drives.
    pub outputs: Vec<usize>,
    in_buf: Vec<f64>,
    out_buf: Vec<f64>,
}

impl Wired {
    /// The levels the brain ordered at the last step, before clamping and
    /// its actuators' `rate` (one per output).
    pub fn orders(&self) -> &[f64] {
        &self.out_buf
    }

    /// Wires `brain` to sensors `inputs` and actuators `outputs`.
    pub fn new(
        name: String,
        brain: Box<dyn Brain>,
        inputs: Vec<usize>,
        outputs: Vec<usize>,
    ) -> Wired {
        let (ni, no) = (inputs.len(), outputs.len());
        Wired {
            name,
            brain,
            inputs,
            outputs,
            in_buf: vec![0.0; ni],
            out_buf: vec![0.0; no],
        }
    }
}

/// A scene's sensors, actuators and controllers.
#[derive(Default)]
pub struct NervousSystem {
    /// Named sensors, in the scene's order.
    pub sensors: Vec<(String, ScaledSensor)>,
    /// Named actuators, in the scene's order.
    pub actuators: Vec<(String, AnyActuator)>,
    /// The most each actuator's level may change per second (`None`: no
    /// limit), in the order of `actuators`.
    pub rates: Vec<Option<f64>>,
    /// Controllers, in the scene's order.
    pub controllers: Vec<Wired>,
    levels: Vec<f64>,
}

impl NervousSystem {
    /// True when it has nothing to do.
    pub fn is_empty(&self) -> bool {
        self.sensors.is_empty() && self.actuators.is_empty() && self.controllers.is_empty()
    }

    /// The index of the controller called `name`.
    pub fn controller(&self, name: &str) -> Option<usize> {
        self.controllers.iter().position(|c| c.name == name)
    }

    /// Every sensor's level now, in the scene's order.
    pub fn sensor_levels(&self, world: &World) -> Vec<f64> {
        self.sensors.iter().map(|(_, s)| s.level(world)).collect()
    }

    /// Every actuator's level, in the scene's order.
    pub fn actuator_levels(&self) -> Vec<f64> {
        self.actuators.iter().map(|(_, a)| a.level()).collect()
    }

    /// Sets every actuator's level (a program driving the creature, e.g.
    /// from Python); controllers overwrite the ones they drive at the next
    /// step.
    pub fn set_levels(&mut self, world: &mut World, levels: &[f64]) -> Result<(), String> {
        if levels.len() != self.actuators.len() {
            return Err(format!(
                "{} levels given for {} actuators",
                levels.len(),
                self.actuators.len()
            ));
        }
        for ((_, a), l) in self.actuators.iter_mut().zip(levels) {
            a.set_level(world, *l);
        }
        Ok(())
    }

    /// Reads the sensors and runs every controller for the step about to be
    /// taken.
    pub fn act(&mut self, world: &mut World, dt: f64) {
        if self.controllers.is_empty() {
            return;
        }
        self.levels.clear();
        for (_, s) in &self.sensors {
            self.levels.push(s.level(world));
        }
        let t = world.time();
        for c in &mut self.controllers {
            for (x, &i) in c.in_buf.iter_mut().zip(&c.inputs) {
                *x = self.levels[i];
            }
            c.brain.think(t, dt, &c.in_buf, &mut c.out_buf);
            for (&o, &l) in c.outputs.iter().zip(&c.out_buf) {
                slew(
                    &mut self.actuators[o].1,
                    self.rates.get(o).copied().flatten(),
                    world,
                    l,
                    dt,
                );
            }
        }
    }

    /// Drives every actuator towards `levels` (scene order) for the step
    /// about to be taken, each at most its `rate` allows, and runs no
    /// controller: a program outside the scene is the brain (the Python
    /// environments). Levels must be finite; they are clamped to [0, 1].
    pub fn drive(&mut self, world: &mut World, levels: &[f64], dt: f64) -> Result<(), String> {
        if levels.len() != self.actuators.len() {
            return Err(format!(
                "{} levels given for {} actuators",
                levels.len(),
                self.actuators.len()
            ));
        }
        if let Some(i) = levels.iter().position(|l| !l.is_finite()) {
            return Err(format!(
                "the level of actuator `{}` is not finite: {}",
                self.actuators[i].0, levels[i]
            ));
        }
        for (o, &l) in levels.iter().enumerate() {
            slew(
                &mut self.actuators[o].1,
                self.rates.get(o).copied().flatten(),
                world,
                l,
                dt,
            );
        }
        Ok(())
    }
}

/// Moves `a` towards `level` (clamped to [0, 1]), at most `rate × dt`.
fn slew(a: &mut AnyActuator, rate: Option<f64>, world: &mut World, level: f64, dt: f64) {
    let mut level = unit(level);
    if let Some(rate) = rate {
        let now = a.level();
        level = now + (level - now).clamp(-rate * dt, rate * dt);
    }
    a.set_level(world, level);
}

impl Actor for NervousSystem {
    fn act(&mut self, world: &mut World, dt: f64) {
        NervousSystem::act(self, world, dt);
    }
}
