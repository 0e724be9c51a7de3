//! The brain of a creature (thesis §2.3.2.4): sensor levels in, actuator
//! levels out, once per step. Every controller kind implements [`Brain`]:
//! the scene file's oscillator, neural network and FSM (`brains/`), and the
//! thesis's own roobot and jellyfish FSMs.
//!
//! A brain that can be evolved exposes its parameters as a *genome*: a flat
//! vector of numbers with bounds, in an order its file documents.
//!
//! Conventions for the creatures' own brains, whose inputs and outputs
//! each file lists: an input may be a raw reading where the thesis reads
//! one (the roobot's hip velocity), or an actuator's level now or at the
//! start (so that "return to rest" is a level too); an output of NaN means
//! "leave that actuator as it is". The scene's controllers always write
//! every output.

use animats_engine::ModelError;

/// Sensor levels in, actuator levels out.
pub trait Brain: Send {
    /// The kind's name (`oscillator`, `neural`, `fsm`...).
    fn kind(&self) -> &'static str;

    /// Decides the step starting at time `t` (s) of length `dt`: reads
    /// `inputs` (levels in [0, 1], in the order the brain was wired) and
    /// writes `outputs` (levels; the caller clamps them to [0, 1]).
    fn think(&mut self, t: f64, dt: f64, inputs: &[f64], outputs: &mut [f64]);

    /// The current state's name, for brains that have states.
    fn state(&self) -> Option<&str> {
        None
    }

    /// Its own state as it runs (an FSM's current state, a recurrent
    /// network's activations), for a scene's snapshot; `None` for a brain
    /// whose outputs follow from its inputs and the time alone.
    fn save_state(&self) -> Option<crate::kept::Kept> {
        None
    }

    /// Takes back a [`Brain::save_state`] of this brain (or of one built
    /// the same way); the error says why not.
    fn load_state(&mut self, kept: Option<&crate::kept::Kept>) -> Result<(), String> {
        crate::kept::nothing(kept, &format!("a {} brain", self.kind()))
    }

    /// The brain as itself, for code that reads a built-in kind's
    /// parameters (the GPU's packer reads a neural network's layers); a
    /// user's brain need not say.
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }

    /// The evolvable parameters (empty if none).
    fn genome(&self) -> Vec<f64> {
        Vec::new()
    }

    /// Sets the evolvable parameters; the error says what is wrong.
    fn set_genome(&mut self, genome: &[f64]) -> Result<(), String> {
        if genome.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "a {} brain has no evolvable parameters",
                self.kind()
            ))
        }
    }

    /// Bounds of each gene, `(lo, hi)`, always containing the current value.
    fn bounds(&self) -> Vec<(f64, f64)> {
        Vec::new()
    }

    /// Where the genome is written in the brain's table of a scene file,
    /// in genome order: the keys' lengths add up to the genome's.
    fn genome_keys(&self) -> Vec<GenomeKey> {
        Vec::new()
    }

    /// Returns to the state it started in (time, FSM state).
    fn reset(&mut self) {}
}

/// A key of a brain's table in a scene file that holds genes: a number or
/// an array of numbers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GenomeKey {
    /// The key's path below the brain's table: `frequency`, `weights`,
    /// `state[0].levels`, `state[1].transition[0].above`.
    pub path: String,
    /// `None`: one number; `Some(n)`: an array of `n`.
    pub len: Option<usize>,
}

impl GenomeKey {
    /// A key holding one number.
    pub fn number(path: impl Into<String>) -> GenomeKey {
        GenomeKey {
            path: path.into(),
            len: None,
        }
    }

    /// A key holding an array of `n` numbers.
    pub fn array(path: impl Into<String>, n: usize) -> GenomeKey {
        GenomeKey {
            path: path.into(),
            len: Some(n),
        }
    }

    /// Genes it holds.
    pub fn genes(&self) -> usize {
        self.len.unwrap_or(1)
    }
}

/// Checks a genome's length against the brain's.
pub fn check_genome(kind: &str, expected: usize, genome: &[f64]) -> Result<(), String> {
    if genome.len() != expected {
        return Err(format!(
            "a genome for this {kind} controller has {expected} numbers, got {}",
            genome.len()
        ));
    }
    if let Some(i) = genome.iter().position(|x| !x.is_finite()) {
        return Err(format!("gene {i} is not finite: {}", genome[i]));
    }
    Ok(())
}

/// `(lo, hi)` widened to contain `x`.
pub fn around(x: f64, lo: f64, hi: f64) -> (f64, f64) {
    (lo.min(x), hi.max(x))
}

/// `x` if finite, else an error naming `field`.
pub fn finite(field: &str, x: f64) -> Result<f64, ModelError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(ModelError::new(
            field,
            format!("must be a finite number, got {x}"),
        ))
    }
}

/// `x` if finite and > 0, else an error naming `field`.
pub fn positive(field: &str, x: f64) -> Result<f64, ModelError> {
    if finite(field, x)? > 0.0 {
        Ok(x)
    } else {
        Err(ModelError::new(field, format!("must be > 0, got {x}")))
    }
}

/// One finite number per output (`n`), or `default` for each if not given.
pub fn per_output(
    field: &str,
    v: &Option<Vec<f64>>,
    n: usize,
    default: f64,
) -> Result<Vec<f64>, ModelError> {
    match v {
        None => Ok(vec![default; n]),
        Some(v) if v.len() != n => Err(ModelError::new(
            field,
            format!("needs one number per output ({n}), got {}", v.len()),
        )),
        Some(v) => {
            for x in v {
                finite(field, *x)?;
            }
            Ok(v.clone())
        }
    }
}

/// A network's inputs into `x`: each sensor level mapped from [0, 1] onto
/// [−1, 1] (`2x − 1`, so 0.5 is no signal), then, with a clock of
/// frequency `clock` Hz, `sin 2πft` and `cos 2πft` (libm: the same bits on
/// every platform).
pub fn network_inputs(x: &mut Vec<f64>, inputs: &[f64], clock: Option<f64>, t: f64) {
    x.clear();
    x.extend(inputs.iter().map(|v| 2.0 * v - 1.0));
    if let Some(f) = clock {
        let w = std::f64::consts::TAU * f * t;
        x.push(animats_engine::math::sin(w));
        x.push(animats_engine::math::cos(w));
    }
}
