//! The hopping gait FSM (thesis §3.2.1.4), exactly as Appendix B's
//! `FSMRobot.HopBehaviour` does it: four states, each with its own feedback
//! law, and transitions when a sensor or actuator level passes a parameter.
//!
//! - **stance** (foot on the ground): while the leg-angle level is below
//!   `p1`, compress the leg towards `p0` at rate
//!   `p3 (leg - p0) / (p1 - angle)` and set the ankle to
//!   `0.5 + p4 (p1 - angle) + p5 (p2 - speed)`; then reset hip and ankle and
//!   go to **leap**.
//! - **leap**: extend the leg towards `p6` at rate `p7`; once there, **launch**.
//! - **launch**: retract the leg towards `p10` at rate `p8` until the foot is
//!   `p9` high; then **flight**.
//! - **flight**: retract the leg towards `p10` at rate `p11`, reset the ankle,
//!   and drive the hip to `0.5 + p13 (target - angle) / (touchdown + 0.05)`
//!   with `target = 0.5 + clamp(-p12 v_hip, 0, 1)`; when the foot height
//!   reaches 0, **stance**.
//!
//! Every level set is clamped to [0, 1]. A transition takes effect on the
//! next step (the step that detects it only changes state), as in the thesis.
//! Appendix B's outer IDLE behaviour always chooses to hop, so it is left out.

use super::params::HopParams;
use std::fmt;

/// The four phases of a hop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum HopState {
    /// Foot on the ground, leg compressing, body tilting over the foot.
    #[default]
    Stance,
    /// Explosive leg extension.
    Leap,
    /// Leg retraction until the foot clears the ground.
    Launch,
    /// In the air: leg retracted, foot swung to the touchdown angle.
    Flight,
}

impl HopState {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            HopState::Stance => "stance",
            HopState::Leap => "leap",
            HopState::Launch => "launch",
            HopState::Flight => "flight",
        }
    }

    /// One-letter code (S, L, A, F) for compact phase strings.
    pub fn letter(self) -> char {
        match self {
            HopState::Stance => 'S',
            HopState::Leap => 'L',
            HopState::Launch => 'A',
            HopState::Flight => 'F',
        }
    }
}

impl fmt::Display for HopState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What the FSM reads each step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Senses {
    /// Foot height level.
    pub height: f64,
    /// Leg angle level.
    pub angle: f64,
    /// Hip forward speed level.
    pub speed: f64,
    /// Time till touchdown level.
    pub touchdown: f64,
    /// Hip forward velocity, m/s (unclamped: Appendix B reads it directly).
    pub hip_velocity: f64,
}

/// What the FSM asks of one actuator this step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Leave it as it is.
    Keep,
    /// Return to its initial level.
    Reset,
    /// Set this level.
    Set(f64),
}

/// The FSM's orders for the leg, hip and ankle actuators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orders {
    /// Leg (spring rest length).
    pub leg: Command,
    /// Hip motor.
    pub hip: Command,
    /// Ankle motor.
    pub ankle: Command,
}

/// The hopping controller's state machine.
#[derive(Clone, Debug, PartialEq)]
pub struct HopFsm {
    /// Its 14 parameters.
    pub params: HopParams,
    state: HopState,
    last_transition: Option<(HopState, HopState)>,
}

fn clamp01(x: f64) -> f64 {
    crate::sensor::unit(x)
}

impl HopFsm {
    /// A machine in stance.
    pub fn new(params: HopParams) -> Self {
        HopFsm {
            params,
            state: HopState::Stance,
            last_transition: None,
        }
    }

    /// The current state.
    pub fn state(&self) -> HopState {
        self.state
    }

    /// The transition made during the last step, if any.
    pub fn last_transition(&self) -> Option<(HopState, HopState)> {
        self.last_transition
    }

    /// Back to stance.
    pub fn reset(&mut self) {
        self.state = HopState::Stance;
        self.last_transition = None;
    }

    fn go(&mut self, to: HopState) {
        self.last_transition = Some((self.state, to));
        self.state = to;
    }

    /// One step of `HopBehaviour`: given the senses and the leg actuator's
    /// level, the orders for the three actuators.
    pub fn step(&mut self, s: &Senses, leg_level: f64, dt: f64) -> Orders {
        let p = &self.params.0;
        let keep = Orders {
            leg: Command::Keep,
            hip: Command::Keep,
            ankle: Command::Keep,
        };
        self.last_transition = None;
        match self.state {
            HopState::Stance => {
                if s.angle < p[1] {
                    let rate = p[3] * (leg_level - p[0]) / (p[1] - s.angle);
                    let leg = p[0].max(leg_level - rate * dt);
                    let ankle = 0.5 + p[4] * (p[1] - s.angle) + p[5] * (p[2] - s.speed);
                    Orders {
                        leg: Command::Set(clamp01(leg)),
                        hip: Command::Reset,
                        ankle: Command::Set(clamp01(ankle)),
                    }
                } else {
                    self.go(HopState::Leap);
                    Orders {
                        hip: Command::Reset,
                        ankle: Command::Reset,
                        ..keep
                    }
                }
            }
            HopState::Leap => {
                if leg_level < p[6] {
                    let leg = p[6].min(leg_level + p[7] * dt);
                    Orders {
                        leg: Command::Set(clamp01(leg)),
                        ..keep
                    }
                } else {
                    self.go(HopState::Launch);
                    keep
                }
            }
            HopState::Launch => {
                if s.height < p[9] {
                    let leg = p[10].max(leg_level - p[8] * dt);
                    Orders {
                        leg: Command::Set(clamp01(leg)),
                        ..keep
                    }
                } else {
                    self.go(HopState::Flight);
                    keep
                }
            }
            HopState::Flight => {
                if s.height > 0.0 {
                    let leg = p[10].max(leg_level - p[11] * dt);
                    let target = 0.5 + clamp01(-p[12] * s.hip_velocity);
                    let hip = 0.5 + p[13] * (target - s.angle) / (s.touchdown + 0.05);
                    Orders {
                        leg: Command::Set(clamp01(leg)),
                        hip: Command::Set(clamp01(hip)),
                        ankle: Command::Reset,
                    }
                } else {
                    self.go(HopState::Stance);
                    keep
                }
            }
        }
    }
}

/// Inputs of the FSM as a [`Brain`]: the four sensor levels, the hip's
/// forward velocity (m/s, unclamped, as Appendix B reads it), then for the
/// leg, the hip and the ankle their levels now and their initial levels.
pub const BRAIN_INPUTS: [&str; 11] = [
    "foot height",
    "leg angle",
    "hip forward speed",
    "time till touchdown",
    "hip forward velocity, m/s",
    "leg level",
    "hip level",
    "ankle level",
    "leg initial level",
    "hip initial level",
    "ankle initial level",
];

/// Outputs of the FSM as a [`Brain`]: the leg, hip and ankle levels (NaN:
/// keep).
pub const BRAIN_OUTPUTS: [&str; 3] = ["leg", "hip", "ankle"];

impl crate::brain::Brain for HopFsm {
    fn kind(&self) -> &'static str {
        "hop"
    }

    /// Its state and last transition.
    fn save_state(&self) -> Option<crate::kept::Kept> {
        Some(crate::kept::Kept::new((self.state, self.last_transition)))
    }

    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        type K = (HopState, Option<(HopState, HopState)>);
        let &(state, last) = crate::kept::required::<K>(kept, "a hop brain")?;
        (self.state, self.last_transition) = (state, last);
        Ok(())
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    /// See [`BRAIN_INPUTS`] and [`BRAIN_OUTPUTS`].
    fn think(&mut self, _t: f64, dt: f64, inputs: &[f64], outputs: &mut [f64]) {
        let senses = Senses {
            height: inputs[0],
            angle: inputs[1],
            speed: inputs[2],
            touchdown: inputs[3],
            hip_velocity: inputs[4],
        };
        let orders = self.step(&senses, inputs[5], dt);
        for (k, c) in [orders.leg, orders.hip, orders.ankle]
            .into_iter()
            .enumerate()
        {
            outputs[k] = match c {
                Command::Keep => f64::NAN,
                Command::Reset => inputs[8 + k],
                Command::Set(level) => level,
            };
        }
    }

    fn state(&self) -> Option<&str> {
        Some(self.state.name())
    }

    fn genome(&self) -> Vec<f64> {
        self.params.0.to_vec()
    }

    fn set_genome(&mut self, genome: &[f64]) -> Result<(), String> {
        crate::brain::check_genome("hop", super::PARAM_COUNT, genome)?;
        self.params.0.copy_from_slice(genome);
        Ok(())
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        self.params
            .0
            .iter()
            .zip(super::params::BOUNDS)
            .map(|(&p, (lo, hi))| crate::brain::around(p, lo, hi))
            .collect()
    }

    /// The roobot's `params`.
    fn genome_keys(&self) -> Vec<crate::brain::GenomeKey> {
        vec![crate::brain::GenomeKey::array("params", super::PARAM_COUNT)]
    }

    fn reset(&mut self) {
        HopFsm::reset(self);
    }
}
