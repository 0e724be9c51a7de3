//! The roobot, a hopping monopod (thesis §3.2.1, Appendix B `FSMRobot`).
//!
//! - `body.rs`: the masses, springs, joints and motors, and their constants.
//! - `fsm.rs`: the four-state hopping controller.
//! - `params.rs`: its 14 parameters; `params_file.rs`: their files (`params/`, `best.toml`).
//! - `evaluate.rs`: one fitness evaluation, as the thesis's `HopEvolver` runs it.
//! - `env.rs`: the same evaluation stepped by a program (reinforcement learning).
//! - `gait.rs`: stance durations and foot slide, for reports.
//!
//! Actuators: the leg's rest length, the hip motor (acts only in flight) and
//! the ankle motor (acts only in stance). Sensors: foot height, leg angle
//! from the vertical, hip forward speed, time till touchdown.

pub mod body;
pub mod env;
pub mod evaluate;
pub mod fsm;
pub mod gait;
pub mod params;
pub mod params_file;
pub mod raibert;

use crate::actuator::Actuator;
use crate::actuators::{JointTorque, SpringRestLength};
use crate::brain::Brain;
use crate::controller::{Actor, Status};
use crate::sensor::Sensor;
use crate::sensors::{HeightSensor, SpeedSensor, TiltSensor, TouchdownSensor};
use animats_engine::{DVec3, ModelError, World};
pub use body::{Body, BodyConstants};
pub use fsm::{Command, HopFsm, HopState, Orders, Senses};
pub use params::{HopParams, PARAM_COUNT, PARAM_NAMES};

/// The roobot's four sensors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoobotSensors {
    /// Foot height, m.
    pub height: HeightSensor,
    /// Leg angle from the vertical.
    pub angle: TiltSensor,
    /// Hip forward speed, m/s.
    pub speed: SpeedSensor,
    /// Time till the foot touches down, s.
    pub touchdown: TouchdownSensor,
}

impl RoobotSensors {
    /// Reads every sense.
    pub fn read(&self, world: &World) -> Senses {
        Senses {
            height: self.height.level(world),
            angle: self.angle.level(world),
            speed: self.speed.level(world),
            touchdown: self.touchdown.level(world),
            hip_velocity: self.speed.speed(world),
        }
    }
}

/// A roobot in a world: body, sensors, actuators and its hopping FSM.
#[derive(Clone, Debug)]
pub struct Roobot {
    /// A name for reports.
    pub name: String,
    /// Handles to its parts.
    pub body: Body,
    /// Its senses.
    pub sensors: RoobotSensors,
    /// The leg's rest length.
    pub leg: Actuator<SpringRestLength>,
    /// The hip motor.
    pub hip: Actuator<JointTorque>,
    /// The ankle motor.
    pub ankle: Actuator<JointTorque>,
    /// The controller.
    pub fsm: HopFsm,
    landings: u32,
}

impl Roobot {
    /// Builds a roobot standing at `base` facing `heading` (radians from +x),
    /// controlled by `params`.
    pub fn build(
        world: &mut World,
        name: &str,
        constants: &BodyConstants,
        base: DVec3,
        heading: f64,
        params: HopParams,
    ) -> Result<Roobot, ModelError> {
        let body = body::build(world, constants, base, heading)?;
        let height = HeightSensor {
            particle: body.foot,
        };
        let sensors = RoobotSensors {
            height,
            angle: TiltSensor {
                base: body.foot,
                tip: body.hip,
                forward: body.forward,
                gain: constants.leg_angle_gain,
            },
            speed: SpeedSensor {
                particle: body.hip,
                forward: body.forward,
            },
            // The thesis's sensor assumes 9.8 m/s² whatever the world's gravity.
            touchdown: TouchdownSensor { height, g: 9.8 },
        };
        let (l0, l1) = constants.leg_range;
        let leg = Actuator::new(SpringRestLength(body.leg), l0, l1, world);
        let hip = Actuator::new(
            JointTorque(body.hip_motor),
            -constants.hip_torque,
            constants.hip_torque,
            world,
        );
        let ankle = Actuator::new(
            JointTorque(body.ankle_motor),
            -constants.ankle_torque,
            constants.ankle_torque,
            world,
        );
        Ok(Roobot {
            name: name.to_string(),
            body,
            sensors,
            leg,
            hip,
            ankle,
            fsm: HopFsm::new(params),
            landings: 0,
        })
    }

    /// True while the foot touches the floor.
    pub fn foot_down(&self, world: &World) -> bool {
        self.sensors.height.level(world) <= 0.0
    }

    /// The hip motor acts only in flight and the ankle motor only in stance
    /// (thesis §3.2.1.2): the one without ground to push against is idle,
    /// whatever level the controller left it at. `down`: the foot is on the
    /// floor.
    pub fn gate_motors(&self, world: &mut World, down: bool) {
        let motors = &mut world.forces_mut().torque_joints;
        if down {
            motors.set_torque(self.body.hip_motor, 0.0);
            motors.set_torque(self.body.ankle_motor, self.ankle.value());
        } else {
            motors.set_torque(self.body.hip_motor, self.hip.value());
            motors.set_torque(self.body.ankle_motor, 0.0);
        }
    }

    /// Landings (flight → stance transitions) so far.
    pub fn landings(&self) -> u32 {
        self.landings
    }

    /// True once the hip, or any other part but the foot, touches the floor:
    /// it has fallen. (Appendix B tests the hip alone; in this body the tail
    /// and head can prop the hip up, and a roobot lying on its tail must not
    /// count as upright. See docs/ROOBOT.md.)
    pub fn fallen(&self, world: &World) -> bool {
        let b = &self.body;
        let r = &world.particles().radius;
        [b.hip, b.head, b.tail1, b.tail2]
            .iter()
            .any(|p| world.position(*p).y - r[p.index()] <= 1e-9)
    }
}

impl Actor for Roobot {
    fn act(&mut self, world: &mut World, dt: f64) {
        let senses = self.sensors.read(world);
        let inputs = [
            senses.height,
            senses.angle,
            senses.speed,
            senses.touchdown,
            senses.hip_velocity,
            self.leg.level(),
            self.hip.level(),
            self.ankle.level(),
            self.leg.initial_level(),
            self.hip.initial_level(),
            self.ankle.initial_level(),
        ];
        let mut out = [0.0; 3];
        Brain::think(&mut self.fsm, world.time(), dt, &inputs, &mut out);
        // NaN: the FSM keeps that actuator as it is.
        if !out[0].is_nan() {
            self.leg.set_level(world, out[0]);
        }
        for (a, level) in [&mut self.hip, &mut self.ankle].into_iter().zip(&out[1..]) {
            if !level.is_nan() {
                a.set_level(world, *level);
            }
        }
        if self.fsm.last_transition() == Some((HopState::Flight, HopState::Stance)) {
            self.landings += 1;
        }
        self.gate_motors(world, senses.height <= 0.0);
    }

    fn status(&self) -> Option<Status> {
        Some(Status {
            name: self.name.clone(),
            state: self.fsm.state().name(),
            energy: None,
            phase: None,
        })
    }
}
