//! The engine's two kinds of failure: a model that is built wrong, and a
//! simulation that blows up.

use crate::particle::ParticleId;
use std::fmt;

/// A number as a message shows it: as Rust writes it for ordinary
/// magnitudes, in scientific notation (`1e300`, `2.5e-12`) from 10⁹ and
/// below 10⁻⁶, where the plain form runs to hundreds of digits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shown(pub f64);

impl fmt::Display for Shown {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if a.is_finite() && a != 0.0 && !(1e-6..1e9).contains(&a) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// A particle, force or event was described with an impossible value.
///
/// `field` names the offending field (`"mass"`, `"rest_length"`...), so a
/// caller that knows which file and table entry it came from can say exactly
/// where the mistake is.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelError {
    /// The field at fault.
    pub field: String,
    /// What is wrong with it.
    pub reason: String,
}

impl ModelError {
    /// A new error about `field`.
    pub fn new(field: impl Into<String>, reason: impl Into<String>) -> Self {
        ModelError {
            field: field.into(),
            reason: reason.into(),
        }
    }
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.reason)
    }
}

impl std::error::Error for ModelError {}

/// A step could not be completed.
#[derive(Clone, Debug, PartialEq)]
pub enum SimError {
    /// A particle's position or velocity stopped being a finite number: the
    /// system blew up (usually a step too large for the stiffest spring). The
    /// world is left at its last finite state, at time `time` minus the piece
    /// of step that failed.
    NonFinite {
        /// The first particle found with a non-finite position or velocity.
        particle: ParticleId,
        /// The simulated time at the end of the step that went wrong, s.
        time: f64,
    },
    /// The simulation stayed finite but ran away (see
    /// [`DivergenceGuard`](crate::DivergenceGuard)): a blow-up all the same.
    Diverged {
        /// The particle with the most kinetic energy.
        particle: ParticleId,
        /// The simulated time it was noticed, s.
        time: f64,
        /// What ran away.
        why: String,
    },
    /// The step size was not a positive finite number.
    BadStep(f64),
}

impl SimError {
    /// The particle to blame and the time, for a blow-up.
    pub fn blame(&self) -> Option<(ParticleId, f64)> {
        match self {
            SimError::NonFinite { particle, time } | SimError::Diverged { particle, time, .. } => {
                Some((*particle, *time))
            }
            SimError::BadStep(_) => None,
        }
    }

    /// What went wrong with the particle named `name` (the blame without
    /// the time): the words front ends put after "the simulation went ...".
    pub fn what(&self, name: &str) -> String {
        match self {
            SimError::NonFinite { .. } => {
                format!("particle `{name}` has a non-finite position or velocity")
            }
            SimError::Diverged { why, .. } => format!("particle `{name}` ran away: {why}"),
            SimError::BadStep(dt) => {
                format!("step size must be a positive finite number, got {dt}")
            }
        }
    }
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::NonFinite { particle, time } => write!(
                f,
                "the simulation went non-finite at t = {time} s: particle #{} has a non-finite position or velocity (try a smaller step)",
                particle.index()
            ),
            SimError::Diverged { particle, time, why } => write!(
                f,
                "the simulation diverged at t = {time} s: particle #{} ran away: {why} (try a smaller step)",
                particle.index()
            ),
            SimError::BadStep(dt) => write!(f, "step size must be a positive finite number, got {dt}"),
        }
    }
}

impl std::error::Error for SimError {}

#[cfg(test)]
mod tests {
    use super::Shown;

    #[test]
    fn numbers_in_messages_stay_short() {
        let shown = |x: f64| Shown(x).to_string();
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(-1e300), "-1e300");
        assert_eq!(shown(1e-300), "1e-300");
        assert_eq!(shown(-2.5e-12), "-2.5e-12");
        assert_eq!(shown(86_400.0), "86400");
        assert_eq!(shown(0.01), "0.01");
        assert_eq!(shown(-1.0), "-1");
        assert_eq!(shown(999_999_999.0), "999999999");
        assert_eq!(shown(1e9), "1e9");
        assert_eq!(shown(1e-6), "0.000001");
        assert_eq!(shown(0.0), "0");
        assert_eq!(shown(f64::NAN), "NaN");
        assert_eq!(shown(f64::NEG_INFINITY), "-inf");
    }
}
