//! The roobot, a hopping monopod (thesis §3.2.1, Appendix B `FSMRobot`).
//!
//! - `body.rs`: the masses, springs, joints and motors, and their constants.
//! - `fsm.rs`: the four-state hopping controller, a [`Brain`].
//! - `raibert.rs`: Raibert's three-part controller, a baseline [`Brain`].
//! - `params.rs`: the FSM's 14 parameters; `params_file.rs`: their files
//!   (`params/`).
//! - `gait.rs`: stance durations and foot slide, for reports.
//!
//! [`install`] builds one into a world and its nervous system: the body;
//! its sensors (`NAME.foot_height`, `NAME.leg_angle`, `NAME.hip_speed`,
//! `NAME.touchdown`); its actuators (`NAME.leg`, the leg's rest length;
//! `NAME.hip`, the hip motor, gated to act only in flight; `NAME.ankle`,
//! the ankle motor, gated to act only in stance); and its brain, the
//! controller `NAME`. Everything else (the floor, the air, how a run is
//! scored and when it ends) is the scene's, as for every creature.

pub mod body;
pub mod fsm;
pub mod gait;
pub mod params;
pub mod params_file;
pub mod raibert;

use crate::actuator::Actuator;
use crate::actuators::{AnyActuator, JointTorque, SpringRestLength};
use crate::brain::Brain;
use crate::nervous_system::{Gate, Inputs, NervousSystem, Senses, Wired};
use crate::sensor::Sensor;
use crate::sensors::{HeightSensor, SpeedSensor, TiltSensor, TouchdownSensor};
use animats_engine::{DVec3, ModelError, ParticleId, World};
pub use body::{Body, BodyConstants};
pub use fsm::{Command, HopFsm, HopState, Orders, Senses as HopSenses};
pub use params::{HopParams, PARAM_COUNT, PARAM_NAMES};
pub use raibert::Raibert;

/// The brain a roobot is built with.
#[derive(Clone, Debug, PartialEq)]
pub enum RoobotBrain {
    /// The thesis's hopping FSM with these parameters.
    Hop(HopParams),
    /// Raibert's controller with these gains.
    Raibert([f64; raibert::GAIN_COUNT]),
    /// None: its actuators stay where they are put (by a program, or by a
    /// controller of the scene's).
    None,
}

/// Names of the roobot's sensors, after `NAME.`, in the order installed.
pub const SENSORS: [&str; 4] = ["foot_height", "leg_angle", "hip_speed", "touchdown"];

/// Names of the roobot's actuators, after `NAME.`, in the order installed.
pub const ACTUATORS: [&str; 3] = ["leg", "hip", "ankle"];

/// Where a roobot's parts are in the world and its nervous system.
#[derive(Clone, Debug, PartialEq)]
pub struct Installed {
    /// Handles to its body.
    pub body: Body,
    /// Index of its first sensor (the others follow in [`SENSORS`] order).
    pub sensors: usize,
    /// Index of its first actuator (the others follow in [`ACTUATORS`] order).
    pub actuators: usize,
    /// Index of its controller, if it has a brain.
    pub controller: Option<usize>,
}

/// Builds a roobot called `name` standing at `base` facing `heading`
/// (radians from +x) into `world`, and its sensors, actuators and brain
/// into `nervous`. Names are not checked for clashes: the caller does.
pub fn install(
    world: &mut World,
    nervous: &mut NervousSystem,
    name: &str,
    constants: &BodyConstants,
    base: DVec3,
    heading: f64,
    brain: RoobotBrain,
) -> Result<Installed, ModelError> {
    let body = body::build(world, constants, base, heading)?;
    let height = HeightSensor {
        particle: body.foot,
    };
    let angle = TiltSensor {
        base: body.foot,
        tip: body.hip,
        forward: body.forward,
        gain: constants.leg_angle_gain,
    };
    let speed = SpeedSensor {
        particle: body.hip,
        forward: body.forward,
    };
    // The thesis's sensor assumes 9.8 m/s² whatever the world's gravity.
    let touchdown = TouchdownSensor { height, g: 9.8 };
    let sensors = nervous.sensors.len();
    let boxed: [Box<dyn Sensor + Send>; 4] = [
        Box::new(height),
        Box::new(angle),
        Box::new(speed),
        Box::new(touchdown),
    ];
    for (part, s) in SENSORS.iter().zip(boxed) {
        nervous.sensors.push((format!("{name}.{part}"), s));
    }

    let (l0, l1) = constants.leg_range;
    let leg = Actuator::new(SpringRestLength(body.leg), l0, l1, world);
    let torque =
        |motor, max: f64, world: &World| Actuator::new(JointTorque(motor), -max, max, world);
    let hip = torque(body.hip_motor, constants.hip_torque, world);
    let ankle = torque(body.ankle_motor, constants.ankle_torque, world);
    // The hip motor acts only in flight and the ankle motor only in stance
    // (thesis §3.2.1.2): the one without ground to push against is idle,
    // whatever level its controller left it at.
    let foot = sensors; // the foot's height sensor
    let gates = [
        None,
        Some(Gate {
            sensor: foot,
            threshold: 0.0,
            above: true,
        }),
        Some(Gate {
            sensor: foot,
            threshold: 0.0,
            above: false,
        }),
    ];
    let actuators = nervous.actuators.len();
    let parts = [
        AnyActuator::Spring(leg),
        AnyActuator::TorqueJoint(hip),
        AnyActuator::TorqueJoint(ankle),
    ];
    for ((part, a), gate) in ACTUATORS.iter().zip(parts).zip(gates) {
        nervous.add_actuator(format!("{name}.{part}"), a, None, gate);
    }
    let outputs = vec![actuators, actuators + 1, actuators + 2];

    let wired: Option<(Box<dyn Brain>, Inputs)> = match brain {
        RoobotBrain::Hop(params) => Some((
            Box::new(HopFsm::new(params)),
            Inputs::Senses(Box::new(FsmSenses {
                sensors,
                actuators,
                speed,
            })),
        )),
        RoobotBrain::Raibert(gains) => Some((
            Box::new(Raibert::new(gains, constants)),
            Inputs::Senses(Box::new(raibert::RaibertSenses::new(&body, angle, sensors))),
        )),
        RoobotBrain::None => None,
    };
    let controller = wired.map(|(brain, inputs)| {
        nervous
            .controllers
            .push(Wired::new(name.to_string(), brain, inputs, outputs));
        nervous.controllers.len() - 1
    });
    Ok(Installed {
        body,
        sensors,
        actuators,
        controller,
    })
}

/// What the hopping FSM reads ([`fsm::BRAIN_INPUTS`]): the four sensors'
/// levels, the hip's forward velocity (m/s, unclamped, as Appendix B reads
/// it), then the leg's, hip's and ankle's levels now and at the start.
pub struct FsmSenses {
    /// Index of the foot height sensor (the others follow).
    pub sensors: usize,
    /// Index of the leg actuator (hip and ankle follow).
    pub actuators: usize,
    /// The hip's forward velocity.
    pub speed: SpeedSensor,
}

impl Senses for FsmSenses {
    fn count(&self) -> usize {
        fsm::BRAIN_INPUTS.len()
    }

    fn read(
        &self,
        world: &World,
        levels: &[f64],
        actuators: &[(String, AnyActuator)],
        out: &mut [f64],
    ) {
        out[..4].copy_from_slice(&levels[self.sensors..self.sensors + 4]);
        out[4] = self.speed.speed(world);
        let mine = &actuators[self.actuators..self.actuators + 3];
        for (k, (_, a)) in mine.iter().enumerate() {
            out[5 + k] = a.level();
            out[8 + k] = a.initial_level();
        }
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}

/// True while a roobot's `foot` touches the floor (its height sensor reads 0).
pub fn foot_down(world: &World, foot: ParticleId) -> bool {
    HeightSensor { particle: foot }.level(world) <= 0.0
}
