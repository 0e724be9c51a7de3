//! `bodies` (on request; issue 39): evolving bodies, for the land and the
//! water tasks (`scenes/bodies_walk.toml`, `scenes/bodies_swim.toml`, and
//! `swim-rods`: `scenes/bodies_swim.toml` with `[fluid] springs` as
//! `scenes/bodies_swim_rods.toml` gives it, so the same bodies at the same
//! step with drag across their springs, whose row against swim's is what
//! that drag costs). A
//! population of 16 checked random bodies (the body GA's first generation,
//! seed 1):
//!
//! - evaluated on one thread and on two, alternating (bodies a second);
//! - the time the body GA takes to make and check the next generation
//!   (mutation, crossover, development, every check and the 0.5 s settle,
//!   retries included), on one thread, against the time that generation's
//!   evaluations take on one thread (goal: at most 5 %);
//! - the same population without self-contact, and without robust
//!   evaluation (one run at the scene's step instead of two), on one
//!   thread: what each costs.

use crate::{measure, measure_pair, pool, Check, Row, Timing};
use animats_evolve::optimiser::body_ga::BodyGa;
use animats_evolve::problem::BodyEvolution;
use animats_scene::morphology::MorphologyProblem;
use rayon::prelude::*;

/// Bodies a timed run evaluates.
const POPULATION: usize = 16;

/// Runs the workload for both tasks.
pub fn run(quick: bool, runs: usize) -> Result<Vec<Row>, String> {
    let runs = if quick { runs.min(5) } else { runs };
    let mut rows = Vec::new();
    let read = |path: &str| std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"));
    let swim = read("scenes/bodies_swim.toml")?;
    let still = "drag_coefficient = 0.47\n";
    if !swim.contains(still) {
        return Err(format!(
            "scenes/bodies_swim.toml: no `{}` line to add drag across springs after",
            still.trim()
        ));
    }
    let rods = swim.replacen(
        still,
        &format!("{still}springs = {{ diameter = 0.02 }}\n"),
        1,
    );
    for (name, path, text) in [
        (
            "walk",
            "scenes/bodies_walk.toml",
            read("scenes/bodies_walk.toml")?,
        ),
        ("swim", "scenes/bodies_swim.toml", swim),
        (
            "swim-rods",
            "scenes/bodies_swim.toml with [fluid] springs",
            rods,
        ),
    ] {
        rows.extend(task(name, path, &text, runs)?);
    }
    Ok(rows)
}

fn problem(text: &str, file: &str) -> Result<BodyEvolution, String> {
    Ok(BodyEvolution(
        MorphologyProblem::parse(text, file).map_err(|e| e.to_string())?,
    ))
}

fn evaluate_all(p: &BodyEvolution, bodies: &[Vec<f64>], threads: &rayon::ThreadPool) -> Vec<f64> {
    threads.install(|| {
        bodies
            .par_iter()
            .map(|g| p.0.evaluate(g).map_or(f64::NAN, |e| e.fitness))
            .collect()
    })
}

fn row(name: &str, variant: String, per: Timing, checks: Vec<Check>) -> Row {
    Row::per_item("bodies", format!("{name}: {variant}"), per, checks)
}

fn task(name: &str, path: &str, text: &str, runs: usize) -> Result<Vec<Row>, String> {
    let p = problem(text, path)?;
    let (one, two) = (pool(1)?, pool(2)?);
    // The first generation: 16 checked random bodies.
    let mut ga = BodyGa::new(1, 0, Some(POPULATION));
    let bodies = one.install(|| ga.ask(&p));
    let (t1, t2, f1, f2) = measure_pair(
        runs,
        Vec::new,
        |out| *out = evaluate_all(&p, &bodies, &one),
        Vec::new,
        |out| *out = evaluate_all(&p, &bodies, &two),
    );
    let same = f1.iter().zip(&f2).all(|(a, b)| a.to_bits() == b.to_bits());
    let mut rows = Vec::new();
    let speedup = t1.median / t2.median;
    for (threads, t) in [(1, &t1), (2, &t2)] {
        let per = t.divided(POPULATION as f64);
        let mut checks = vec![Check::info("bodies evaluated per s", 1.0 / per.median)];
        if threads == 2 {
            checks.push(Check::target("speed-up on 2 threads", speedup, 1.8));
            checks.push(Check::new(
                "fitness equal bit for bit on 1 and 2 threads",
                same as u8 as f64,
                1.0,
                0.0,
            ));
        }
        rows.push(row(
            name,
            format!("{POPULATION} random bodies evaluated, {threads} thr"),
            per,
            checks,
        ));
    }
    // The next generation made and checked, against its evaluations.
    ga.tell(&f1)?;
    let (tv, children) = measure(
        runs,
        || ga.clone(),
        |g| {
            one.install(|| g.ask(&p));
        },
    );
    let made = children.refused_total() - ga.refused_total();
    let share = tv.median / t1.median;
    rows.push(row(
        name,
        format!("making and checking {POPULATION} children, 1 thr"),
        tv.divided(POPULATION as f64),
        vec![
            Check::target_at_most("share of the evaluations' time", share, 0.05),
            Check::info("refusals on the way", made as f64),
        ],
    ));
    // What self-contact and robust evaluation cost.
    for (what, edited) in [
        (
            "without self-contact",
            text.replace("[morphology]\n", "[morphology]\nself_contact = false\n"),
        ),
        (
            "without robust evaluation",
            text.replace("[evolve]\n", "[evolve]\nrobust = false\n"),
        ),
    ] {
        let q = problem(&edited, path)?;
        // The scene as shipped and as edited, alternating.
        let (tw, tq, _, _) = measure_pair(
            runs,
            || (),
            |_| {
                evaluate_all(&p, &bodies, &one);
            },
            || (),
            |_| {
                evaluate_all(&q, &bodies, &one);
            },
        );
        rows.push(row(
            name,
            format!("{POPULATION} bodies {what}, 1 thr"),
            tq.divided(POPULATION as f64),
            vec![Check::info(
                "time with it over time without",
                tw.median / tq.median,
            )],
        ));
    }
    Ok(rows)
}
