//! `animats`: the command line. A thin layer over the libraries: it parses
//! arguments, loads files, calls the library, and reports.
//!
//! Exit status: 0 success, 2 bad input (arguments, scene or parameter files,
//! unwritable outputs, corrupt checkpoints), 3 the simulation blew up,
//! 130 interrupted by Ctrl-C (after saving), 1 anything else.

/// `println!` for the command's report on stdout, where a reader that has
/// gone away (`animats simulate ... | head`, a test harness that stopped
/// reading) costs the line, not a panic.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod bench;
mod device;
mod evaluate;
mod evolve;
mod hop;
mod output;
mod render;
mod simulate;
mod view;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// mimalloc, not the system's `malloc`: with glibc's, a block freed by
/// another thread than its maker's is reused by the freeing thread among
/// the maker's blocks, and an evolution on two threads spent 5–20 % more
/// processor time than on one, its threads' worlds sharing cache lines
/// (docs/DESIGN.md, "Threads").
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Build creatures from the physics up: simulate scenes of point masses,
/// springs and joints, evolve hopping gaits, and benchmark the engine.
#[derive(Parser)]
#[command(name = "animats", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene file headless; write its trajectory or print a summary.
    Simulate(simulate::Args),
    /// Simulate one hopping roobot with a parameter set and report its fitness.
    Hop(hop::Args),
    /// Evolve hopping gaits (no scene), a scene's [evolve] controllers, or
    /// bodies and brains ([morphology]); CMA-ES unless the scene or
    /// --optimiser says otherwise, lanes in parallel.
    Evolve(evolve::Args),
    /// Run a scene's [evolve] evaluation once and print its fitness.
    Evaluate(evaluate::Args),
    /// Run the standard benchmark workloads beside hand-written baselines.
    Bench(bench::Args),
    /// Run a scene live and watch it in the browser (3D, with controls).
    View(view::Args),
    /// Render a scene headless to a PNG, an animated GIF or an MP4.
    Render(render::Args),
}

/// A failed command, with the exit status it maps to.
pub enum Failure {
    /// Bad input: exit 2.
    Input(String),
    /// The simulation went non-finite: exit 3.
    Blowup(String),
    /// Stopped by Ctrl-C after saving its work: exit 130.
    Interrupted(String),
    /// Anything else: exit 1.
    Other(String),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // On request, the global pool's threads keep to their own processors
    // (`animats_engine::pin`). Not by default: where this loop steps a
    // world from outside the pool, a pinned pool measured slower on a
    // cloth on the floor: 2.64–3.09 s against 2.38–2.82 s for 1 s of a
    // 16,384-particle cloth on two threads).
    // Nothing has built the pool yet; if something had, it stays as it is.
    if std::env::var_os("ANIMATS_PIN_THREADS").is_some_and(|v| v == "1") {
        let _ = animats_engine::pin::pin_global_pool();
    }
    let result = match cli.command {
        Command::Simulate(args) => simulate::run(args),
        Command::Hop(args) => hop::run(args),
        Command::Evolve(args) => evolve::run(args),
        Command::Evaluate(args) => evaluate::run(args),
        Command::Bench(args) => bench::run(args),
        Command::View(args) => view::run(args),
        Command::Render(args) => render::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(2)
        }
        Err(Failure::Blowup(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(3)
        }
        Err(Failure::Interrupted(m)) => {
            eprintln!("{m}");
            ExitCode::from(130)
        }
        Err(Failure::Other(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(1)
        }
    }
}

/// Parses a positive, finite number (for steps and durations).
pub fn positive_f64(s: &str) -> Result<f64, String> {
    let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(format!("must be a positive finite number, got {s}"))
    }
}

/// Parses a number >= 0 and finite (for intervals where 0 means "always").
pub fn non_negative_f64(s: &str) -> Result<f64, String> {
    let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(format!("must be a finite number >= 0, got {s}"))
    }
}

/// The longest single evaluation `hop` runs, s (a simulated day).
pub const MAX_EVAL_SECONDS: f64 = 86_400.0;

/// Parses an evaluation's length: positive, at most [`MAX_EVAL_SECONDS`].
pub fn eval_seconds(s: &str) -> Result<f64, String> {
    let x = positive_f64(s)?;
    if x <= MAX_EVAL_SECONDS {
        Ok(x)
    } else {
        Err(format!(
            "must be at most {MAX_EVAL_SECONDS} s (a simulated day), got {s}"
        ))
    }
}

/// Prints a scene's warnings on stderr (the run goes on).
pub fn warn(scene: &std::path::Path, warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {}: {w}", scene.display());
    }
}
