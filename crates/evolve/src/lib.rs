//! # animats-evolve
//!
//! Evolving controllers (thesis §3.2.1.5–6, §5.4): the thesis's hill climber
//! over the roobot's hopping parameters, many independent lanes run in
//! parallel, reproducible from a seed whatever the thread count, with
//! atomic checkpoints to stop and resume.
//!
//! - [`optimiser::Optimiser`]: ask/tell interface; [`hill_climber::HillClimber`]
//!   is Appendix B's selection-and-mutation scheme.
//! - [`run::State`]: a run's lanes and log; `advance` moves it on.
//! - [`checkpoint`]: save and load a run.
//! - [`random::Random`]: one random stream per (seed, lane, generation).

#![warn(missing_docs)]

pub mod checkpoint;
pub mod hill_climber;
pub mod optimiser;
pub mod run;

pub use run::{Config, Lane, LogRow, State};
