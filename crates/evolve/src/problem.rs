//! What evolution optimises: a genome → fitness function. The roobot's
//! hopping gait and a scene's `[evolve]` controller are both problems, and
//! one evaluation loop ([`crate::run`]) serves them.

use crate::optimiser::Bounds;
use animats_creatures::roobot::evaluate::{evaluate, EvalSettings};
use animats_creatures::roobot::{raibert, HopParams, PARAM_COUNT};

/// The outcome of one evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// The fitness (higher is better).
    pub fitness: f64,
    /// Time survived, s.
    pub time: f64,
    /// Distance travelled along the direction that counts, m.
    pub distance: f64,
    /// Why it ended (`timeout`, `touch <particle>`, `blow-up`; the roobot's
    /// `fell`, `leg limit`, `timeout`, `blew up`).
    pub ended: String,
}

/// A genome → fitness function, evaluated from many threads at once.
pub trait Problem: Send + Sync {
    /// The genome's length.
    fn dim(&self) -> usize;
    /// Where evolution starts.
    fn start(&self) -> Vec<f64>;
    /// The genome's bounds, if it has natural ones.
    fn bounds(&self) -> Option<Bounds>;
    /// Whether the thesis's hill climber should mutate relatively, ignoring
    /// the bounds (Appendix B's scheme; the roobot's).
    fn relative_mutation(&self) -> bool {
        false
    }
    /// Evaluates one genome. Deterministic: the same genome gives the same
    /// bits on any thread.
    fn evaluate(&self, genome: &[f64]) -> Result<Outcome, String>;
}

/// The roobot's hopping gait (thesis §3.2.1.5): 14 FSM parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct RoobotProblem {
    /// Where every lane starts.
    pub start: Vec<f64>,
    /// How it is evaluated.
    pub settings: EvalSettings,
}

impl Problem for RoobotProblem {
    fn dim(&self) -> usize {
        PARAM_COUNT
    }
    fn start(&self) -> Vec<f64> {
        self.start.clone()
    }
    fn bounds(&self) -> Option<Bounds> {
        let (lo, hi) = animats_creatures::roobot::params::BOUNDS
            .iter()
            .copied()
            .unzip();
        Some(Bounds { lo, hi })
    }
    fn relative_mutation(&self) -> bool {
        true
    }
    fn evaluate(&self, genome: &[f64]) -> Result<Outcome, String> {
        if genome.len() != PARAM_COUNT {
            return Err(format!(
                "a roobot genome has {PARAM_COUNT} genes, got {}",
                genome.len()
            ));
        }
        let mut params = HopParams::INITIAL;
        params.0.copy_from_slice(genome);
        let e = evaluate(params, &self.settings).map_err(|e| e.to_string())?;
        Ok(Outcome {
            fitness: e.fitness,
            time: e.time_up,
            distance: e.distance,
            ended: e.ending.name().to_string(),
        })
    }
}

/// A scene's `[evolve]` controller (see `animats_scene::evaluate`).
#[derive(Clone, Debug)]
pub struct SceneEvolution(pub animats_scene::evaluate::SceneProblem);

impl Problem for SceneEvolution {
    fn dim(&self) -> usize {
        self.0.start().len()
    }
    fn start(&self) -> Vec<f64> {
        self.0.start().to_vec()
    }
    fn bounds(&self) -> Option<Bounds> {
        let (lo, hi) = self.0.bounds().iter().copied().unzip();
        Some(Bounds { lo, hi })
    }
    fn evaluate(&self, genome: &[f64]) -> Result<Outcome, String> {
        let e = self.0.evaluate(genome)?;
        Ok(Outcome {
            fitness: e.fitness,
            time: e.time,
            distance: e.distance,
            ended: e.ended.to_string(),
        })
    }
}

/// Raibert's three-part controller on the roobot's body, its 8 gains
/// evolved (`animats_creatures::roobot::raibert`): the hand-designed
/// baseline the hopping FSM is compared with.
#[derive(Clone, Debug, PartialEq)]
pub struct RaibertProblem {
    /// How it is evaluated (the FSM's settings).
    pub settings: EvalSettings,
}

impl Problem for RaibertProblem {
    fn dim(&self) -> usize {
        raibert::GAIN_COUNT
    }
    fn start(&self) -> Vec<f64> {
        raibert::START.to_vec()
    }
    fn bounds(&self) -> Option<Bounds> {
        let (lo, hi) = raibert::BOUNDS.iter().copied().unzip();
        Some(Bounds { lo, hi })
    }
    fn evaluate(&self, genome: &[f64]) -> Result<Outcome, String> {
        let gains: [f64; raibert::GAIN_COUNT] = genome.try_into().map_err(|_| {
            format!(
                "Raibert's controller has {} gains, got {}",
                raibert::GAIN_COUNT,
                genome.len()
            )
        })?;
        let e = raibert::evaluate(gains, &self.settings).map_err(|e| e.to_string())?;
        Ok(Outcome {
            fitness: e.fitness,
            time: e.time_up,
            distance: e.distance,
            ended: e.ending.name().to_string(),
        })
    }
}
