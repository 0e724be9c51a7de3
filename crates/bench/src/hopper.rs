//! `hopper`: the roobot's evolution workload (issue 3), the built-in
//! `scenes/hop_evolver.toml`. One 20 s fitness evaluation of the shipped
//! evolved gait (RK4, 8 ms, 2500 steps; the scene built afresh, as
//! evolution does), and the thesis's experiment: 6 lanes × 1000
//! generations from Appendix B's initial parameters (quick: 100
//! generations), on every core.

use crate::{measure, Check, Row, Timing};
use animats_evolve::{Config, State};
use animats_scene::evaluate::{Evaluation, SceneProblem};

/// Evaluations timed per run of the single-evaluation measurement.
const EVALS_PER_RUN: usize = 20;

/// Runs the workload: one row per measurement.
pub fn run(quick: bool, runs: usize) -> Result<Vec<Row>, String> {
    let params = animats_scene::params::load("evolved", None).map_err(|e| e.to_string())?;
    let problem = SceneProblem::parse(animats_scene::HOP_EVOLVER, animats_scene::HOP_EVOLVER_FILE)
        .map_err(|e| e.to_string())?;
    let (seconds, dt) = (problem.spec().duration, problem.fresh()?.dt);
    let (timing, last): (Timing, Option<Evaluation>) = measure(
        runs,
        || None,
        |out| {
            for _ in 0..EVALS_PER_RUN {
                *out = problem.evaluate(&params.0).ok();
            }
        },
    );
    let per_eval = timing.divided(EVALS_PER_RUN as f64);
    let e = last.ok_or("the evolved gait could not be evaluated")?;
    let steps = (seconds / dt).round() as usize;
    let eval_row = Row {
        workload: "hopper".into(),
        variant: "1 evaluation, 20 s, rk4".into(),
        particles: 5,
        springs: 4,
        steps,
        dt,
        evaluations: 4,
        pairs: 0,
        engine: per_eval.clone(),
        baseline: None,
        checks: vec![
            Check::new("time upright", e.time, 20.0, 0.0),
            Check::target("times real time", seconds / per_eval.median, 15e3),
        ],
    };

    let generations = if quick { 100 } else { 1000 };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    let config = Config::thesis(6, generations, 1);
    let evolved = config.problem.build()?;
    let (evo, state) = measure(
        runs,
        || State::new(config.clone()).expect("valid configuration"),
        |s| {
            // As `animats evolve` runs it: lanes that never wait for each
            // other, stopping only for a checkpoint every 5 s.
            while !s.done() {
                let begun = std::time::Instant::now();
                let more = || begun.elapsed().as_secs_f64() < 5.0;
                pool.install(|| s.advance_while(evolved.as_ref(), None, &more, &|_| ()))
                    .expect("evaluations succeed");
            }
        },
    );
    let stable = state
        .lanes
        .iter()
        .filter(|l| l.best.as_ref().is_some_and(|b| b.time >= 20.0))
        .count();
    let mut checks = vec![Check::info("lanes hopping 20 s", stable as f64)];
    if !quick {
        // The thesis experiment on this machine's cores (issue 13's goal).
        checks.push(Check::target_at_most("wall time, s", evo.median, 3.0));
    }
    let evo_row = Row {
        workload: "hopper".into(),
        variant: format!("evolve 6 lanes x {generations} gens, {threads} thr"),
        particles: 5,
        springs: 4,
        steps: 6 * generations as usize * steps,
        dt,
        evaluations: 4,
        pairs: 0,
        engine: evo,
        baseline: None,
        checks,
    };
    Ok(vec![eval_row, evo_row])
}
