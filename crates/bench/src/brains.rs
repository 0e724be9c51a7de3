//! `brains`: evolving a scene's brain (issue 10). For the soft walker and
//! the thesis's quadruped: one population's evaluations (around the evolved
//! brain) on one thread and on two, alternating in one run (evaluations per second, and the parallel
//! efficiency); and CMA-ES's own time per generation (ask and tell) against
//! the time its evaluations take.

use crate::{measure, measure_pair, pool, Check, Row};
use animats_evolve::optimiser::{AnyOptimiser, Optimiser, OptimiserKind, Setup};
use animats_scene::evaluate::SceneProblem;
use rayon::prelude::*;

/// Genomes evaluated per timed run: a population of two CMA-ES
/// generations' size, so that two threads get equal shares.
const POPULATION: usize = 16;

/// Runs the workload for the evolved walker and quadruped
/// (`scenes/walker_evolved.toml`, `scenes/quadruped3_walk.toml`).
pub fn run(quick: bool, runs: usize) -> Result<Vec<Row>, String> {
    let runs = if quick { runs.min(5) } else { runs };
    let mut rows = Vec::new();
    for (name, path) in [
        ("walker", "scenes/walker_evolved.toml"),
        ("quadruped3", "scenes/quadruped3_walk.toml"),
    ] {
        let problem = SceneProblem::load(std::path::Path::new(path)).map_err(|e| e.to_string())?;
        let bounds = problem.bounds();
        let setup = Setup {
            kind: OptimiserKind::CmaEs,
            start: problem.start().to_vec(),
            bounds: Some(animats_evolve::optimiser::Bounds {
                lo: bounds.iter().map(|b| b.0).collect(),
                hi: bounds.iter().map(|b| b.1).collect(),
            }),
            population: Some(POPULATION),
            seed: 1,
            lane: 0,
            sigma: Some(0.02),
            restarts: 0,
        };
        let (evaluations, per_evaluation) = evaluation_rows(name, &problem, &setup, runs)?;
        rows.extend(evaluations);
        rows.push(cma_es_row(name, &problem, &setup, runs, per_evaluation)?);
    }
    Ok(rows)
}

/// One population's evaluations on one thread and on two: a row each;
/// and the time one evaluation takes on two threads, s.
fn evaluation_rows(
    name: &str,
    problem: &SceneProblem,
    setup: &Setup,
    runs: usize,
) -> Result<(Vec<Row>, f64), String> {
    let (one, two) = (pool(1)?, pool(2)?);
    // A population as CMA-ES asks it late in a run, around the evolved
    // brain: nearly every evaluation runs its full length.
    let genomes = AnyOptimiser::new(setup)?.ask();
    let evaluate_all = |p: &rayon::ThreadPool| -> Vec<f64> {
        p.install(|| {
            genomes
                .par_iter()
                .map(|g| problem.evaluate(g).map_or(f64::NAN, |e| e.fitness))
                .collect()
        })
    };
    let (t1, t2, f1, f2) = measure_pair(
        runs,
        Vec::new,
        |out| *out = evaluate_all(&one),
        Vec::new,
        |out| *out = evaluate_all(&two),
    );
    let same = f1.iter().zip(&f2).all(|(a, b)| a.to_bits() == b.to_bits());
    let scene = problem.scene(problem.start())?;
    let spec = scene.evolve.as_ref().ok_or("no [evolve]")?;
    let steps = (spec.duration / scene.dt).round() as usize;
    let (particles, springs) = (scene.world.len(), scene.world.forces().springs.len());
    let efficiency = t1.median / t2.median;
    let mut rows = Vec::new();
    for (threads, t) in [(1, &t1), (2, &t2)] {
        let per = t.divided(POPULATION as f64);
        let mut checks = vec![Check::info("evaluations per s", 1.0 / per.median)];
        if threads == 2 {
            checks.push(Check::target("speed-up on 2 threads", efficiency, 1.8));
            let full = f2.iter().filter(|f| f.is_finite()).count();
            checks.push(Check::info("evaluations in the population", full as f64));
            checks.push(Check::new(
                "fitness equal bit for bit on 1 and 2 threads",
                same as u8 as f64,
                1.0,
                0.0,
            ));
        }
        rows.push(Row {
            workload: "brains".into(),
            variant: format!("{name}: {POPULATION} evaluations, {threads} thr"),
            particles,
            springs,
            steps,
            dt: scene.dt,
            evaluations: 1,
            pairs: 0,
            engine: per,
            baseline: None,
            checks,
        });
    }
    Ok((rows, t2.divided(POPULATION as f64).median))
}

/// CMA-ES's own time: ask and tell for one generation of its default
/// population, with the fitness already known, against the time its
/// evaluations take (`per_evaluation`, s).
fn cma_es_row(
    name: &str,
    problem: &SceneProblem,
    setup: &Setup,
    runs: usize,
    per_evaluation: f64,
) -> Result<Row, String> {
    let scene = problem.scene(problem.start())?;
    let mut default_setup = setup.clone();
    default_setup.population = None;
    let lambda = AnyOptimiser::new(&default_setup)?.ask().len();
    let generations = 200;
    let (tc, _) = measure(
        runs,
        || AnyOptimiser::new(&default_setup).expect("a valid setup"),
        |o| {
            for _ in 0..generations {
                let pop = o.ask();
                let f: Vec<f64> = pop
                    .iter()
                    .map(|g| -g.iter().map(|x| x * x).sum::<f64>())
                    .collect();
                o.tell(&f).expect("a population's fitness");
            }
        },
    );
    let per_generation = tc.divided(generations as f64);
    let evaluations = lambda as f64 * per_evaluation;
    Ok(Row {
        workload: "brains".into(),
        variant: format!(
            "{name}: cma-es ask+tell, {} genes, λ {lambda}",
            setup.start.len()
        ),
        particles: scene.world.len(),
        springs: scene.world.forces().springs.len(),
        steps: 0,
        dt: scene.dt,
        evaluations: 0,
        pairs: 0,
        engine: per_generation.clone(),
        baseline: None,
        checks: vec![Check::info(
            "share of a generation (2 thr)",
            per_generation.median / (per_generation.median + evaluations),
        )],
    })
}
