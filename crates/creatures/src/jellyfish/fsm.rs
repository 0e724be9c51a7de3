//! The jellyfish's action selection (thesis §3.2.2.4, Appendix B
//! `BehaviourRoutine`): an energy-driven FSM with three behaviours.
//!
//! - **idle**: energy rises 0.4/s; actuators rest. If the jellyfish is at or
//!   above 1 m (its depth sense saturates) or has under 0.2 energy, it stays
//!   idle. Otherwise it tracks if its energy is above 0.9 (or above 0.5 and it
//!   was tracking), else hovers, remembering the depth to hold.
//! - **track**: energy falls 0.1/s. One pulse (phase 0 → 2π over the pulse
//!   period): pulse level `0.5 + ½ sin φ` (a tenth as strong on the recovery
//!   stroke); the dome mass that smells the food least is pushed along the
//!   dome's normal in step with the pulse, the others wobble, so the dome tips
//!   towards the food. Then back to idle.
//! - **hover**: energy unchanged. Pulses (as in track, without the food push)
//!   only while below the remembered depth; back to idle at the end of a pulse
//!   or on reaching that depth.
//!
//! **Table 5 and the code disagree** on when a rested jellyfish starts
//! tracking: Table 5 lists energy (0.7, 1.0] as "go to hover" and [0.5, 0.7]
//! as "return to track", while the code starts tracking above 0.9 and keeps
//! tracking above 0.5. We follow the code (0.9), whose comment also reads
//! (0.7, 1.0] as hover: so a jellyfish tracks from full energy down to 0.5,
//! hovers to regain energy, and tracks again after passing 0.9.
//!
//! **A slip fixed**: Appendix B's steering loop starts at dome mass 1, so
//! mass 0 never steers and a jellyfish whose far side is mass 0 cannot turn;
//! we steer every mass. When all three food senses are equal (saturated
//! within 10 cm of the food) nobody is pushed.
//!
//! **A balance reflex (ours).** Appendix B's body cannot right itself: a
//! ring of three masses with a chain hanging from each is neutrally stable in
//! orientation (equal loads at points symmetric about the centre make no
//! torque), and its own steering tips it over. Simulated as written, the
//! jellyfish spends half its time upside down and swims away from food as
//! often as towards it. Real jellyfish right themselves with statocysts, so
//! ours has one: during every pulse each dome mass's steering is lowered by
//! `balance × lean × pulse` (lean: how far the mass sits above the dome's
//! centre, in dome radii), pushing the low side up. The food push then sets
//! a steady lean towards the food instead of a roll. We also scale
//! Appendix B's random wobble on the other masses down to 0.3 of its
//! amplitude: at full amplitude it alone can overturn the dome. See
//! docs/SEAWORLD.md for the measurements.

use animats_engine::math;
use std::f64::consts::TAU;
use std::fmt;

/// The three behaviours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Behaviour {
    /// Resting and deciding.
    #[default]
    Idle,
    /// Swimming towards the food.
    Track,
    /// Holding depth.
    Hover,
}

impl Behaviour {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Behaviour::Idle => "idle",
            Behaviour::Track => "track",
            Behaviour::Hover => "hover",
        }
    }
}

impl fmt::Display for Behaviour {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What the FSM senses each step.
#[derive(Clone, Debug, PartialEq)]
pub struct Senses {
    /// Food level at each dome mass.
    pub food: Vec<f64>,
    /// Depth level (height of dome mass 0, m, clamped to [0, 1]).
    pub depth: f64,
    /// Simulated time, s (the thesis's wobble uses it).
    pub time: f64,
    /// How far each dome mass sits above the dome's centre, in dome radii
    /// (the sine of the dome's tilt towards that mass): the balance sense.
    pub lean: Vec<f64>,
}

/// The FSM's orders for this step: `None` means "rest" (reset to the
/// initial level, which is no force).
#[derive(Clone, Debug, PartialEq)]
pub struct Orders {
    /// Pulse actuator level.
    pub pulse: Option<f64>,
    /// Steering actuator levels, one per dome mass.
    pub steer: Option<Vec<f64>>,
}

/// The jellyfish's controller state.
#[derive(Clone, Debug, PartialEq)]
pub struct JellyfishFsm {
    behaviour: Behaviour,
    previous: Behaviour,
    energy: f64,
    phase: f64,
    hover_depth: Option<f64>,
    /// Seconds per pulse.
    pub pulse_period: f64,
    /// Balance reflex: each dome mass's steering level is lowered by
    /// `balance × lean × pulse level` (ours; see the module notes).
    pub balance: f64,
    /// Amplitude of Appendix B's wobble on the steering of the masses that are
    /// not furthest from the food, as a fraction of Appendix B's (ours: 0.3).
    pub wobble: f64,
}

impl JellyfishFsm {
    /// A rested jellyfish (energy 1, idle), as Appendix B starts it.
    pub fn new(pulse_period: f64) -> Self {
        JellyfishFsm {
            behaviour: Behaviour::Idle,
            previous: Behaviour::Idle,
            energy: 1.0,
            phase: 0.0,
            hover_depth: None,
            pulse_period,
            balance: 4.0,
            wobble: 0.3,
        }
    }

    /// The current behaviour.
    pub fn behaviour(&self) -> Behaviour {
        self.behaviour
    }

    /// The behaviour it last chose on leaving idle (track or hover; idle
    /// at the start): a tired jellyfish keeps tracking after a pulse.
    pub fn previous(&self) -> Behaviour {
        self.previous
    }

    /// Internal energy, in [0, 1].
    pub fn energy(&self) -> f64 {
        self.energy
    }

    /// Pulse phase, rad in [0, 2π) (drives the dome's drawing).
    pub fn phase(&self) -> f64 {
        self.phase
    }

    /// The depth being held while hovering.
    pub fn hover_depth(&self) -> Option<f64> {
        self.hover_depth
    }

    /// The pulse level at the current phase: `0.5 + ½ sin φ`, with the
    /// recovery half (sin φ < 0) at a tenth of the strength.
    fn pulse_level(&self) -> f64 {
        let p = 0.5 * math::sin(self.phase);
        0.5 + if p < 0.0 { 0.1 * p } else { p }
    }

    /// Advances the phase; true when the pulse is over (phase wraps to 0).
    fn advance_phase(&mut self, dt: f64) -> bool {
        self.phase += TAU * dt / self.pulse_period;
        if self.phase >= TAU {
            self.phase = 0.0;
            true
        } else {
            false
        }
    }

    /// Steering levels that only keep the dome level (the balance reflex).
    fn balanced(&self, s: &Senses, pulse: f64) -> Vec<f64> {
        s.lean
            .iter()
            .map(|l| 0.5 - self.balance * l * pulse.abs())
            .collect()
    }

    /// One step of `BehaviourRoutine`.
    pub fn step(&mut self, s: &Senses, dt: f64) -> Orders {
        let rest = Orders {
            pulse: None,
            steer: None,
        };
        match self.behaviour {
            Behaviour::Idle => {
                self.energy = (self.energy + 0.4 * dt).clamp(0.0, 1.0);
                if s.depth >= 1.0 || self.energy < 0.2 {
                    return rest; // too high or too tired: keep idling
                }
                if self.energy > 0.9 || (self.energy > 0.5 && self.previous == Behaviour::Track) {
                    self.previous = Behaviour::Track;
                    self.behaviour = Behaviour::Track;
                    self.hover_depth = None;
                } else {
                    self.hover_depth.get_or_insert(s.depth);
                    self.previous = Behaviour::Hover;
                    self.behaviour = Behaviour::Hover;
                }
                rest
            }
            Behaviour::Track => {
                self.energy = (self.energy - 0.1 * dt).clamp(0.0, 1.0);
                if self.advance_phase(dt) {
                    self.behaviour = Behaviour::Idle;
                    return rest;
                }
                let pulse = self.pulse_level();
                let least = (0..s.food.len()).min_by(|&a, &b| s.food[a].total_cmp(&s.food[b]));
                let gradient = s.food.iter().any(|f| *f != s.food[0]);
                let mut steer = self.balanced(s, pulse);
                for (i, level) in steer.iter_mut().enumerate() {
                    *level += if gradient && Some(i) == least {
                        // Appendix B: the far side pushes in step with the pulse.
                        pulse.abs() - 0.5
                    } else {
                        let wobble = 0.5 * math::sin(i as f64 * 5.0 * s.time + s.depth);
                        self.wobble * wobble * pulse.abs()
                    };
                }
                Orders {
                    pulse: Some(pulse),
                    steer: Some(steer),
                }
            }
            Behaviour::Hover => {
                let reached = self.hover_depth.is_some_and(|d| s.depth >= d);
                if self.advance_phase(dt) || reached {
                    self.phase = 0.0;
                    self.behaviour = Behaviour::Idle;
                    return rest;
                }
                let pulse = self.pulse_level();
                Orders {
                    pulse: Some(pulse),
                    steer: Some(self.balanced(s, pulse)),
                }
            }
        }
    }
}

/// The FSM as a [`crate::brain::Brain`], for `n` dome masses: inputs are
/// the food level at each dome mass (n), the depth level, the lean of each
/// dome mass (n, in dome radii), then the pulse's and each steering
/// actuator's initial level (1 + n); outputs the pulse level and each
/// steering level (1 + n), "rest" being the initial level.
/// What a [`JellyfishFsm`] keeps in a snapshot: its behaviour now and
/// before, its energy, its pulse's phase and the depth it holds.
#[derive(Clone, Copy)]
struct JellyfishKept {
    behaviour: Behaviour,
    previous: Behaviour,
    energy: f64,
    phase: f64,
    hover_depth: Option<f64>,
}

impl crate::brain::Brain for JellyfishFsm {
    fn kind(&self) -> &'static str {
        "jellyfish-fsm"
    }

    fn save_state(&self) -> Option<crate::kept::Kept> {
        Some(crate::kept::Kept::new(JellyfishKept {
            behaviour: self.behaviour,
            previous: self.previous,
            energy: self.energy,
            phase: self.phase,
            hover_depth: self.hover_depth,
        }))
    }

    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        let k: &JellyfishKept = crate::kept::required(kept, "a jellyfish's brain")?;
        self.behaviour = k.behaviour;
        self.previous = k.previous;
        self.energy = k.energy;
        self.phase = k.phase;
        self.hover_depth = k.hover_depth;
        Ok(())
    }

    fn think(&mut self, t: f64, dt: f64, inputs: &[f64], outputs: &mut [f64]) {
        let n = (inputs.len() - 2) / 3;
        let senses = Senses {
            food: inputs[..n].to_vec(),
            depth: inputs[n],
            time: t,
            lean: inputs[n + 1..2 * n + 1].to_vec(),
        };
        let rest = &inputs[2 * n + 1..];
        let orders = self.step(&senses, dt);
        outputs[0] = orders.pulse.unwrap_or(rest[0]);
        for i in 0..n {
            outputs[1 + i] = match &orders.steer {
                Some(levels) => levels[i],
                None => rest[1 + i],
            };
        }
    }

    fn state(&self) -> Option<&str> {
        Some(self.behaviour.name())
    }
}
