//! A scene's sensors, actuators and controllers wired together: once per
//! step, before the world advances, every sensor is read, then each
//! controller (in the order declared) turns its inputs into its outputs'
//! levels, the actuators drive their parameters, and gated actuators act
//! only while their gate is open.
//!
//! A controller's inputs are sensor levels, or a creature's own senses
//! ([`Senses`]: readings its brain takes raw, as the roobot's hopping FSM
//! reads the hip's velocity). An output of NaN leaves its actuator as it is.
//!
//! An actuator may have a top speed (`rate`, levels per second): a
//! controller's order then moves it at most `rate × dt` per step, as a
//! muscle cannot change its length at once. It may have a gate: a motor
//! that acts only while a sensor's level is above a threshold (or only
//! while it is not), as the roobot's hip motor acts only in flight.
//!
//! Each actuator is driven by at most one controller; one that none drives
//! stays at its level (which a program may set, [`NervousSystem::set_levels`]).

use crate::actuators::AnyActuator;
use crate::brain::Brain;
use crate::sensor::{unit, Sensor};
use animats_engine::World;

/// A creature's own senses: what its brain reads from the world, in the
/// brain's own order and units (levels, raw readings, its actuators'
/// levels).
pub trait Senses: Send {
    /// Inputs it gives.
    fn count(&self) -> usize;
    /// Reads them into `out`; `levels` are every sensor's level this step
    /// (the scene's order) and `actuators` every actuator.
    fn read(
        &self,
        world: &World,
        levels: &[f64],
        actuators: &[(String, AnyActuator)],
        out: &mut [f64],
    );
    /// Itself, for those that expose what they read (the GPU's packer
    /// reads the roobot's); a user's senses need not say.
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }
}

/// Where a controller's inputs come from.
pub enum Inputs {
    /// These sensors' levels (indices into [`NervousSystem::sensors`]).
    Sensors(Vec<usize>),
    /// A creature's own senses.
    Senses(Box<dyn Senses>),
}

impl Inputs {
    fn len(&self) -> usize {
        match self {
            Inputs::Sensors(s) => s.len(),
            Inputs::Senses(s) => s.count(),
        }
    }
}

/// When a gated actuator acts: while sensor `sensor`'s level is above
/// `threshold` (`above`), or while it is not (`!above`). A closed gate
/// holds its motor's torque or its force at zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gate {
    /// The sensor read (an index into [`NervousSystem::sensors`]).
    pub sensor: usize,
    /// The level compared.
    pub threshold: f64,
    /// Open above the threshold (else open at or below it).
    pub above: bool,
}

impl Gate {
    /// Whether the gate is open with the sensors at `levels`.
    pub fn open(&self, levels: &[f64]) -> bool {
        let l = levels[self.sensor];
        if self.above {
            l > self.threshold
        } else {
            l <= self.threshold
        }
    }
}

/// A controller and what it is wired to.
pub struct Wired {
    /// Its name in the scene.
    pub name: String,
    /// The brain.
    pub brain: Box<dyn Brain>,
    /// Where its inputs come from.
    pub inputs: Inputs,
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

    /// The inputs its brain read at the last step.
    pub fn inputs_read(&self) -> &[f64] {
        &self.in_buf
    }

    /// Wires `brain` to `inputs` and actuators `outputs`.
    pub fn new(name: String, brain: Box<dyn Brain>, inputs: Inputs, outputs: Vec<usize>) -> Wired {
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
    /// Named sensors, in the scene's order (a scene's `[[sensor]]`
    /// entries, a creature's own).
    pub sensors: Vec<(String, Box<dyn Sensor + Send>)>,
    /// Named actuators, in the scene's order.
    pub actuators: Vec<(String, AnyActuator)>,
    /// The most each actuator's level may change per second (`None`: no
    /// limit), in the order of `actuators`.
    pub rates: Vec<Option<f64>>,
    /// Each actuator's gate (`None`: it always acts), in the order of
    /// `actuators`.
    pub gates: Vec<Option<Gate>>,
    /// Controllers, in the scene's order.
    pub controllers: Vec<Wired>,
    /// Added to each level a controller orders, in the order of
    /// `actuators` (an evaluation's noisy trial); empty: none.
    pub offsets: Vec<f64>,
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

    /// The index of the sensor called `name`.
    pub fn sensor(&self, name: &str) -> Option<usize> {
        self.sensors.iter().position(|(n, _)| n == name)
    }

    /// The index of the actuator called `name`.
    pub fn actuator(&self, name: &str) -> Option<usize> {
        self.actuators.iter().position(|(n, _)| n == name)
    }

    /// Adds an actuator (with its top speed and gate); returns its index.
    pub fn add_actuator(
        &mut self,
        name: String,
        actuator: AnyActuator,
        rate: Option<f64>,
        gate: Option<Gate>,
    ) -> usize {
        self.actuators.push((name, actuator));
        self.rates.push(rate);
        self.gates.push(gate);
        self.actuators.len() - 1
    }

    /// Every sensor's level now, in the scene's order.
    pub fn sensor_levels(&self, world: &World) -> Vec<f64> {
        self.sensors.iter().map(|(_, s)| s.level(world)).collect()
    }

    /// Every actuator's level, in the scene's order.
    pub fn actuator_levels(&self) -> Vec<f64> {
        self.actuators.iter().map(|(_, a)| a.level()).collect()
    }

    /// One level for each actuator, or an error saying how many.
    fn check_levels(&self, levels: &[f64]) -> Result<(), String> {
        if levels.len() != self.actuators.len() {
            return Err(format!(
                "{} levels given for {} actuators",
                levels.len(),
                self.actuators.len()
            ));
        }
        Ok(())
    }

    /// Sets every actuator's level (a program driving the creature, e.g.
    /// from Python); controllers overwrite the ones they drive at the next
    /// step.
    pub fn set_levels(&mut self, world: &mut World, levels: &[f64]) -> Result<(), String> {
        self.check_levels(levels)?;
        for ((_, a), l) in self.actuators.iter_mut().zip(levels) {
            a.set_level(world, *l);
        }
        Ok(())
    }

    /// Each controller's brain's own state ([`Brain::save_state`]), in
    /// the scene's order.
    pub fn brain_states(&self) -> Vec<Option<crate::kept::Kept>> {
        self.controllers
            .iter()
            .map(|c| c.brain.save_state())
            .collect()
    }

    /// Takes back [`NervousSystem::brain_states`]; the error names the
    /// controller.
    pub fn set_brain_states(&mut self, kept: &[Option<crate::kept::Kept>]) -> Result<(), String> {
        if kept.len() != self.controllers.len() {
            return Err(format!(
                "the snapshot holds {} controllers' states for {} controllers",
                kept.len(),
                self.controllers.len()
            ));
        }
        for (c, k) in self.controllers.iter_mut().zip(kept) {
            c.brain
                .load_state(k.as_ref())
                .map_err(|e| format!("controller `{}`: {e}", c.name))?;
        }
        Ok(())
    }

    /// Sets every actuator's level without touching the world: for a
    /// snapshot's restore, whose world holds the values the levels gave.
    pub fn set_levels_alone(&mut self, levels: &[f64]) -> Result<(), String> {
        self.check_levels(levels)?;
        for ((_, a), l) in self.actuators.iter_mut().zip(levels) {
            a.set_level_alone(*l);
        }
        Ok(())
    }

    fn read_sensors(&mut self, world: &World) {
        self.levels.clear();
        for (_, s) in &self.sensors {
            self.levels.push(s.level(world));
        }
    }

    /// Reads the sensors and runs every controller for the step about to be
    /// taken, then applies the gates.
    pub fn act(&mut self, world: &mut World, dt: f64) {
        if self.controllers.is_empty() && self.gates.iter().all(Option::is_none) {
            return;
        }
        self.read_sensors(world);
        let t = world.time();
        for c in &mut self.controllers {
            match &c.inputs {
                Inputs::Sensors(inputs) => {
                    for (x, &i) in c.in_buf.iter_mut().zip(inputs) {
                        *x = self.levels[i];
                    }
                }
                Inputs::Senses(senses) => {
                    senses.read(world, &self.levels, &self.actuators, &mut c.in_buf)
                }
            }
            c.brain.think(t, dt, &c.in_buf, &mut c.out_buf);
            for (&o, &l) in c.outputs.iter().zip(&c.out_buf) {
                let l = match self.offsets.get(o) {
                    Some(d) => l + d,
                    None => l,
                };
                slew(
                    &mut self.actuators[o].1,
                    self.rates.get(o).copied().flatten(),
                    world,
                    l,
                    dt,
                );
            }
        }
        self.apply_gates(world);
    }

    /// Drives every actuator towards `levels` (scene order) for the step
    /// about to be taken, each at most its `rate` allows, its gate applied,
    /// and runs no controller: a program outside the scene is the brain
    /// (the Python environments). Levels must be finite; they are clamped
    /// to [0, 1].
    pub fn drive(&mut self, world: &mut World, levels: &[f64], dt: f64) -> Result<(), String> {
        self.check_levels(levels)?;
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
        if self.gates.iter().any(Option::is_some) {
            self.read_sensors(world);
            self.apply_gates(world);
        }
        Ok(())
    }

    /// Holds each gated actuator's parameter at zero while its gate is
    /// closed, at its level's value while open (the sensors as last read).
    fn apply_gates(&mut self, world: &mut World) {
        for ((_, a), gate) in self.actuators.iter().zip(&self.gates) {
            if let Some(g) = gate {
                a.gate(world, g.open(&self.levels));
            }
        }
    }
}

/// Moves `a` towards `level` (clamped to [0, 1]), at most `rate × dt`; NaN
/// leaves it as it is.
fn slew(a: &mut AnyActuator, rate: Option<f64>, world: &mut World, level: f64, dt: f64) {
    if level.is_nan() {
        return;
    }
    let mut level = unit(level);
    if let Some(rate) = rate {
        let now = a.level();
        level = now + (level - now).clamp(-rate * dt, rate * dt);
    }
    a.set_level(world, level);
}
