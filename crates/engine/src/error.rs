//! The engine's two kinds of failure: a model that is built wrong, and a
//! simulation that blows up.

use crate::particle::ParticleId;
use std::fmt;

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
    /// The step size was not a positive finite number.
    BadStep(f64),
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::NonFinite { particle, time } => write!(
                f,
                "the simulation went non-finite at t = {time} s: particle #{} has a non-finite position or velocity (try a smaller step)",
                particle.index()
            ),
            SimError::BadStep(dt) => write!(f, "step size must be a positive finite number, got {dt}"),
        }
    }
}

impl std::error::Error for SimError {}
