//! The 14 parameters of the hopping FSM (thesis Table 4, Appendix B).

/// Number of parameters.
pub const PARAM_COUNT: usize = 14;

/// What each parameter means (thesis Table 4), in order.
pub const PARAM_NAMES: [&str; PARAM_COUNT] = [
    "target leg extension in stance",
    "target leg angle in stance",
    "target hip forward speed in stance",
    "leg retraction rate f((leg extension - target leg extension) / (target leg angle - leg angle)) in stance",
    "ankle torque f(leg angle - target leg angle) in stance",
    "ankle torque f(hip forward speed - target hip forward speed) in stance",
    "target leg extension in leap",
    "leg extension rate in leap",
    "leg retraction rate in launch",
    "minimum launch height",
    "target leg extension in flight",
    "leg retraction rate in flight",
    "target leg angle in touchdown f(hip forward speed)",
    "hip torque f((target leg angle - leg angle) / (time till touchdown))",
];

/// Bounds on each parameter for optimisers that want a box (the GA and
/// CMA-ES; the thesis's hill climber mutates relatively and ignores them).
/// Ours, not the thesis's: levels and targets in [0, 1], the launch height
/// up to 0.2 m, rates and gains up to about twice the largest value Table 6
/// or our own runs reached.
pub const BOUNDS: [(f64, f64); PARAM_COUNT] = [
    (0.0, 1.0),  // 0 target leg extension in stance
    (0.0, 1.0),  // 1 target leg angle in stance
    (0.0, 1.0),  // 2 target hip forward speed in stance
    (0.0, 2.0),  // 3 leg retraction rate in stance
    (0.0, 10.0), // 4 ankle torque f(angle)
    (0.0, 10.0), // 5 ankle torque f(speed)
    (0.0, 1.0),  // 6 target leg extension in leap
    (0.0, 20.0), // 7 leg extension rate in leap
    (0.0, 20.0), // 8 leg retraction rate in launch
    (0.0, 0.2),  // 9 minimum launch height
    (0.0, 1.0),  // 10 target leg extension in flight
    (0.0, 2.0),  // 11 leg retraction rate in flight
    (0.0, 1.0),  // 12 target leg angle in touchdown
    (0.0, 10.0), // 13 hip torque
];

/// A parameter set of the hopping FSM.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HopParams(pub [f64; PARAM_COUNT]);

impl HopParams {
    /// Appendix B's starting vector (`HopEvolver`), Table 6's generation 1.
    pub const INITIAL: HopParams = HopParams([
        0.2, 0.55, 0.01, 0.5, 5.0, 5.0, 1.0, 3.0, 2.0, 0.02, 0.3, 0.5, 0.01, 4.0,
    ]);

    /// True when every parameter is a finite number.
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|p| p.is_finite())
    }
}

impl Default for HopParams {
    fn default() -> Self {
        HopParams::INITIAL
    }
}
