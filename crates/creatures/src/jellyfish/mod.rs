//! The jellyfish (thesis §3.2.2, Appendix B `Jellyfish`): a dome of three
//! masses trailing three tentacles, swimming by pulses of a force along its
//! dome's normal and steering by pushing one side harder, choosing between
//! idling, tracking food and hovering by its internal energy.
//!
//! - `body.rs`: masses, springs and forces (Appendix B's constants);
//! - `fsm.rs`: the energy-driven behaviour FSM.
//!
//! Sensors: a food sensor at each dome mass and a depth sensor. Actuators:
//! the pulse force per dome mass (±4.5 times the submerged weight the mass
//! carries; Appendix B's ±5 N with the scene key `pulse_force`) and one
//! steering force per dome mass (a tenth of the pulse's, as Appendix B's
//! ±0.5 N against ±5 N), all along the dome's normal, recomputed every step.

pub mod body;
pub mod fsm;

use crate::actuator::Actuator;
use crate::actuators::ForceMagnitude;
use crate::brain::Brain;
use crate::controller::{Actor, Status};
use crate::sensor::Sensor;
use crate::sensors::{DepthSensor, FoodSensor};
use animats_engine::{DVec3, ModelError, ParticleId, World};
pub use body::{Body, JellyfishConstants};
pub use fsm::{Behaviour, JellyfishFsm, Orders, Senses};

/// A jellyfish in a world.
#[derive(Clone, Debug)]
pub struct Jellyfish {
    /// A name for reports.
    pub name: String,
    /// Handles to its parts.
    pub body: Body,
    /// One food sensor per dome mass.
    pub food: Vec<FoodSensor>,
    /// Its depth sense (dome mass 0).
    pub depth: DepthSensor,
    /// The pulse force.
    pub pulse: Actuator<ForceMagnitude>,
    /// The steering forces.
    pub steer: Vec<Actuator<ForceMagnitude>>,
    /// Its controller.
    pub fsm: JellyfishFsm,
    body_radius: f64,
    /// The brain's inputs and outputs, kept between steps (no allocation
    /// per step).
    scratch: (Vec<f64>, Vec<f64>),
}

impl Jellyfish {
    /// Builds a jellyfish with its dome centred at `at`, smelling `food`.
    pub fn build(
        world: &mut World,
        name: &str,
        constants: &JellyfishConstants,
        at: DVec3,
        food: ParticleId,
    ) -> Result<Jellyfish, ModelError> {
        let body = body::build(world, constants, at)?;
        let axis = body.normal(world);
        let pulse = Actuator::new(
            ForceMagnitude {
                force: body.pulse,
                axis,
            },
            -constants.pulse_force,
            constants.pulse_force,
            world,
        );
        let steer = body
            .steer
            .iter()
            .map(|f| {
                Actuator::new(
                    ForceMagnitude { force: *f, axis },
                    -constants.steer_force,
                    constants.steer_force,
                    world,
                )
            })
            .collect();
        Ok(Jellyfish {
            name: name.to_string(),
            food: body
                .dome
                .iter()
                .map(|d| FoodSensor { sensor: *d, food })
                .collect(),
            depth: DepthSensor {
                particle: body.dome[0],
                ceiling: constants.ceiling,
            },
            body,
            pulse,
            steer,
            fsm: JellyfishFsm::new(constants.pulse_period),
            body_radius: constants.dome_radius,
            scratch: (Vec::new(), Vec::new()),
        })
    }

    /// Radius of its dome ring, m: the unit of its balance sense.
    pub fn dome_radius(&self) -> f64 {
        self.body_radius
    }

    /// Mean horizontal distance from the dome masses to the food, m.
    pub fn food_distance(&self, world: &World) -> f64 {
        self.food.iter().map(|f| f.distance(world)).sum::<f64>() / self.food.len() as f64
    }
}

impl Actor for Jellyfish {
    fn act(&mut self, world: &mut World, dt: f64) {
        // Every force acts along the dome's current normal.
        let axis = self.body.normal(world);
        self.pulse.target_mut().axis = axis;
        for s in &mut self.steer {
            s.target_mut().axis = axis;
        }
        let centre = self.body.centre(world);
        let radius = self.body_radius;
        let (inputs, out) = &mut self.scratch;
        inputs.clear();
        inputs.extend(self.food.iter().map(|f| f.level(world)));
        inputs.push(self.depth.level(world));
        inputs.extend(
            self.body
                .dome
                .iter()
                .map(|d| (world.position(*d).y - centre.y) / radius),
        );
        inputs.push(self.pulse.initial_level());
        inputs.extend(self.steer.iter().map(|s| s.initial_level()));
        out.clear();
        out.resize(1 + self.steer.len(), 0.0);
        Brain::think(&mut self.fsm, world.time(), dt, inputs, out);
        self.pulse.set_level(world, out[0]);
        for (s, level) in self.steer.iter_mut().zip(&out[1..]) {
            s.set_level(world, *level);
        }
    }

    fn status(&self) -> Option<Status> {
        Some(Status {
            name: self.name.clone(),
            state: self.fsm.behaviour().name(),
            energy: Some(self.fsm.energy()),
            phase: Some(self.fsm.phase()),
        })
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    /// Its brain's state and its forces' levels.
    fn save_state(&self) -> Option<crate::kept::Kept> {
        let levels: Vec<f64> = std::iter::once(self.pulse.level())
            .chain(self.steer.iter().map(|s| s.level()))
            .collect();
        Some(crate::kept::Kept::new((
            Brain::save_state(&self.fsm),
            levels,
        )))
    }

    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        type K = (Option<crate::kept::Kept>, Vec<f64>);
        let (fsm, levels) = crate::kept::required::<K>(kept, &self.name)?;
        if levels.len() != 1 + self.steer.len() {
            return Err(format!(
                "{}: the snapshot is of another jellyfish",
                self.name
            ));
        }
        Brain::load_state(&mut self.fsm, fsm.as_ref())?;
        self.pulse.set_level_alone(levels[0]);
        for (s, &l) in self.steer.iter_mut().zip(&levels[1..]) {
            s.set_level_alone(l);
        }
        Ok(())
    }
}
