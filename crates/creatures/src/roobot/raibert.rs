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

use super::{Body, Roobot};
use animats_engine::World;

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
    in_stance: bool,
    thrusting: bool,
    stance_started: f64,
    last_stance: f64,
    last_angle: Option<f64>,
    last_pitch: Option<f64>,
}

impl Raibert {
    /// A controller with `gains`.
    pub fn new(gains: [f64; GAIN_COUNT]) -> Raibert {
        Raibert {
            gains,
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

    fn pitch(world: &World, b: &Body) -> f64 {
        let v = world.position(b.head) - world.position(b.tail1);
        libm::atan2(v.y, v.dot(b.forward))
    }

    /// Sets the roobot's actuators for the step of length `dt` about to be
    /// taken; returns true when a flight ended in a landing.
    pub fn act(&mut self, world: &mut World, r: &mut Roobot, dt: f64) -> bool {
        let g = self.gains;
        let b = r.body;
        let t = world.time();
        let down = r.foot_down(world);
        let mut landed = false;
        if down && !self.in_stance {
            self.in_stance = true;
            self.thrusting = false;
            self.stance_started = t;
            landed = true;
        } else if !down && self.in_stance {
            self.in_stance = false;
            if t > self.stance_started {
                self.last_stance = (t - self.stance_started).min(1.0);
            }
        }
        let angle = r.sensors.angle.angle(world);
        let rate = self.last_angle.map_or(0.0, |a| (angle - a) / dt);
        self.last_angle = Some(angle);
        let pitch = Raibert::pitch(world, &b);
        let pitch_rate = self.last_pitch.map_or(0.0, |p| (pitch - p) / dt);
        self.last_pitch = Some(pitch);
        let hip_torque = b.constants.hip_torque;
        let ankle_torque = b.constants.ankle_torque;
        let level = |tau: f64, max: f64| 0.5 + tau / (2.0 * max);
        if self.in_stance {
            // 1: thrust once the hip stops falling.
            if world.velocity(b.hip).y >= 0.0 {
                self.thrusting = true;
            }
            let leg = g[1] + if self.thrusting { g[0] } else { 0.0 };
            r.leg.set_level(world, leg);
            // 3: attitude by the ankle.
            let tau = -g[6] * pitch - g[7] * pitch_rate;
            r.ankle.set_level(world, level(tau, ankle_torque));
            r.hip.set_level(world, 0.5);
        } else {
            r.leg.set_level(world, g[1]);
            // 2: foot placement by the hip.
            let v = world.velocity(b.hip).dot(b.forward);
            let length = b.leg_length(world).max(1e-3);
            let ahead = v * self.last_stance / 2.0 + g[2] * (v - g[3]);
            let target = -libm::asin((ahead / length).clamp(-0.9, 0.9));
            let tau = -g[4] * (angle - target) - g[5] * rate;
            r.hip.set_level(world, level(tau, hip_torque));
            r.ankle.set_level(world, 0.5);
        }
        landed
    }
}

/// One evaluation of the gains, exactly as the hopping FSM's is run
/// ([`super::evaluate::evaluate_with`]: the same world, the same end rule,
/// the same fitness `time upright + 50 × distance`).
pub fn evaluate(
    gains: [f64; GAIN_COUNT],
    settings: &super::evaluate::EvalSettings,
) -> Result<super::evaluate::Evaluation, animats_engine::ModelError> {
    evaluate_with(gains, settings, |_, _| {})
}

/// [`evaluate`], calling `observe` with the world after every step.
pub fn evaluate_with(
    gains: [f64; GAIN_COUNT],
    settings: &super::evaluate::EvalSettings,
    observe: impl FnMut(&World, &Roobot),
) -> Result<super::evaluate::Evaluation, animats_engine::ModelError> {
    let mut controller = Raibert::new(gains);
    super::evaluate::evaluate_driven(
        super::HopParams::INITIAL,
        settings,
        |world, roobot, dt| {
            let landed = controller.act(world, roobot, dt);
            let down = roobot.foot_down(world);
            roobot.gate_motors(world, down);
            landed
        },
        observe,
    )
}
