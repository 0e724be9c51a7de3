//! The roobot's evolution with each optimiser at equal evaluation budgets
//! (issue 10, docs/ROOBOT.md): for every seed, one lane of 6000
//! evaluations with the thesis's hill climber, the GA and CMA-ES, tuning
//! the thesis's hopping FSM (14 parameters) and Raibert's three-part
//! controller (8 gains, `roobot::raibert`), each the roobot's brain in the
//! thesis's scene (`scenes/hop_evolver.toml`); how many evaluations until the
//! first stable hop (20 s upright), and the best fitness after 600 and 6000
//! evaluations. Prints a Markdown table and plots the median best fitness
//! against evaluations.
//!
//! ```sh
//! cargo run --release -p animats --example optimisers -- 20 6000 docs/img/optimisers.png
//! ```
//!
//! `-- one raibert|fsm OPTIMISER SEED BUDGET` reruns one case and prints its
//! best genome and what it does (distance, why it ended), also at a half
//! and a quarter of the evaluation's step.
//!
//! The hill climber of run k mutates as the thesis's lane (k − 1) mod 6
//! does (±25 % to ±150 %), so the 20 runs cover all six of its lanes.

use animats_evolve::optimiser::{AnyOptimiser, Optimiser, OptimiserKind};
use animats_evolve::problem::{Problem, SceneEvolution};
use animats_evolve::Config;
use animats_render::{step_plot_png, Plot, Series};
use animats_scene::evaluate::{evaluate, Evaluation, SceneProblem};
use rayon::prelude::*;

/// What one run saw: every evaluation's fitness and time upright, in order,
/// and the best genome.
struct Run {
    fitness: Vec<f64>,
    time: Vec<f64>,
    best: Vec<f64>,
}

/// What is tuned.
#[derive(Clone, Copy, PartialEq)]
enum Controller {
    Fsm,
    Raibert,
}

impl Controller {
    fn name(self) -> &'static str {
        match self {
            Controller::Fsm => "FSM",
            Controller::Raibert => "Raibert",
        }
    }

    /// The thesis's scene with this brain.
    fn problem(self) -> SceneProblem {
        let text = match self {
            Controller::Fsm => animats_scene::HOP_EVOLVER.to_string(),
            Controller::Raibert => {
                animats_scene::HOP_EVOLVER.replace("params = \"initial\"", "brain = \"raibert\"")
            }
        };
        SceneProblem::parse(&text, animats_scene::HOP_EVOLVER_FILE).expect("the thesis's scene")
    }
}

fn run(controller: Controller, kind: OptimiserKind, seed: u64, budget: usize) -> Run {
    let mut config = Config::thesis(1, u64::MAX, seed);
    config.optimiser = kind;
    let problem: Box<dyn Problem> = Box::new(SceneEvolution(controller.problem()));
    let lane = ((seed - 1) % 6) as usize;
    let mut setup = config.setup(problem.as_ref(), 0);
    if kind == OptimiserKind::HillClimber {
        setup.lane = lane;
    }
    let mut o = AnyOptimiser::new(&setup).expect("a valid setup");
    let (mut fitness, mut time) = (Vec::new(), Vec::new());
    let mut best = (f64::NEG_INFINITY, Vec::new());
    while fitness.len() < budget {
        let pop = o.ask();
        let outcomes: Vec<_> = pop
            .iter()
            .map(|g| problem.evaluate(g).expect("an evaluation"))
            .collect();
        o.tell(&outcomes.iter().map(|e| e.fitness).collect::<Vec<_>>())
            .expect("tell");
        for (g, e) in pop.iter().zip(outcomes) {
            if fitness.len() < budget && e.fitness > best.0 {
                best = (e.fitness, g.clone());
            }
            fitness.push(e.fitness);
            time.push(e.time);
        }
    }
    fitness.truncate(budget);
    time.truncate(budget);
    Run {
        fitness,
        time,
        best: best.1,
    }
}

/// `genome` for `controller` evaluated at the thesis's step divided by
/// `divide`.
fn evaluate_at(controller: Controller, genome: &[f64], divide: f64) -> Option<Evaluation> {
    let mut scene = controller.problem().scene(genome).ok()?;
    scene.dt /= divide;
    evaluate(scene).ok()
}

/// The run's best genome evaluated at a quarter of the step (2 ms): its
/// distance if it stays up for the 20 s, else `None`.
fn at_quarter_step(controller: Controller, genome: &[f64]) -> Option<f64> {
    let e = evaluate_at(controller, genome, 4.0)?;
    (e.time >= 20.0).then_some(e.distance)
}

fn best_after(r: &Run, n: usize) -> f64 {
    r.fitness[..n]
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The q-quantile (linear between order statistics).
fn quantile(v: &[f64], q: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let x = q * (s.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x - x.floor());
    if i + 1 < s.len() {
        s[i] * (1.0 - f) + s[i + 1] * f
    } else {
        s[i]
    }
}

fn one(args: &[String]) {
    let controller = match args.first().map(String::as_str) {
        Some("raibert") => Controller::Raibert,
        _ => Controller::Fsm,
    };
    let kind =
        OptimiserKind::parse(args.get(1).map_or("ga", String::as_str)).expect("an optimiser");
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let budget: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(6000);
    let r = run(controller, kind, seed, budget);
    println!(
        "{} tuned by {}, seed {seed}: best genome {:?}",
        controller.name(),
        kind.name(),
        r.best
    );
    for divide in [1.0, 2.0, 4.0] {
        let e = evaluate_at(controller, &r.best, divide).expect("an evaluation");
        println!(
            "dt {} s: fitness {}, upright {} s, distance {} m, mean speed {:.3} m/s, ended: {}",
            0.008 / divide,
            e.fitness,
            e.time,
            e.distance,
            e.distance / e.time.max(1e-9),
            e.ended
        );
    }
}

/// Prints the Markdown table of `runs` (one per job) and returns each
/// controller and optimiser's median best fitness curve, for the plot.
fn table(runs: &[Run], jobs: &[(Controller, OptimiserKind, u64)], budget: usize) -> Vec<Series> {
    let kinds = OptimiserKind::ALL;
    let controllers = [Controller::Fsm, Controller::Raibert];
    let early = 600.min(budget);
    println!("| controller | optimiser | evaluations to the first 20 s hop: median [Q1–Q3] (runs that found one) | best fitness at {early}: median [Q1–Q3] | at {budget}: median [Q1–Q3] | the best at 2 ms: runs upright 20 s, their median distance |");
    println!("|---|---|---|---|---|---|");
    let mut series = Vec::new();
    for (controller, kind) in controllers
        .iter()
        .flat_map(|c| kinds.iter().map(move |k| (*c, *k)))
    {
        let mine: Vec<&Run> = runs
            .iter()
            .zip(jobs)
            .filter(|(_, j)| j.0 == controller && j.1 == kind)
            .map(|(r, _)| r)
            .collect();
        let firsts: Vec<f64> = mine
            .iter()
            .filter_map(|r| {
                r.time
                    .iter()
                    .position(|t| *t >= 20.0)
                    .map(|i| (i + 1) as f64)
            })
            .collect();
        let at = |n: usize| -> Vec<f64> { mine.iter().map(|r| best_after(r, n)).collect() };
        let q3 = |v: &[f64], digits: usize| {
            format!(
                "{:.*} [{:.*}–{:.*}]",
                digits,
                quantile(v, 0.5),
                digits,
                quantile(v, 0.25),
                digits,
                quantile(v, 0.75)
            )
        };
        let first = if firsts.is_empty() {
            "never".to_string()
        } else {
            format!("{} ({} of {})", q3(&firsts, 0), firsts.len(), mine.len())
        };
        let fine: Vec<f64> = mine
            .par_iter()
            .filter_map(|r| at_quarter_step(controller, &r.best))
            .collect();
        let fine = if fine.is_empty() {
            "0".to_string()
        } else {
            format!(
                "{} of {}, {:.1} m",
                fine.len(),
                mine.len(),
                quantile(&fine, 0.5)
            )
        };
        println!(
            "| {} | {} | {first} | {} | {} | {fine} |",
            controller.name(),
            kind.name(),
            q3(&at(early), 1),
            q3(&at(budget), 1)
        );
        // Median best-so-far at 60 points along the budget.
        let points: Vec<(f64, f64)> = (1..=60)
            .map(|i| {
                let n = (budget * i / 60).max(1);
                (n as f64, quantile(&at(n), 0.5))
            })
            .collect();
        series.push(Series {
            label: format!(
                "{}, {} (median of {})",
                controller.name(),
                kind.name(),
                mine.len()
            ),
            points,
        });
    }
    series
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("one") {
        return one(&args[1..]);
    }
    let seeds: u64 = args.first().and_then(|s| s.parse().ok()).unwrap_or(20);
    let budget: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(6000);
    let plot = args.get(2).cloned();
    let kinds = OptimiserKind::ALL;
    let controllers = [Controller::Fsm, Controller::Raibert];
    let jobs: Vec<(Controller, OptimiserKind, u64)> = controllers
        .iter()
        .flat_map(|c| kinds.iter().map(move |k| (*c, *k)))
        .flat_map(|(c, k)| (1..=seeds).map(move |s| (c, k, s)))
        .collect();
    let start = std::time::Instant::now();
    let runs: Vec<Run> = jobs
        .par_iter()
        .map(|&(c, k, s)| run(c, k, s, budget))
        .collect();
    eprintln!(
        "{} runs of {budget} evaluations in {:.1} s",
        runs.len(),
        start.elapsed().as_secs_f64()
    );
    let series = table(&runs, &jobs, budget);
    if let Some(path) = plot {
        let png = step_plot_png(&Plot {
            title: format!("The roobot: median best fitness over {seeds} seeds, one lane each"),
            x_label: "evaluations".into(),
            y_label: "best fitness (time upright + 50 × distance)".into(),
            series,
            size: (900, 600),
        })
        .expect("a plot");
        std::fs::write(&path, png).expect("write the plot");
        eprintln!("wrote {path}");
    }
}
