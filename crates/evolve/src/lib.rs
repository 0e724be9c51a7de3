//! # animats-evolve
//!
//! Evolving controllers (thesis §3.2.1.5–6, §5.4): the thesis's hill climber
//! over any genome (the roobot's hopping parameters, a scene's controller),
//! many independent lanes run in
//! parallel, reproducible from a seed whatever the thread count, with
//! atomic checkpoints to stop and resume.
//!
//! - [`optimiser::Optimiser`]: ask/tell over whole populations;
//!   [`hill_climber::HillClimber`] is Appendix B's selection-and-mutation
//!   scheme, [`ga::Ga`] a generational GA, [`cma_es::CmaEs`] Hansen's CMA-ES.
//! - [`problem::Problem`]: genome → fitness; the roobot's gait
//!   ([`problem::RoobotProblem`]) and a scene's controller
//!   (`animats_scene::evaluate::SceneProblem`).
//! - [`run::State`]: a run's lanes and log; `advance` moves it on.
//! - [`checkpoint`]: save and load a run.

#![warn(missing_docs)]

pub mod checkpoint;
pub mod cma_es;
pub mod ga;
pub mod hill_climber;
pub mod optimiser;
pub mod problem;
pub mod run;

pub use optimiser::{AnyOptimiser, Optimiser, OptimiserKind, Setup};
pub use problem::{Outcome, Problem};
pub use run::{next_batch, Best, Config, Lane, LogRow, ProblemSpec, State, FIRST_BATCH};
