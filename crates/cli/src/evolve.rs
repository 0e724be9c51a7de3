//! `animats evolve`: the thesis's evolution of hopping gaits, in parallel
//! lanes, with a progress bar, checkpoints, and Ctrl-C to stop cleanly.

use crate::Failure;
use animats_evolve::{checkpoint, Config, State};
use animats_render::{step_plot_png, Plot, Series};
use animats_scene::params::{format_best, LaneBest};
use animats_viewer::exhibition::Showcase;
use animats_viewer::Exhibition;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Arguments of `animats evolve`.
#[derive(clap::Args)]
pub struct Args {
    /// Generations per lane (a resumed run can be given a new total).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    generations: Option<u64>,
    /// Independent lanes (lane k mutates by up to ±25 (k + 1) %).
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
    /// Watch it live in the browser: every lane's current best hopping side
    /// by side. The view stays open after the run until Ctrl-C.
    #[arg(long)]
    view: bool,
    #[command(flatten)]
    serving: crate::view::Serving,
}

const CHECKPOINT: &str = "checkpoint.json";
/// Generations each lane advances between progress updates and Ctrl-C checks.
const BATCH: u64 = 10;

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
    let lanes: Vec<LaneBest> = state
        .lanes
        .iter()
        .filter_map(|l| {
            let mut params = animats_creatures::roobot::HopParams::INITIAL;
            params.0.copy_from_slice(&l.best);
            l.best_fitness.map(|fitness| LaneBest {
                lane: l.lane,
                params,
                fitness,
                time_up: l.best_time_up,
                distance: l.best_distance,
            })
        })
        .collect();
    let comment = format!(
        "Best roobot hopping parameters of `animats evolve` (seed {}, {} lanes, generation {}).\nLoad the best with `animats hop best.toml`, lane K's with `--lane K`.",
        state.config.seed,
        state.config.lanes,
        state.generation()
    );
    animats_files::write_atomically(
        &dir.join("best.toml"),
        format_best(&lanes, &comment).as_bytes(),
    )
    .map_err(io)?;
    if with_plot {
        let plot = Plot {
            title: format!("Best fitness per lane (seed {})", state.config.seed),
            x_label: "generation".into(),
            y_label: "best fitness (time upright + 50 × distance)".into(),
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

/// Shows every lane's best so far to the viewer.
fn publish(showcase: &Showcase, state: &State) {
    for l in &state.lanes {
        if let Some(fitness) = l.best_fitness {
            let mut params = animats_creatures::roobot::HopParams::INITIAL;
            params.0.copy_from_slice(&l.best);
            showcase.set_best(l.lane, params, fitness);
        }
    }
    showcase.set_generation(state.generation(), state.config.generations);
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let (dir, mut state) = match &args.resume {
        Some(dir) => {
            let state = checkpoint::load(&dir.join(CHECKPOINT)).map_err(input)?;
            if args.lanes.is_some_and(|l| l != state.config.lanes)
                || args.seed.is_some_and(|s| s != state.config.seed)
            {
                return Err(input(format!(
                    "{}: a resumed run keeps its lanes ({}) and seed ({}); leave --lanes and --seed out",
                    dir.display(),
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
            writable(&dir)?;
            let config = Config::thesis(
                args.lanes.unwrap_or(6),
                args.generations.unwrap_or(100),
                args.seed.unwrap_or(1),
            );
            (dir, State::new(config).map_err(input)?)
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
        let showcase = Showcase::new(state.config.lanes);
        publish(&showcase, &state);
        let exhibition =
            Exhibition::new(showcase.clone(), state.config.settings()).map_err(Failure::Other)?;
        let server = args.serving.bind(1.0)?;
        let stop = stop.clone();
        let thread = std::thread::spawn(move || server.serve(Box::new(exhibition), stop));
        Some((showcase, thread))
    } else {
        None
    };

    let total = state.config.generations;
    let bar = ProgressBar::new(total);
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
    while !state.done() {
        if stop.load(Ordering::SeqCst) {
            interrupted = true;
            break;
        }
        pool.install(|| state.advance(BATCH))
            .map_err(Failure::Other)?;
        let rate =
            (state.evaluations - evals_at_start) as f64 / start.elapsed().as_secs_f64().max(1e-9);
        if let Some((showcase, _)) = &viewing {
            publish(showcase, &state);
        }
        bar.set_position(state.generation());
        bar.set_message(format!(
            "{rate:.0} evals/s, best fitness {:.1}",
            state.best_fitness().unwrap_or(f64::NAN)
        ));
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
    for l in &state.lanes {
        println!(
            "  lane {}: best fitness {:>8.2}  upright {:>6.3} s  distance {:>7.3} m",
            l.lane,
            l.best_fitness.unwrap_or(f64::NAN),
            l.best_time_up,
            l.best_distance
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
