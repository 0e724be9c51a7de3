//! # animats-evolve
//!
//! Evolving controllers (thesis §3.2.1.5–6, §5.4): the thesis's hill climber
//! and its successors over a scene's `[evolve]` controller (the thesis's
//! roobot is a scene: `scenes/hop_evolver.toml`), many independent lanes
//! run in parallel, reproducible from a seed whatever the thread count,
//! with atomic checkpoints to stop and resume.
//!
//! - [`optimiser::Optimiser`]: ask/tell over whole populations;
//!   [`hill_climber::HillClimber`] is Appendix B's selection-and-mutation
//!   scheme, [`ga::Ga`] a generational GA, [`cma_es::CmaEs`] Hansen's CMA-ES.
//! - [`problem::Problem`]: genome → evaluation; a scene's controller
//!   ([`problem::SceneEvolution`] over `animats_scene::evaluate::SceneProblem`).
//! - [`run::State`]: a run's lanes and log; `advance` moves it on.
//! - [`checkpoint`]: save and load a run.
//! - [`check`]: a winner checked at a quarter of the step, and
//!   `checked.toml`, the best candidate that keeps its fitness there.
//! - [`schedule`]: a run's work, recorded, and replayed on any number of
//!   workers to predict its wall time.

#![warn(missing_docs)]

pub mod archive;
pub mod check;
pub mod checkpoint;
pub mod optimiser;
pub mod problem;
pub mod run;
pub mod schedule;
pub mod screen;

pub use optimiser::{cma_es, ga, hill_climber};

pub use optimiser::{AnyOptimiser, Optimiser, OptimiserKind, Setup};
pub use problem::{Outcome, Problem};
pub use run::{Best, Choices, Config, Lane, LogMode, LogRow, ProblemSpec, State};
