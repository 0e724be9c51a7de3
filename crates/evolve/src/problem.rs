//! What evolution optimises: a genome → evaluation function. Every
//! creature is a scene, so the one problem is a scene's `[evolve]`
//! controller ([`SceneEvolution`]); the trait stays so that a run can be
//! driven by anything that scores genomes the same way (tests count
//! evaluations through it).

use crate::optimiser::Bounds;
use animats_scene::def::MutationName;
use animats_scene::evaluate::SceneProblem;

/// The outcome of one evaluation: the scene's.
pub use animats_scene::evaluate::{Ended, Evaluation as Outcome};

/// A genome → evaluation function, evaluated from many threads at once.
pub trait Problem: Send + Sync {
    /// The genome's length.
    fn dim(&self) -> usize;
    /// Where evolution starts.
    fn start(&self) -> Vec<f64>;
    /// The genome's bounds, if it has natural ones.
    fn bounds(&self) -> Option<Bounds>;
    /// Whether the thesis's hill climber should mutate relatively, ignoring
    /// the bounds (Appendix B's scheme: `[evolve] mutation = "relative"`).
    fn relative_mutation(&self) -> bool {
        false
    }
    /// Evaluates one genome. Deterministic: the same genome gives the same
    /// bits on any thread.
    fn evaluate(&self, genome: &[f64]) -> Result<Outcome, String>;
}

/// A scene's `[evolve]` controller (see `animats_scene::evaluate`).
#[derive(Clone, Debug)]
pub struct SceneEvolution(pub SceneProblem);

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
    fn relative_mutation(&self) -> bool {
        self.0.spec().mutation == MutationName::Relative
    }
    fn evaluate(&self, genome: &[f64]) -> Result<Outcome, String> {
        self.0.evaluate(genome)
    }
}
