//! `animats evolve [SCENE]`: the thesis's evolution of hopping gaits (no
//! scene), or of a scene's `[evolve]` controller, in parallel lanes with
//! the hill climber, a GA or CMA-ES; a progress bar (a line every few
//! seconds when stderr is not a terminal), checkpoints, and Ctrl-C to stop
//! cleanly.

use crate::Failure;
use animats_evolve::{checkpoint, Config, OptimiserKind, ProblemSpec, State};
use animats_render::{step_plot_png, Plot, Series};
use animats_scene::evaluate::SceneProblem;
use animats_viewer::exhibition::Showcase;
use animats_viewer::{BestBrain, Exhibition, SceneExhibition};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Arguments of `animats evolve`.
#[derive(clap::Args)]
pub struct Args {
    /// A scene file with an `[evolve]` table; without one, the roobot.
    scene: Option<PathBuf>,
    /// hill-climber (the thesis's), ga or cma-es.
    #[arg(long, value_parser = OptimiserKind::parse)]
    optimiser: Option<OptimiserKind>,
    /// Candidates per generation per lane (default: hill-climber 1, ga 32,
    /// cma-es 4 + 3 ln n).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    population: Option<u64>,
    /// CMA-ES only: start again with twice the population, up to this many
    /// times, when a run converges or stagnates (IPOP).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=20))]
    restarts: Option<u32>,
    /// Generations per lane (a resumed run can be given a new total).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    generations: Option<u64>,
    /// Independent lanes (default 6 for the roobot, 1 for a scene; the hill
    /// climber's lane k mutates by up to ±25 (k + 1) %).
    #[arg(long)]
    lanes: Option<usize>,
    /// Seed of every random choice.
    #[arg(long)]
    seed: Option<u64>,
    /// Directory to write log.csv, best.toml, fitness.png and the checkpoint.
    #[arg(long, default_value = "evolution")]
    out: PathBuf,
    /// Continue the run in this directory from its checkpoint.
    #[arg(long, conflicts_with = "out")]
    resume: Option<PathBuf>,
    /// Worker threads (default: every core).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    threads: Option<u64>,
    /// Seconds between checkpoints (0: after every batch of generations).
    #[arg(long, default_value_t = 5.0, value_parser = crate::non_negative_f64)]
    checkpoint_every: f64,
    /// Watch it live in the browser: the roobot's lanes' current bests
    /// hopping side by side, or the scene driven by its best brain so far
    /// (restarted with the newest best when each run ends). The view stays
    /// open after the run until Ctrl-C.
    #[arg(long)]
    view: bool,
    #[command(flatten)]
    serving: crate::view::Serving,
}

const CHECKPOINT: &str = "checkpoint.json";
/// Seconds between progress lines when stderr is not a terminal.
const PROGRESS_EVERY: f64 = 5.0;

fn input(m: impl Into<String>) -> Failure {
    Failure::Input(m.into())
}

/// Makes sure `dir` exists and can be written, before any work is done.
fn writable(dir: &Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        input(format!(
            "{}: cannot create the output directory: {e}",
            dir.display()
        ))
    })?;
    let probe = dir.join(format!(".write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| {
        input(format!(
            "{}: cannot write in the output directory: {e}",
            dir.display()
        ))
    })?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// Writes log.csv, best.toml, fitness.png and the checkpoint.
fn save(dir: &Path, state: &State, with_plot: bool) -> Result<(), Failure> {
    let io = Failure::Other;
    animats_files::write_atomically(&dir.join("log.csv"), state.log_csv().as_bytes())
        .map_err(io)?;
    if let Some(best) = state.best_toml().map_err(Failure::Other)? {
        animats_files::write_atomically(&dir.join("best.toml"), best.as_bytes()).map_err(io)?;
    }
    if with_plot {
        let y_label = if state.config.problem.is_roobot() {
            "best fitness (time upright + 50 × distance)"
        } else {
            "best fitness"
        };
        let plot = Plot {
            title: format!(
                "Best fitness per lane ({}, seed {})",
                state.config.optimiser.name(),
                state.config.seed
            ),
            x_label: "generation".into(),
            y_label: y_label.into(),
            series: state
                .fitness_curves()
                .into_iter()
                .enumerate()
                .map(|(k, c)| Series {
                    label: format!("lane {k}"),
                    points: c.into_iter().map(|(g, f)| (g as f64, f)).collect(),
                })
                .collect(),
            size: (900, 600),
        };
        let png = step_plot_png(&plot).map_err(io)?;
        animats_files::write_atomically(&dir.join("fitness.png"), &png).map_err(io)?;
    }
    checkpoint::save(&dir.join(CHECKPOINT), state).map_err(io)
}

/// What the live view shows: the roobot's lanes side by side, or a scene
/// driven by its best brain.
enum Watched {
    Roobot(Showcase),
    Scene(BestBrain),
}

/// Shows the bests so far to the viewer.
fn publish(watched: &Watched, state: &State) {
    match watched {
        Watched::Roobot(showcase) => {
            for l in &state.lanes {
                if let Some(b) = &l.best {
                    let mut params = animats_creatures::roobot::HopParams::INITIAL;
                    params.0.copy_from_slice(&b.genome);
                    showcase.set_best(l.lane, params, b.fitness);
                }
            }
            showcase.set_generation(state.generation(), state.config.generations);
        }
        Watched::Scene(board) => {
            if let Some(l) = state.best_lane() {
                if let Some(b) = &l.best {
                    board.set_best(&b.genome, b.fitness, l.lane);
                }
            }
            board.set_generation(state.generation(), state.config.generations);
        }
    }
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let (dir, mut state) = match &args.resume {
        Some(dir) => {
            let state = checkpoint::load(&dir.join(CHECKPOINT)).map_err(input)?;
            if args.lanes.is_some_and(|l| l != state.config.lanes)
                || args.seed.is_some_and(|s| s != state.config.seed)
                || args.optimiser.is_some_and(|o| o != state.config.optimiser)
                || args
                    .population
                    .is_some_and(|p| Some(p as usize) != state.config.population)
                || args.scene.is_some()
            {
                return Err(input(format!(
                    "{}: a resumed run keeps its scene, optimiser ({}), population, lanes ({}) and seed ({}); give only --resume and --generations",
                    dir.display(),
                    state.config.optimiser.name(),
                    state.config.lanes,
                    state.config.seed
                )));
            }
            let mut state = state;
            if let Some(g) = args.generations {
                if g < state.generation() {
                    return Err(input(format!(
                        "--generations {g} is fewer than the {} already done",
                        state.generation()
                    )));
                }
                state.config.generations = g;
            }
            writable(dir)?;
            (dir.clone(), state)
        }
        None => {
            let dir = args.out.clone();
            if dir.join(CHECKPOINT).exists() {
                return Err(input(format!(
                    "{}: already holds an evolution run; continue it with --resume {} or choose another --out",
                    dir.display(),
                    dir.display()
                )));
            }
            let mut config = Config::thesis(
                args.lanes
                    .unwrap_or(if args.scene.is_some() { 1 } else { 6 }),
                args.generations.unwrap_or(100),
                args.seed.unwrap_or(1),
            );
            if let Some(path) = &args.scene {
                // Read once; refused here, before any output exists, if it
                // does not parse (State::new builds it).
                config.problem = ProblemSpec::Scene {
                    file: path.display().to_string(),
                    text: animats_scene::read(path).map_err(|e| input(e.to_string()))?,
                };
            }
            if let Some(o) = args.optimiser {
                config.optimiser = o;
            }
            config.population = args.population.map(|p| p as usize);
            if let Some(r) = args.restarts {
                if config.optimiser != OptimiserKind::CmaEs {
                    return Err(input(format!(
                        "--restarts is for --optimiser cma-es, not {}",
                        config.optimiser.name()
                    )));
                }
                config.restarts = r;
            }
            let state = State::new(config).map_err(input)?;
            writable(&dir)?;
            (dir, state)
        }
    };

    let threads = args.threads.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |t| t as usize,
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Failure::Other(e.to_string()))?;
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // If a handler cannot be installed, Ctrl-C simply kills the run; the
        // last checkpoint still stands.
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let viewing = if args.view {
        let (watched, stage): (Watched, Box<dyn animats_viewer::Stage>) =
            match &state.config.problem {
                ProblemSpec::Roobot { .. } => {
                    let showcase = Showcase::new(state.config.lanes);
                    let exhibition = Exhibition::new(showcase.clone(), state.config.settings())
                        .map_err(Failure::Other)?;
                    (Watched::Roobot(showcase), Box::new(exhibition))
                }
                ProblemSpec::Scene { file, text } => {
                    let problem =
                        SceneProblem::parse(text, file).map_err(|e| input(e.to_string()))?;
                    let board = BestBrain::default();
                    let exhibition =
                        SceneExhibition::new(problem, board.clone()).map_err(Failure::Other)?;
                    (Watched::Scene(board), Box::new(exhibition))
                }
            };
        publish(&watched, &state);
        let server = args.serving.bind(1.0)?;
        let stop = stop.clone();
        let thread = std::thread::spawn(move || server.serve(stage, stop));
        Some((watched, thread))
    } else {
        None
    };

    // Built once for the whole run (a scene is parsed and checked here).
    let problem = state.config.problem.build().map_err(input)?;
    let total = state.config.generations;
    // A terminal gets a bar; a log file a line every few seconds.
    let lines = !std::io::stderr().is_terminal();
    let mut last_line = Instant::now();
    let bar = if lines {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(total)
    };
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:32}] {pos}/{len} generations  {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_position(state.generation());
    let start = Instant::now();
    let evals_at_start = state.evaluations;
    let mut last_save = Instant::now();
    let mut interrupted = false;
    // Generations each roobot lane advances between progress updates and
    // Ctrl-C checks, grown to about a quarter of a second's work (a
    // scene's lanes advance one generation at a time: its generations are
    // long).
    let mut batch = animats_evolve::FIRST_BATCH;
    while !state.done() {
        if stop.load(Ordering::SeqCst) {
            interrupted = true;
            break;
        }
        let roobot = state.config.problem.is_roobot();
        let n = if roobot { batch } else { 1 };
        let begun = Instant::now();
        pool.install(|| state.advance_with(problem.as_ref(), n))
            .map_err(Failure::Other)?;
        if roobot {
            batch = animats_evolve::next_batch(batch, begun.elapsed());
        }
        let rate =
            (state.evaluations - evals_at_start) as f64 / start.elapsed().as_secs_f64().max(1e-9);
        if let Some((watched, _)) = &viewing {
            publish(watched, &state);
        }
        bar.set_position(state.generation());
        let message = format!(
            "{rate:.0} evals/s, best fitness {:.1}",
            state.best_fitness().unwrap_or(f64::NAN)
        );
        if lines && (last_line.elapsed().as_secs_f64() >= PROGRESS_EVERY || state.done()) {
            eprintln!(
                "generation {} of {total}: {} evaluations, {message}",
                state.generation(),
                state.evaluations
            );
            last_line = Instant::now();
        }
        bar.set_message(message);
        if last_save.elapsed().as_secs_f64() >= args.checkpoint_every {
            save(&dir, &state, false)?;
            last_save = Instant::now();
        }
    }
    bar.finish_and_clear();
    save(&dir, &state, true)?;
    let wall = start.elapsed().as_secs_f64();
    let evals = state.evaluations - evals_at_start;

    println!(
        "{} lanes, generation {} of {}, seed {}: {evals} evaluations in {wall:.2} s ({:.0}/s, {threads} threads)",
        state.config.lanes,
        state.generation(),
        total,
        state.config.seed,
        evals as f64 / wall.max(1e-9)
    );
    let time_name = if state.config.problem.is_roobot() {
        "upright"
    } else {
        "time"
    };
    for l in &state.lanes {
        let Some(b) = &l.best else { continue };
        println!(
            "  lane {}: best fitness {:>8.2}  {time_name} {:>6.3} s  distance {:>7.3} m  ({})",
            l.lane, b.fitness, b.time, b.distance, b.ended
        );
    }
    println!(
        "wrote {}/log.csv, best.toml, fitness.png, {CHECKPOINT}",
        dir.display()
    );
    if let Some((_, thread)) = viewing {
        if !interrupted {
            println!("the view stays open: Ctrl-C to stop");
        }
        let served = thread
            .join()
            .unwrap_or_else(|_| Err("the viewer failed".into()));
        served.map(|_| ()).map_err(Failure::Other)?;
    }
    if interrupted {
        return Err(Failure::Interrupted(format!(
            "interrupted at generation {}; continue with `animats evolve --resume {}`",
            state.generation(),
            dir.display()
        )));
    }
    Ok(())
}
