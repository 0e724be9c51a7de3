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
