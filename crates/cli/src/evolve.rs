//! `animats evolve [SCENE]`: a scene's `[evolve]` controller (without a
//! scene, the thesis's evolution of hopping gaits, the built-in
//! `scenes/hop_evolver.toml`), in parallel lanes with the hill climber, a
//! GA or CMA-ES; a progress bar (a line every few seconds when stderr is
//! not a terminal), checkpoints, and Ctrl-C to stop cleanly.

use crate::Failure;
use animats_evolve::optimiser::map_elites::QdKind;
use animats_evolve::{checkpoint, Choices, Config, OptimiserKind, ProblemSpec, State};
use animats_render::{step_plot_png, Plot, Series};
use animats_scene::morphology::MorphologyProblem;
use animats_viewer::{BestBrain, Exhibition};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Arguments of `animats evolve`.
#[derive(clap::Args)]
pub struct Args {
    /// A scene file with an `[evolve]` table; without one, the thesis's
    /// roobot (scenes/hop_evolver.toml, built in).
    scene: Option<PathBuf>,
    /// The optimiser of every lane [default: the scene's `[evolve]
    /// optimiser`, else cma-es; a [morphology] scene's: body-ga; the
    /// thesis's roobot: hill-climber]. map-elites and cma-me fill the
    /// scene's [archive] (one lane; docs/DIVERSITY.md).
    #[arg(long, value_parser = optimiser_names())]
    optimiser: Option<OptimiserKind>,
    /// Candidates per generation per lane [default: hill-climber 1, ga 32,
    /// cma-es 4 + 3 ln n, body-ga 16; map-elites and cma-me: per emitter
    /// 36 and 4 + 3 ln n].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    population: Option<u64>,
    /// CMA-ES only: start again with twice the population, up to this many
    /// times, when a run converges or stagnates (IPOP) [default: 0].
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=20))]
    restarts: Option<u32>,
    /// Generations per lane (a resumed run can be given a new total)
    /// [default: 100].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    generations: Option<u64>,
    /// Independent lanes [default: the scene's `[evolve] lanes`, else 1;
    /// the thesis's roobot: 6]; the hill climber's lane k mutates by up to
    /// ±25 (k + 1) % where the scene says `mutation = "relative"`.
    #[arg(long)]
    lanes: Option<usize>,
    /// Seed of every random choice [default: 1].
    #[arg(long)]
    seed: Option<u64>,
    /// Directory to write log.csv, best.toml (the best lane's scene),
    /// lanes/K.toml (each lane's), fitness.png and the checkpoint.
    #[arg(long, default_value = "evolution")]
    out: PathBuf,
    /// Continue the run in this directory from its checkpoint.
    #[arg(long, conflicts_with = "out")]
    resume: Option<PathBuf>,
    /// Worker threads [default: every core].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    threads: Option<u64>,
    /// Seconds between checkpoints (0: after each generation of every lane);
    /// the lanes never wait for each other between them.
    #[arg(long, default_value_t = 5.0, value_parser = crate::non_negative_f64)]
    checkpoint_every: f64,
    /// Watch it live in the browser: the scene driven by its best brain so
    /// far, or in a [morphology] scene its best body and brain (restarted
    /// with the newest best when each run ends). The view stays open after
    /// the run until Ctrl-C.
    #[arg(long)]
    view: bool,
    /// Record where the run's time goes (every ask, evaluation and tell:
    /// its lane, generation, batch, thread, start and duration) into
    /// DIR/schedule.csv, and print the wall time the run's own dependencies
    /// predict for 1 to 64 workers, with and without the barrier at the
    /// end of each batch of generations. The results are unchanged.
    #[arg(long)]
    pub(crate) schedule: bool,
    /// Skip the checks at the end of the run (the best scored again at a
    /// quarter of the step with its own integrator and with another: eight
    /// evaluations' time at the scene's step).
    #[arg(long)]
    no_check: bool,
    /// Where the candidates are evaluated: cpu (the engine on every core),
    /// cuda (a generation at a time on an NVIDIA GPU, one thread a
    /// candidate: the same log and best; docs/GPU.md says what it covers)
    /// or cuda-fast (the GPU with fused multiply-adds: not the same bits).
    #[arg(long, value_enum, default_value_t)]
    device: crate::device::DeviceName,
    #[command(flatten)]
    serving: crate::view::Serving,
}

/// `--optimiser`: one of [`OptimiserKind::ALL`], listed in `--help`.
fn optimiser_names() -> impl clap::builder::TypedValueParser<Value = OptimiserKind> {
    use clap::builder::TypedValueParser;
    let names: Vec<&'static str> = OptimiserKind::ALL.iter().map(|k| k.name()).collect();
    clap::builder::PossibleValuesParser::new(names).try_map(|s| OptimiserKind::parse(&s))
}

const CHECKPOINT: &str = checkpoint::FILE;
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

/// Prints the checks a winner must pass before it is believed
/// (`animats_evolve::check`: the best at a quarter of the step with its
/// own integrator and with another, and whether each keeps 80 % of its
/// fitness) and writes `checked.toml`, the best candidate that keeps 80 %
/// in both: the best itself, or where it fails, the first that passes of
/// the next 16. It changes nothing written before. Returns whether it
/// wrote `checked.toml`.
fn check_best(dir: &Path, state: &State) -> Result<bool, Failure> {
    let Some(report) = animats_evolve::check::check(state).map_err(Failure::Other)? else {
        return Ok(false);
    };
    let checked = report.checked_toml();
    if let Some(text) = &checked {
        animats_files::write_atomically(&dir.join("checked.toml"), text.as_bytes())
            .map_err(Failure::Other)?;
    }
    for line in report.lines(Some(dir)) {
        say!("  {line}");
    }
    Ok(checked.is_some())
}

/// The end of a run's (or of this part of it) files: log.csv, best.toml,
/// fitness.png, each lane's best (lanes/K.toml), an archive's archive.csv
/// and elites, and the checkpoint. The files are independent of each other and are
/// written side by side on the caller's rayon pool (at the end of a run on
/// many cores they are, with the winner's checks, all there is to do); the
/// checkpoint last, so that one on disk never stands for more than the
/// files beside it. The first error in that order is returned. (During a
/// run: [`periodic_files`] and [`Writing`].)
fn save(dir: &Path, state: &State) -> Result<(), Failure> {
    use rayon::prelude::*;
    type Job<'a> = Box<dyn Fn() -> Result<(), Failure> + Send + Sync + 'a>;
    let io = Failure::Other;
    let write =
        |path: PathBuf, bytes: &[u8]| animats_files::write_atomically(&path, bytes).map_err(io);
    let mut jobs: Vec<Job> = vec![
        Box::new(|| write(dir.join("log.csv"), state.log_csv().as_bytes())),
        Box::new(|| match state.best_toml().map_err(io)? {
            Some(best) => write(dir.join("best.toml"), best.as_bytes()),
            None => Ok(()),
        }),
        Box::new(|| match state.archive_csv() {
            Some(csv) => write(dir.join("archive.csv"), csv.as_bytes()),
            None => Ok(()),
        }),
    ];
    if state.config.lanes > 1 {
        let lanes = dir.join("lanes");
        std::fs::create_dir_all(&lanes)
            .map_err(|e| Failure::Other(format!("{}: cannot create it: {e}", lanes.display())))?;
        for l in &state.lanes {
            let lanes = lanes.clone();
            jobs.push(Box::new(move || {
                match state.lane_toml(l.lane).map_err(io)? {
                    Some(text) => write(lanes.join(format!("{}.toml", l.lane)), text.as_bytes()),
                    None => Ok(()),
                }
            }));
        }
    }
    if state.archive().is_some() {
        jobs.push(Box::new(|| save_elites(dir, state)));
    }
    jobs.push(Box::new(|| {
        let plot = Plot {
            title: format!(
                "Best fitness per lane ({}, seed {})",
                state.config.optimiser.name(),
                state.config.seed
            ),
            x_label: "generation".into(),
            y_label: "best fitness".into(),
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
        write(dir.join("fitness.png"), &step_plot_png(&plot).map_err(io)?)
    }));
    let done: Vec<Result<(), Failure>> = jobs.par_iter().map(|job| job()).collect();
    done.into_iter().collect::<Result<(), Failure>>()?;
    checkpoint::save(&dir.join(CHECKPOINT), state).map_err(io)
}

/// The files of a save during a run (log.csv, best.toml, an archive's
/// archive.csv, the checkpoint last), made in memory side by side while
/// the lanes stand still, to be written by [`Writing`] while they go on.
fn periodic_files(dir: &Path, state: &State) -> Result<Vec<(PathBuf, Vec<u8>)>, Failure> {
    Ok(checkpoint::run_files(state)
        .map_err(Failure::Other)?
        .into_iter()
        .map(|(name, text)| (dir.join(name), text.into_bytes()))
        .collect())
}

/// A run's periodic save being written by a thread of its own, so that
/// the lanes need not wait for the disk (each file is synced before it
/// is renamed into place: a few milliseconds on this project's machines,
/// far longer on a busy or networked file system). One save at a time:
/// the next, and the end's, wait for it first ([`Writing::wait`]);
/// dropped, it is waited for too.
#[derive(Default)]
struct Writing(Option<std::thread::JoinHandle<Result<(), String>>>);

impl Writing {
    /// Writes `files` in order (the checkpoint last: one on disk never
    /// stands for more than the files beside it) once the save before
    /// them is written; that save's error, if any.
    fn start(&mut self, files: Vec<(PathBuf, Vec<u8>)>) -> Result<(), Failure> {
        self.wait()?;
        self.0 = Some(std::thread::spawn(move || {
            files
                .iter()
                .try_for_each(|(path, bytes)| animats_files::write_atomically(path, bytes))
        }));
        Ok(())
    }

    /// Waits for the save being written; its error, if any.
    fn wait(&mut self) -> Result<(), Failure> {
        match self.0.take().map(std::thread::JoinHandle::join) {
            None => Ok(()),
            Some(Ok(written)) => written.map_err(Failure::Other),
            Some(Err(_)) => Err(Failure::Other("writing a checkpoint panicked".into())),
        }
    }
}

impl Drop for Writing {
    fn drop(&mut self) {
        let _ = self.wait();
    }
}

/// A quality-diversity run's `elites/<index>.toml` (each elite as a whole
/// scene) and `archive.png` (the heat map).
fn save_elites(dir: &Path, state: &State) -> Result<(), Failure> {
    use rayon::prelude::*;
    let io = Failure::Other;
    let Some(archive) = state.archive() else {
        return Ok(());
    };
    let elites = dir.join("elites");
    std::fs::create_dir_all(&elites)
        .map_err(|e| Failure::Other(format!("{}: cannot create it: {e}", elites.display())))?;
    // The elites' files and the heat map side by side; the first error
    // in that order.
    let (written, png) = rayon::join(
        || -> Result<(), Failure> {
            let tomls = state.elite_tomls().map_err(io)?;
            let done: Vec<Result<(), Failure>> = tomls
                .par_iter()
                .map(|(index, text)| {
                    let path = elites.join(format!("{index}.toml"));
                    animats_files::write_atomically(&path, text.as_bytes()).map_err(io)
                })
                .collect();
            done.into_iter().collect()
        },
        || -> Result<(), Failure> {
            let png = animats_render::heatmap_png(&heatmap(state, archive)).map_err(io)?;
            animats_files::write_atomically(&dir.join("archive.png"), &png).map_err(io)
        },
    );
    written.and(png)
}

/// The archive's heat map: the first two measures, each cell coloured by
/// the best objective over the rest.
pub fn heatmap(
    state: &State,
    archive: &animats_evolve::archive::GridArchive,
) -> animats_render::Heatmap {
    let g = &archive.grid;
    let mut best: std::collections::BTreeMap<(u64, u64), f64> = Default::default();
    for e in archive.elites() {
        let c = archive.unravel(e.index);
        let key = (c[0], c.get(1).copied().unwrap_or(0));
        let f = best.entry(key).or_insert(f64::NEG_INFINITY);
        *f = f.max(e.objective);
    }
    let s = archive.stats();
    animats_render::Heatmap {
        title: format!(
            "{} ({}, seed {}): coverage {:.1} %, QD score {:.4e}",
            Path::new(&state.config.problem.file)
                .file_name()
                .map_or_else(
                    || state.config.problem.file.clone(),
                    |n| n.to_string_lossy().into_owned()
                ),
            state.config.optimiser.name(),
            state.config.seed,
            100.0 * s.coverage,
            s.qd_score
        ),
        x_label: g.names[0].clone(),
        y_label: g.names.get(1).cloned().unwrap_or_default(),
        bins: (g.bins[0], g.bins.get(1).copied().unwrap_or(1)),
        ranges: (g.ranges[0], g.ranges.get(1).copied().unwrap_or((0.0, 1.0))),
        cells: best.into_iter().map(|((i, j), f)| (i, j, f)).collect(),
        size: (900, 700),
    }
}

/// Shows the best so far to the viewer.
fn publish(board: &BestBrain, state: &State) {
    if let Some(l) = state.best_lane() {
        if let Some(b) = &l.best {
            board.set_best(&b.genome, b.fitness, l.lane);
        }
    }
    board.set_generation(state.generation(), state.config.generations);
}

/// The state of a new run, or of the run in `dir` continued.
fn start(args: &Args) -> Result<(PathBuf, State), Failure> {
    let choices = Choices {
        lanes: args.lanes,
        generations: args.generations,
        seed: args.seed,
        optimiser: args.optimiser,
        population: args.population.map(|p| p as usize),
        restarts: args.restarts,
    };
    if let Some(dir) = &args.resume {
        if args.scene.is_some() {
            return Err(input(format!(
                "{}: a resumed run keeps its scene; give only --resume and --generations",
                dir.display()
            )));
        }
        let mut state = checkpoint::load(&dir.join(CHECKPOINT)).map_err(input)?;
        state
            .resume(&choices)
            .map_err(|e| input(format!("{}: {e}", dir.display())))?;
        writable(dir)?;
        return Ok((dir.clone(), state));
    }
    let dir = args.out.clone();
    if dir.join(CHECKPOINT).exists() {
        return Err(input(format!(
            "{}: already holds an evolution run; continue it with --resume {} or choose another --out",
            dir.display(),
            dir.display()
        )));
    }
    // Read once; refused here, before any output exists, if it does not
    // parse.
    let problem = match &args.scene {
        Some(path) => ProblemSpec {
            file: path.display().to_string(),
            text: animats_scene::read(path).map_err(|e| input(e.to_string()))?,
        },
        None => ProblemSpec::thesis(),
    };
    if let Some(path) = &args.scene {
        // What `simulate` and `evaluate` would warn of (an unstable step, a
        // particle inside the floor, an actuator that jumps at t = 0); a
        // [morphology] scene's bodies are checked as they develop.
        if let Ok(scene) = animats_scene::parse(&problem.text, &problem.file) {
            crate::warn(path, &scene.warnings);
        }
    }
    let config = Config::new(problem, &choices).map_err(input)?;
    let state = State::new(config).map_err(input)?;
    writable(&dir)?;
    Ok((dir, state))
}

/// The live view of the run, if asked for: the board the run publishes
/// its best to, and the server's thread.
type Viewing = (
    BestBrain,
    std::thread::JoinHandle<Result<animats_viewer::Summary, String>>,
);

fn watch(args: &Args, state: &State, stop: &Arc<AtomicBool>) -> Result<Option<Viewing>, Failure> {
    if !args.view {
        return Ok(None);
    }
    let spec = &state.config.problem;
    let board = BestBrain::default();
    let stage = if spec.has_morphology().map_err(input)? {
        let problem =
            MorphologyProblem::parse(&spec.text, &spec.file).map_err(|e| input(e.to_string()))?;
        Exhibition::bodies(problem, board.clone())
    } else {
        Exhibition::new(spec.parse().map_err(input)?, board.clone())
    }
    .map_err(Failure::Other)?;
    publish(&board, state);
    let server = args.serving.bind(1.0)?;
    let stop = stop.clone();
    let thread = std::thread::spawn(move || server.serve(Box::new(stage), stop));
    Ok(Some((board, thread)))
}

/// Progress on stderr: a bar on a terminal, a line every few seconds in a
/// log file.
struct Progress {
    bar: ProgressBar,
    lines: bool,
    last_line: Instant,
    start: Instant,
    evals_at_start: u64,
    total: u64,
}

impl Progress {
    fn new(state: &State) -> Progress {
        let lines = !std::io::stderr().is_terminal();
        let bar = if lines {
            ProgressBar::hidden()
        } else {
            ProgressBar::new(state.config.generations)
        };
        bar.set_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{bar:32}] {pos}/{len} generations  {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar.set_position(state.generation());
        Progress {
            bar,
            lines,
            last_line: Instant::now(),
            start: Instant::now(),
            evals_at_start: state.evaluations,
            total: state.config.generations,
        }
    }

    fn show(&mut self, state: &State) {
        self.show_numbers(
            state.generation(),
            state.evaluations,
            state.best_fitness(),
            state.done(),
        );
    }

    /// `generation`: the lowest lane's.
    fn show_numbers(&mut self, generation: u64, evaluations: u64, best: Option<f64>, done: bool) {
        let rate = evaluations.saturating_sub(self.evals_at_start) as f64
            / self.start.elapsed().as_secs_f64().max(1e-9);
        self.bar.set_position(generation);
        let message = format!(
            "{rate:.0} evals/s, best fitness {:.1}",
            best.unwrap_or(f64::NAN)
        );
        if self.lines && (self.last_line.elapsed().as_secs_f64() >= PROGRESS_EVERY || done) {
            eprintln!(
                "generation {generation} of {}: {evaluations} evaluations, {message}",
                self.total
            );
            self.last_line = Instant::now();
        }
        self.bar.set_message(message);
    }
}

/// Advances the run to its end (or to Ctrl-C: then true), showing progress,
/// publishing to the view and saving a checkpoint every
/// `--checkpoint-every` seconds. No lane waits for another between
/// checkpoints ([`State::advance_while`]): progress is watched from this
/// thread while the pool's threads work.
fn evolve(
    args: &Args,
    dir: &Path,
    state: &mut State,
    pool: &rayon::ThreadPool,
    stop: &AtomicBool,
    board: Option<&BestBrain>,
    tracer: Option<&animats_evolve::schedule::Tracer>,
) -> Result<bool, Failure> {
    // `--device cuda`: the scene checked and the GPU opened before any
    // generation.
    let spec = &state.config.problem;
    let batches = crate::device::batches(args.device, &spec.file, || crate::device::probe(spec))
        .map_err(input)?
        .map(crate::device::note_small_batches);
    // Built once for the whole run (a scene is parsed and checked here).
    let problem = state.config.problem.build_on(batches).map_err(input)?;
    let mut progress = Progress::new(state);
    let mut writing = Writing::default();
    // Each stretch of work runs until the next checkpoint is due (at least
    // a generation of every lane), or Ctrl-C.
    let every = Duration::try_from_secs_f64(args.checkpoint_every).unwrap_or(Duration::MAX);
    while !state.done() {
        if stop.load(Ordering::SeqCst) {
            progress.bar.finish_and_clear();
            writing.wait()?;
            return Ok(true);
        }
        let begun = Instant::now();
        let live = Mutex::new(Live::new(state));
        let watcher = std::thread::current();
        let problem = problem.as_ref();
        // Set by the work before it wakes this thread: the thread itself
        // is finished only a moment later, and a watcher that woke to find
        // it not yet finished slept its whole 250 ms again while every lane
        // waited (0.25-0.29 s at a checkpoint or at the end, seen in
        // `--schedule` traces, 2026-12-01).
        let done = AtomicBool::new(false);
        let result = std::thread::scope(|scope| {
            let work = scope.spawn(|| {
                let more = || !stop.load(Ordering::SeqCst) && begun.elapsed() < every;
                let seen = |row: &animats_evolve::LogRow| {
                    if let Ok(mut l) = live.lock() {
                        l.saw(row);
                    }
                };
                let r = pool.install(|| state.advance_while(problem, tracer, &more, &seen));
                done.store(true, Ordering::SeqCst);
                watcher.unpark();
                r
            });
            // (Finished also when an evaluation panicked: then `join` says so.)
            while !done.load(Ordering::SeqCst) && !work.is_finished() {
                std::thread::park_timeout(Duration::from_millis(250));
                if let Ok(mut l) = live.lock() {
                    progress.show_numbers(l.generation(), l.evaluations(), l.best_fitness(), false);
                    if let Some(board) = board {
                        l.publish(board);
                    }
                }
            }
            work.join()
        });
        match result {
            Ok(r) => r.map_err(Failure::Other)?,
            Err(_) => return Err(Failure::Other("an evaluation panicked".into())),
        }
        if let Some(board) = board {
            publish(board, state);
        }
        progress.show(state);
        if !state.done() {
            let files = pool.install(|| periodic_files(dir, state))?;
            writing.start(files)?;
        }
    }
    progress.bar.finish_and_clear();
    writing.wait()?;
    Ok(false)
}

/// A run's progress as its lanes report their generations.
struct Live {
    generations: Vec<u64>,
    evaluations: Vec<u64>,
    total: u64,
    /// The best so far: fitness, genome, lane.
    best: Option<(f64, Vec<f64>, usize)>,
    /// Whether `best` changed since it was last published.
    fresh: bool,
}

impl Live {
    fn new(state: &State) -> Live {
        let best = state.best_lane().and_then(|l| {
            l.best
                .as_ref()
                .map(|b| (b.fitness, b.genome.clone(), l.lane))
        });
        Live {
            generations: state.lanes.iter().map(|l| l.generation).collect(),
            evaluations: state.lanes.iter().map(|l| l.evaluations).collect(),
            total: state.config.generations,
            best,
            fresh: false,
        }
    }

    fn saw(&mut self, row: &animats_evolve::LogRow) {
        if let Some(g) = self.generations.get_mut(row.lane) {
            *g = row.generation;
        }
        if let Some(e) = self.evaluations.get_mut(row.lane) {
            *e = row.evaluations;
        }
        if let Some(genome) = &row.improved {
            // The lowest lane among equals, as State::best_lane.
            let better = self.best.as_ref().is_none_or(|(f, _, lane)| {
                row.best_fitness > *f || (row.best_fitness == *f && row.lane < *lane)
            });
            if better {
                self.best = Some((row.best_fitness, genome.clone(), row.lane));
                self.fresh = true;
            }
        }
    }

    fn generation(&self) -> u64 {
        self.generations.iter().copied().min().unwrap_or(0)
    }

    fn evaluations(&self) -> u64 {
        self.evaluations.iter().sum()
    }

    fn best_fitness(&self) -> Option<f64> {
        self.best.as_ref().map(|b| b.0)
    }

    fn publish(&mut self, board: &BestBrain) {
        if let (Some((f, genome, lane)), true) = (&self.best, self.fresh) {
            board.set_best(genome, *f, *lane);
            self.fresh = false;
        }
        board.set_generation(self.generation(), self.total);
    }
}

/// Writes DIR/schedule.csv and prints the schedule model's predictions
/// (`--schedule`), beside the `wall` s the run took on `threads`.
fn report_schedule(
    dir: &Path,
    s: &animats_evolve::schedule::Schedule,
    wall: f64,
    threads: usize,
) -> Result<(), Failure> {
    use animats_evolve::schedule::Piece;
    let mut csv =
        String::from("lane,generation,piece,candidate,batch,thread,start_s,seconds,position\n");
    for w in &s.work {
        let (piece, k) = match w.piece {
            Piece::Ask => ("ask", String::new()),
            Piece::Vary(k) => ("vary", k.to_string()),
            Piece::Evaluate(k) => ("evaluate", k.to_string()),
            Piece::Tell => ("tell", String::new()),
        };
        let position = match w.piece {
            Piece::Evaluate(_) => w.position.to_string(),
            _ => String::new(),
        };
        csv.push_str(&format!(
            "{},{},{piece},{k},{},{},{:.9},{:.9},{position}\n",
            w.lane, w.generation, w.batch, w.thread, w.start, w.seconds
        ));
    }
    animats_files::write_atomically(&dir.join("schedule.csv"), csv.as_bytes())
        .map_err(|e| Failure::Other(e.to_string()))?;
    let work = s.work_seconds();
    let evaluations: Vec<f64> = s
        .work
        .iter()
        .filter(|w| matches!(w.piece, Piece::Evaluate(_)))
        .map(|w| w.seconds)
        .collect();
    let eval_sum: f64 = evaluations.iter().sum();
    let batches = s.work.last().map_or(0, |w| w.batch + 1);
    say!(
        "schedule: {} evaluations ({:.3} s, mean {:.2} ms, longest {:.2} ms) and {:.3} s of asks and tells in {batches} batches; {work:.3} s of work in {wall:.3} s on {threads} threads (busy {:.1} % of the time)",
        evaluations.len(),
        eval_sum,
        1e3 * eval_sum / evaluations.len().max(1) as f64,
        1e3 * evaluations.iter().cloned().fold(0.0, f64::max),
        work - eval_sum,
        100.0 * work / (wall * threads as f64).max(1e-12),
    );
    say!(
        "  critical path {:.3} s with batch barriers, {:.3} s without, {:.3} s overlapped; predicted on {threads} threads {:.3} s (measured {wall:.3} s)",
        s.critical_path(true),
        s.critical_path(false),
        s.critical_path_overlapped(),
        s.makespan(threads, true)
    );
    say!("  workers   predicted wall   speed-up   without barriers   overlapped");
    let one = s.makespan(1, true);
    for w in [1usize, 2, 4, 8, 16, 32, 64] {
        let (a, b, c) = (
            s.makespan(w, true),
            s.makespan(w, false),
            s.makespan_overlapped(w),
        );
        say!(
            "  {w:>7}   {a:>12.3} s   {:>7.2}×   {b:>9.3} s {:>6.2}×   {c:>8.3} s {:>6.2}×",
            one / a,
            one / b,
            one / c
        );
    }
    say!("  (overlapped: each lane asked for its next generation while the last is evaluated: MAP-Elites with [archive] overlap = true)");
    say!("wrote {}/schedule.csv", dir.display());
    Ok(())
}

/// Where a run's threads outnumber the evaluations its lanes' generations
/// hold at a time, a note saying so: the others had nothing to evaluate
/// (a lane's generation waits for its own evaluations; the lanes never
/// wait for each other). More lanes or larger populations give them work;
/// the run cannot widen itself, since its results would then depend on the
/// number of threads. `None` where every thread could be busy.
fn idle_threads_note(state: &State, threads: usize) -> Option<String> {
    // Each lane's evaluations a generation (its mean over its generations).
    let per_lane: Vec<u64> = state
        .lanes
        .iter()
        .filter(|l| l.generation > 0)
        .map(|l| l.evaluations.div_ceil(l.generation))
        .collect();
    let widest = *per_lane.iter().max()?;
    // An overlapping lane evaluates two generations at once.
    let overlap = state.lanes.iter().any(|l| l.optimiser.overlaps());
    let at_once = per_lane.iter().sum::<u64>() * if overlap { 2 } else { 1 };
    if threads as u64 <= at_once {
        return None;
    }
    // Restarts (IPOP) grow the population: the figures are then means.
    let (most, up_to) = if state.config.restarts > 0 {
        ("about", "about")
    } else {
        ("at most", "up to")
    };
    let lanes = match per_lane.len() {
        1 => format!("1 lane, {widest} a generation"),
        n => format!("{n} lanes, {up_to} {widest} a generation each"),
    };
    let two = if overlap {
        ", two generations at once"
    } else {
        ""
    };
    // A quality-diversity search has one lane; MAP-Elites's may overlap
    // its generations (CMA-ME's emitters adapt from each one told).
    let qd = state.lanes.iter().find_map(|l| l.optimiser.kind().qd());
    let wider = match qd {
        Some(QdKind::MapElites) if !overlap => {
            "a larger population (--population) or overlapping generations ([archive] overlap = true)"
        }
        Some(_) => "a larger population (--population)",
        None => "more lanes (--lanes) or a larger population (--population)",
    };
    let others = match threads as u64 - at_once {
        1 => "the other thread".to_string(),
        n => format!("the other {n} threads"),
    };
    Some(format!(
        "note: {threads} threads, but {most} {at_once} evaluations at once ({lanes}{two}): {wider} would give {others} work",
    ))
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let (dir, mut state) = start(&args)?;
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
    let viewing = watch(&args, &state, &stop)?;
    let (start, evals_at_start) = (Instant::now(), state.evaluations);
    let board = viewing.as_ref().map(|(b, _)| b);
    let tracer = args
        .schedule
        .then(animats_evolve::schedule::Tracer::default);
    let interrupted = evolve(
        &args,
        &dir,
        &mut state,
        &pool,
        &stop,
        board,
        tracer.as_ref(),
    )?;
    let wall = start.elapsed().as_secs_f64();
    let evals = state.evaluations - evals_at_start;
    say!(
        "{} lanes, generation {} of {}, seed {}: {evals} evaluations in {wall:.2} s ({:.0}/s, {threads} threads)",
        state.config.lanes,
        state.generation(),
        state.config.generations,
        state.config.seed,
        evals as f64 / wall.max(1e-9)
    );
    for l in &state.lanes {
        let Some(b) = &l.best else { continue };
        say!(
            "  lane {}: best fitness {:>8.2}  time {:>6.3} s  distance {:>7.3} m  ({})",
            l.lane,
            b.fitness,
            b.time,
            b.distance,
            b.ended
        );
    }
    if args.device == crate::device::DeviceName::Cpu {
        if let Some(note) = idle_threads_note(&state, threads) {
            eprintln!("{note}");
        }
    }
    // A checked.toml of an earlier part of this run no longer stands.
    let _ = std::fs::remove_file(dir.join("checked.toml"));
    // The end's files (fitness.png: some 100 M instructions of drawing and
    // compressing) and the winner's checks (two runs side by side) both
    // only read the state: side by side on the run's own threads, the
    // serial work that follows the evaluations.
    let (saved, checked) = pool.install(|| {
        rayon::join(
            || save(&dir, &state),
            || {
                if args.no_check {
                    Ok(false)
                } else {
                    check_best(&dir, &state)
                }
            },
        )
    });
    saved?;
    let checked = checked?;
    if let Some((by, kept)) = state.refusals() {
        let total: u64 = by.values().sum();
        let reasons: Vec<String> = by.iter().map(|(r, n)| format!("{r} {n}")).collect();
        say!(
            "  refused: {total} variations ({}); {kept} children kept their parent after {} tries",
            if reasons.is_empty() {
                "none".to_string()
            } else {
                reasons.join(", ")
            },
            animats_scene::morphology::vary::RETRIES + 1
        );
    }
    if let Some(a) = state.archive() {
        let s = a.stats();
        say!(
            "  archive: {} of {} cells ({:.1} %), QD score {}, best {}",
            s.elites,
            a.cells(),
            100.0 * s.coverage,
            s.qd_score,
            s.obj_max.unwrap_or(f64::NAN)
        );
    }
    say!(
        "wrote {}/log.csv, best.toml, {}{}{}fitness.png, {CHECKPOINT}",
        dir.display(),
        if checked { "checked.toml, " } else { "" },
        if state.config.lanes > 1 {
            "lanes/, "
        } else {
            ""
        },
        if state.archive().is_some() {
            "archive.csv, archive.png, elites/, "
        } else {
            ""
        }
    );
    if let Some(t) = &tracer {
        report_schedule(&dir, &t.schedule(), wall, threads)?;
    }
    if let Some((_, thread)) = viewing {
        if !interrupted {
            say!("the view stays open: Ctrl-C to stop");
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
