//! What evolution optimises: a genome → evaluation function. Every
//! creature is a scene, so the one problem is a scene's `[evolve]`
//! controller ([`SceneEvolution`]); the trait stays so that a run can be
//! driven by anything that scores genomes the same way (tests count
//! evaluations through it).

use crate::optimiser::body_ga::Variation;
use crate::optimiser::{Bounds, Random};
use crate::screen::Screen;
use animats_scene::def::MutationName;
use animats_scene::evaluate::{EvolveSpec, SceneProblem};
use animats_scene::morphology::{BodyStats, MorphologyProblem};

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
    /// [`Problem::evaluate`], a robust scene's half-step run made only
    /// where `screen` says ([`Screen`]); by default in full.
    fn evaluate_screened(&self, genome: &[f64], screen: &Screen) -> Result<Outcome, String> {
        let _ = screen;
        self.evaluate(genome)
    }
    /// Every genome of a generation evaluated at once, where the problem
    /// runs its evaluations in batches (on a GPU: `animats_scene::evaluate::Batches`),
    /// genome `g` as [`Problem::evaluate_screened`] would with the screen
    /// whose `fine` is `fine(g, …)`; `None` where it evaluates them one by
    /// one.
    fn evaluate_population(
        &self,
        _genomes: &[Vec<f64>],
        _fine: &dyn Fn(usize, &Outcome) -> bool,
    ) -> Option<Result<Vec<Outcome>, String>> {
        None
    }
    /// Whether [`Problem::evaluate_population`] evaluates (a GPU's batches).
    fn in_batches(&self) -> bool {
        false
    }
    /// The scene's `[evolve]` table, resolved (none for a problem that is
    /// not a scene).
    fn spec(&self) -> Option<&EvolveSpec> {
        None
    }
    /// The problem's own variation, for genomes whose shape changes (a
    /// `[morphology]` scene's bodies).
    fn variation(&self) -> Option<&dyn Variation> {
        None
    }
    /// The size of the body a genome encodes, for a problem whose bodies
    /// evolve.
    fn stats(&self, _genome: &[f64]) -> Option<BodyStats> {
        None
    }
    /// A relative guess at how long `genome`'s evaluation takes, where the
    /// problem can tell, so that a generation starts its longest
    /// evaluations first (bodies: each step's work grows with the
    /// particles, the springs and the pairs of spheres that may touch).
    /// `None`: the candidates' own order.
    fn cost(&self, genome: &[f64]) -> Option<f64> {
        self.stats(genome).map(|s| {
            let n = s.particles as f64;
            n + s.springs as f64 + n * (n - 1.0) / 4.0
        })
    }
    /// The scene's `[archive]` grid and settings, if it has one.
    fn grid(&self) -> Option<&animats_scene::archive::Grid> {
        None
    }
    /// The whole scene with `genome` written in, preceded by `comment` as
    /// `#` lines: what `best.toml` holds.
    fn scene_toml(&self, _genome: &[f64], _comment: &str) -> Result<String, String> {
        Err("this problem is not a scene: it has no scene file to write".into())
    }
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
    fn evaluate_screened(&self, genome: &[f64], screen: &Screen) -> Result<Outcome, String> {
        self.0.evaluate_screened(genome, &|o| screen.fine(o))
    }
    fn evaluate_population(
        &self,
        genomes: &[Vec<f64>],
        fine: &dyn Fn(usize, &Outcome) -> bool,
    ) -> Option<Result<Vec<Outcome>, String>> {
        let b = self.0.batches()?;
        Some(self.0.evaluate_all(genomes, fine, &*b.0))
    }
    fn in_batches(&self) -> bool {
        self.0.batches().is_some()
    }
    fn spec(&self) -> Option<&EvolveSpec> {
        Some(self.0.spec())
    }
    fn grid(&self) -> Option<&animats_scene::archive::Grid> {
        self.0.grid()
    }
    fn scene_toml(&self, genome: &[f64], comment: &str) -> Result<String, String> {
        self.0.best_toml(genome, comment)
    }
}

/// A `[morphology]` scene: bodies and their brains evolve together (see
/// `animats_scene::morphology`). Genomes change length as bodies grow and
/// shrink; the body GA varies them with the scene's own operators.
#[derive(Clone, Debug)]
pub struct BodyEvolution(pub MorphologyProblem);

impl Problem for BodyEvolution {
    /// The starting body's genes' length (0 for random starts): bodies
    /// have no fixed length.
    fn dim(&self) -> usize {
        self.0.start().map_or(0, <[f64]>::len)
    }
    fn start(&self) -> Vec<f64> {
        self.0.start().map(<[f64]>::to_vec).unwrap_or_default()
    }
    fn bounds(&self) -> Option<Bounds> {
        None
    }
    fn evaluate(&self, genome: &[f64]) -> Result<Outcome, String> {
        self.0.evaluate(genome)
    }
    fn evaluate_screened(&self, genome: &[f64], screen: &Screen) -> Result<Outcome, String> {
        self.0.evaluate_screened(genome, &|o| screen.fine(o))
    }
    fn evaluate_population(
        &self,
        genomes: &[Vec<f64>],
        fine: &dyn Fn(usize, &Outcome) -> bool,
    ) -> Option<Result<Vec<Outcome>, String>> {
        let b = self.0.batches()?;
        Some(self.0.evaluate_all(genomes, fine, &*b.0))
    }
    fn in_batches(&self) -> bool {
        self.0.batches().is_some()
    }
    fn spec(&self) -> Option<&EvolveSpec> {
        Some(self.0.spec())
    }
    fn variation(&self) -> Option<&dyn Variation> {
        Some(self)
    }
    fn grid(&self) -> Option<&animats_scene::archive::Grid> {
        self.0.grid()
    }
    fn stats(&self, genome: &[f64]) -> Option<BodyStats> {
        self.0.stats(genome)
    }
    fn scene_toml(&self, genome: &[f64], comment: &str) -> Result<String, String> {
        self.0.develop(genome, comment)
    }
}

impl Variation for BodyEvolution {
    fn start(&self) -> Option<Vec<f64>> {
        self.0.start().map(<[f64]>::to_vec)
    }
    fn random(&self, rng: &mut Random) -> Vec<f64> {
        self.0.random(rng)
    }
    fn mutate(&self, parent: &[f64], rng: &mut Random) -> Vec<f64> {
        self.0.mutate(parent, rng)
    }
    fn crossover(&self, a: &[f64], b: &[f64], rng: &mut Random) -> Vec<f64> {
        self.0.crossover(a, b, rng)
    }
    fn check(&self, genome: &[f64]) -> Result<(), &'static str> {
        self.0.check(genome).map_err(|r| r.name())
    }
}
