//! Raibert's three-part controller for hopping (M. H. Raibert, *Legged
//! Robots That Balance*, 1986) on the roobot's body, as a hand-designed
//! baseline for evolution (docs/ROOBOT.md). Its gains are the genome.
//!
//! 1. **Hopping height by stance thrust.** In flight the leg's rest length
//!    is held at the flight level; in stance, once the hip stops falling
//!    (the bottom of the stance), the leg extends by the thrust until the
//!    foot leaves the floor.
//! 2. **Forward speed by foot placement.** In flight the foot is placed
//!    ahead of the hip by `x_f = v T_s / 2 + k_v (v − v_d)` (T_s the last
//!    stance's duration, v the hip's forward speed, v_d the speed wanted):
//!    the hip motor servos the leg to the angle `−asin(x_f / L)` from the
//!    vertical, `τ = −k_p (θ − θ_d) − k_d θ̇`.
//! 3. **Body attitude by a servo in stance.** The roobot's body (head and
//!    tail) hangs on passive joints, and its hip motor swings the foot, which
//!    is planted in stance; the actuator that turns the body in stance is the
//!    ankle (it leans the hip over the foot). It servos the body's pitch
//!    (the head–tail line from the horizontal) to level:
//!    `τ = −k_a φ − d_a φ̇`, signed gains, so an optimiser may choose the sense.
//!
//! Torques become actuator levels as `0.5 + τ / (2 τ_max)`, clamped.
//!
//! A [`Brain`] over the roobot's body: its inputs are the roobot's own
//! senses ([`RaibertSenses`]: raw angles, speeds and the leg's length), its
//! outputs the leg's, hip's and ankle's levels.

use super::body::{Body, BodyConstants};
use crate::actuators::AnyActuator;
use crate::brain::{around, check_genome, Brain, GenomeKey};
use crate::nervous_system::Senses;
use crate::sensors::TiltSensor;
use animats_engine::{DVec3, ParticleId, World};

/// Number of gains.
pub const GAIN_COUNT: usize = 8;

/// What each gain is, in order.
pub const GAIN_NAMES: [&str; GAIN_COUNT] = [
    "thrust: leg level added after the bottom of stance",
    "leg level in flight",
    "k_v: foot placement per m/s of speed error, s",
    "v_d: forward speed wanted, m/s",
    "k_p: hip servo stiffness in flight, N m/rad",
    "k_d: hip servo damping in flight, N m s/rad",
    "k_a: attitude servo stiffness in stance, N m/rad",
    "d_a: attitude servo damping in stance, N m s/rad",
];

/// The hand-set gains: a modest thrust, the leg at mid range, 1 m/s
/// wanted, a firm hip servo, no attitude servo. Chosen from a small grid
/// (`cargo run --release -p animats --example raibert_scan`), where they
/// hop for 20 s and so do their neighbours; they are where the optimisers
/// start.
pub const START: [f64; GAIN_COUNT] = [0.1, 0.5, 0.1, 1.0, 5.0, 0.3, 0.0, 0.0];

/// Bounds of each gain (ours).
pub const BOUNDS: [(f64, f64); GAIN_COUNT] = [
    (0.0, 0.5),
    (0.0, 1.0),
    (0.0, 1.0),
    (0.0, 5.0),
    (0.0, 20.0),
    (0.0, 2.0),
    (-20.0, 20.0),
    (-2.0, 2.0),
];

/// The controller's state between steps.
#[derive(Clone, Debug, PartialEq)]
pub struct Raibert {
    /// The gains (see [`GAIN_NAMES`]).
    pub gains: [f64; GAIN_COUNT],
    /// Hip motor torque at levels 0 and 1, N m.
    pub hip_torque: f64,
    /// Ankle motor torque at levels 0 and 1, N m.
    pub ankle_torque: f64,
    /// Whether the foot was down at the last step.
    pub in_stance: bool,
    /// Whether this stance's thrust has begun (the hip stopped falling).
    pub thrusting: bool,
    /// When this stance began, s.
    pub stance_started: f64,
    /// The last stance's duration, s (at most 1).
    pub last_stance: f64,
    /// The leg's angle at the last step (its rate's reference), rad.
    pub last_angle: Option<f64>,
    /// The body's pitch at the last step, rad.
    pub last_pitch: Option<f64>,
}

/// What Raibert's controller reads, in order ([`RaibertSenses`]).
pub const INPUTS: [&str; 6] = [
    "foot height level",
    "leg angle from the vertical, rad (positive forward)",
    "body pitch (head above tail), rad",
    "hip vertical velocity, m/s",
    "hip forward velocity, m/s",
    "leg length, m",
];

impl Raibert {
    /// A controller with `gains` for a body built with `constants`.
    pub fn new(gains: [f64; GAIN_COUNT], constants: &BodyConstants) -> Raibert {
        Raibert {
            gains,
            hip_torque: constants.hip_torque,
            ankle_torque: constants.ankle_torque,
            in_stance: true,
            thrusting: false,
            stance_started: 0.0,
            // A first guess of the stance's duration, s.
            last_stance: 0.15,
            last_angle: None,
            last_pitch: None,
        }
    }

    /// Whether it is in stance.
    pub fn in_stance(&self) -> bool {
        self.in_stance
    }
}

/// What a [`Raibert`] controller keeps in a snapshot: its stance and its
/// last readings.
#[derive(Clone, Copy)]
struct RaibertKept {
    in_stance: bool,
    thrusting: bool,
    stance_started: f64,
    last_stance: f64,
    last_angle: Option<f64>,
    last_pitch: Option<f64>,
}

impl Brain for Raibert {
    fn kind(&self) -> &'static str {
        "raibert"
    }

    fn save_state(&self) -> Option<crate::kept::Kept> {
        Some(crate::kept::Kept::new(RaibertKept {
            in_stance: self.in_stance,
            thrusting: self.thrusting,
            stance_started: self.stance_started,
            last_stance: self.last_stance,
            last_angle: self.last_angle,
            last_pitch: self.last_pitch,
        }))
    }

    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        let k = *crate::kept::required::<RaibertKept>(kept, "a raibert brain")?;
        self.in_stance = k.in_stance;
        self.thrusting = k.thrusting;
        self.stance_started = k.stance_started;
        self.last_stance = k.last_stance;
        self.last_angle = k.last_angle;
        self.last_pitch = k.last_pitch;
        Ok(())
    }

    /// Inputs [`INPUTS`]; outputs the leg's, hip's and ankle's levels.
    fn think(&mut self, t: f64, dt: f64, inputs: &[f64], out: &mut [f64]) {
        let g = self.gains;
        let down = inputs[0] <= 0.0;
        if down && !self.in_stance {
            self.in_stance = true;
            self.thrusting = false;
            self.stance_started = t;
        } else if !down && self.in_stance {
            self.in_stance = false;
            if t > self.stance_started {
                self.last_stance = (t - self.stance_started).min(1.0);
            }
        }
        let angle = inputs[1];
        let rate = self.last_angle.map_or(0.0, |a| (angle - a) / dt);
        self.last_angle = Some(angle);
        let pitch = inputs[2];
        let pitch_rate = self.last_pitch.map_or(0.0, |p| (pitch - p) / dt);
        self.last_pitch = Some(pitch);
        let level = |tau: f64, max: f64| 0.5 + tau / (2.0 * max);
        if self.in_stance {
            // 1: thrust once the hip stops falling.
            if inputs[3] >= 0.0 {
                self.thrusting = true;
            }
            out[0] = g[1] + if self.thrusting { g[0] } else { 0.0 };
            // 3: attitude by the ankle.
            let tau = -g[6] * pitch - g[7] * pitch_rate;
            out[2] = level(tau, self.ankle_torque);
            out[1] = 0.5;
        } else {
            out[0] = g[1];
            // 2: foot placement by the hip.
            let v = inputs[4];
            let length = inputs[5].max(1e-3);
            let ahead = v * self.last_stance / 2.0 + g[2] * (v - g[3]);
            let target = -animats_engine::math::asin((ahead / length).clamp(-0.9, 0.9));
            let tau = -g[4] * (angle - target) - g[5] * rate;
            out[1] = level(tau, self.hip_torque);
            out[2] = 0.5;
        }
    }

    fn state(&self) -> Option<&str> {
        Some(if self.in_stance { "stance" } else { "flight" })
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }

    fn genome(&self) -> Vec<f64> {
        self.gains.to_vec()
    }

    fn set_genome(&mut self, genome: &[f64]) -> Result<(), String> {
        check_genome("raibert", GAIN_COUNT, genome)?;
        self.gains.copy_from_slice(genome);
        Ok(())
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        self.gains
            .iter()
            .zip(BOUNDS)
            .map(|(&g, (lo, hi))| around(g, lo, hi))
            .collect()
    }

    /// The roobot's `gains`.
    fn genome_keys(&self) -> Vec<GenomeKey> {
        vec![GenomeKey::array("gains", GAIN_COUNT)]
    }
}

/// The roobot's senses as Raibert's controller reads them ([`INPUTS`]).
pub struct RaibertSenses {
    /// Index of the foot height sensor in the nervous system.
    pub foot_height: usize,
    /// The leg's angle from the vertical (its raw angle, not its level).
    pub angle: TiltSensor,
    /// The hip, whose velocity it reads.
    pub hip: ParticleId,
    /// The foot (the leg's length is hip to foot).
    pub foot: ParticleId,
    /// The head (the body's pitch is the tail-to-head line's).
    pub head: ParticleId,
    /// The tail's first mass.
    pub tail: ParticleId,
    /// The direction it faces.
    pub forward: DVec3,
}

impl RaibertSenses {
    /// For `body`, whose leg-angle sensor is `angle` and whose foot height
    /// sensor has index `foot_height` in the nervous system.
    pub fn new(body: &Body, angle: TiltSensor, foot_height: usize) -> RaibertSenses {
        RaibertSenses {
            foot_height,
            angle,
            hip: body.hip,
            foot: body.foot,
            head: body.head,
            tail: body.tail1,
            forward: body.forward,
        }
    }
}

impl Senses for RaibertSenses {
    fn count(&self) -> usize {
        INPUTS.len()
    }

    fn read(&self, world: &World, levels: &[f64], _: &[(String, AnyActuator)], out: &mut [f64]) {
        let v = world.position(self.head) - world.position(self.tail);
        let hip = world.velocity(self.hip);
        out[0] = levels[self.foot_height];
        out[1] = self.angle.angle(world);
        out[2] = animats_engine::math::atan2(v.y, v.dot(self.forward));
        out[3] = hip.y;
        out[4] = hip.dot(self.forward);
        out[5] = (world.position(self.hip) - world.position(self.foot)).length();
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}
