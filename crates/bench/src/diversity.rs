//! `diversity` (on request; issue 40): quality-diversity search on the
//! roobot's map (`scenes/hop_map.toml`).
//!
//! - one generation of MAP-Elites (36 candidates from an archive grown for
//!   50 generations, seed 1) evaluated on one thread with the scene's
//!   measures and with its `[archive]` table removed, alternating: what
//!   computing the measures during the evaluation costs;
//! - adding that generation to the archive (statuses, thresholds, stats),
//!   against the time its evaluations took (goal: at most 1 %).

use crate::{measure, measure_pair, pool, Check, Row, Timing};
use animats_evolve::problem::{Outcome, Problem, SceneEvolution};
use animats_evolve::{Choices, Config, OptimiserKind, ProblemSpec, State};
use animats_scene::evaluate::SceneProblem;
use rayon::prelude::*;

const PATH: &str = "scenes/hop_map.toml";

fn row(variant: String, per: Timing, checks: Vec<Check>) -> Row {
    Row::per_item("diversity", variant, per, checks)
}

/// Runs the workload.
pub fn run(quick: bool, runs: usize) -> Result<Vec<Row>, String> {
    let runs = if quick { runs.min(5) } else { runs };
    let text = std::fs::read_to_string(PATH).map_err(|e| format!("{PATH}: {e}"))?;
    let one = pool(1)?;
    let spec = ProblemSpec {
        file: PATH.into(),
        text: text.clone(),
    };
    let config = Config::new(
        spec,
        &Choices {
            optimiser: Some(OptimiserKind::MapElites),
            // 50 to grow the archive, one more to time.
            generations: Some(51),
            ..Choices::default()
        },
    )?;
    let mut state = State::new(config)?;
    one.install(|| state.advance(50))?;
    let archive = state.archive().cloned().ok_or("no archive")?;
    let generation = state.ask()?;
    let genomes: Vec<Vec<f64>> = generation.genomes().map(<[f64]>::to_vec).collect();
    let n = genomes.len();
    if n == 0 {
        return Err("diversity: the run asked for no candidates".into());
    }
    let with = SceneEvolution(SceneProblem::parse(&text, PATH).map_err(|e| e.to_string())?);
    let start = text.find("[archive]").ok_or("no [archive] table")?;
    let bare =
        SceneEvolution(SceneProblem::parse(&text[..start], PATH).map_err(|e| e.to_string())?);
    let evaluate = |p: &SceneEvolution| -> Result<Vec<Outcome>, String> {
        one.install(|| genomes.par_iter().map(|g| p.evaluate(g)).collect())
    };
    let (tm, tb, outcomes, plain) = measure_pair(
        runs,
        Vec::new,
        |out| *out = evaluate(&with).unwrap_or_default(),
        Vec::new,
        |out| *out = evaluate(&bare).unwrap_or_default(),
    );
    let same = outcomes.len() == n
        && outcomes
            .iter()
            .zip(&plain)
            .all(|(a, b)| a.fitness.to_bits() == b.fitness.to_bits());
    let mut rows = vec![
        row(
            format!("{n} evaluations with 2 measures, 1 thr"),
            tm.divided(n as f64),
            vec![
                Check::info("evaluations per s", n as f64 / tm.median),
                Check::info("cost of the measures", tm.median / tb.median - 1.0),
            ],
        ),
        row(
            format!("{n} evaluations without [archive], 1 thr"),
            tb.divided(n as f64),
            vec![
                Check::info("evaluations per s", n as f64 / tb.median),
                Check::new(
                    "fitness equal bit for bit with and without measures",
                    same as u8 as f64,
                    1.0,
                    0.0,
                ),
            ],
        ),
    ];
    let candidates: Vec<animats_evolve::archive::Candidate> = genomes
        .iter()
        .zip(&outcomes)
        .map(|(g, o)| animats_evolve::archive::Candidate::new(g, o))
        .collect();
    let (ta, _) = measure(
        runs.max(20),
        || archive.clone(),
        |a| {
            a.add(&candidates);
        },
    );
    rows.push(row(
        format!("adding {n} to an archive of {} elites", archive.len()),
        ta.divided(n as f64),
        vec![Check::target_at_most(
            "share of the evaluations' time",
            ta.median / tm.median,
            0.01,
        )],
    ));
    Ok(rows)
}
