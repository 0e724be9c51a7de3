//! The checks a run's winner must pass before it is believed (issue 39,
//! docs/BODIES.md, Honest evaluation), and `checked.toml`: the best
//! candidate of a run that keeps at least [`BELIEVED`] of its logged
//! fitness at a quarter of the step, with its own integrator and with
//! another (`animats_scene::evaluate::checks_finer`). The best itself, or
//! where it fails, the first that passes of the next [`CANDIDATES`] (other
//! lanes' bests and the archive's elites, best first).
//!
//! `animats evolve` and Python's `Evolution.check` (and so
//! `python -m animats.evolve`) both print [`Report::lines`] and write
//! [`Report::checked_toml`].

use std::path::Path;

use animats_engine::IntegratorKind;
use animats_scene::evaluate::Evaluation;

use crate::archive::Elite;
use crate::run::State;

/// The share of its logged fitness a candidate must keep in each check
/// at a quarter of the step to be believed (issue 39's rule).
pub const BELIEVED: f64 = 0.8;

/// How many candidates after the best the checks try, best first, when
/// the best fails them.
pub const CANDIDATES: usize = 16;

/// One check of a candidate: the integrator, the step, the evaluation
/// and the share of the logged fitness it kept (`None` where the logged
/// fitness is not above 0: no share to judge).
#[derive(Debug, Clone)]
pub struct Check {
    /// The integrator of this check.
    pub integrator: IntegratorKind,
    /// Its step, s (a quarter of the scene's).
    pub dt: f64,
    /// The scene's `[evolve]` evaluation at that step.
    pub evaluation: Evaluation,
    /// `evaluation.fitness` over the logged fitness.
    pub share: Option<f64>,
}

/// The candidate `checked.toml` holds.
#[derive(Debug, Clone)]
pub struct Checked {
    /// What it is: `the best`, `lane 2`, `elite 37`.
    pub label: String,
    /// Where `animats evolve` writes its scene: `best.toml`,
    /// `lanes/2.toml`, `elites/37.toml`.
    pub file: String,
    /// Its logged fitness.
    pub fitness: f64,
    /// The share of it each check kept.
    pub shares: Vec<Option<f64>>,
    /// Its whole scene.
    pub toml: String,
}

/// What the checks found.
#[derive(Debug, Clone)]
pub enum Verdict {
    /// The best could not be run at a quarter of the step (the message).
    NotRun(String),
    /// A candidate passed both checks.
    Checked(Checked),
    /// The best failed and its fitness is not above 0: nothing else tried.
    NotPositive,
    /// The best failed and the run has no other candidate.
    NoOther,
    /// The best failed and so did the next this many.
    NoneOf(usize),
}

/// The checks of a run's best, and the candidate `checked.toml` holds.
#[derive(Debug, Clone)]
pub struct Report {
    /// The best's logged fitness.
    pub fitness: f64,
    /// The best's checks (empty where it could not be run).
    pub best: Vec<Check>,
    /// What the checks found.
    pub verdict: Verdict,
}

impl Report {
    /// `checked.toml`'s text: a comment naming the candidate and what it
    /// kept, then its scene. `None` where no candidate passed.
    pub fn checked_toml(&self) -> Option<String> {
        let Verdict::Checked(c) = &self.verdict else {
            return None;
        };
        Some(format!(
            "# checked.toml: the best of this run that keeps at least 80 % of its\n# fitness at a quarter of the step with its own integrator and with\n# another ({}: {}); docs/BODIES.md, Honest evaluation.\n{}",
            c.label,
            shares_text(&c.shares),
            c.toml
        ))
    }

    /// The lines that tell what the checks found, `dir` being where
    /// `checked.toml` was written (`None`: nowhere, and no line says so).
    pub fn lines(&self, dir: Option<&Path>) -> Vec<String> {
        let logged = self.fitness;
        let mut out = Vec::new();
        for c in &self.best {
            let kept = match c.share {
                Some(share) => format!(
                    " ({:.1} % of {logged}){}",
                    100.0 * share,
                    if share.is_nan() || share < BELIEVED {
                        ": under 80 %, not to be believed yet (docs/BODIES.md, Honest evaluation)"
                    } else {
                        ""
                    }
                ),
                None => String::new(),
            };
            out.push(format!(
                "check: the best at a quarter of the step ({} s) with {}: fitness {}, distance {} m{kept}",
                c.dt,
                c.integrator.name(),
                c.evaluation.fitness,
                c.evaluation.distance
            ));
        }
        match &self.verdict {
            Verdict::NotRun(e) => out.push(format!(
                "check: the best at a quarter of the step could not be run: {e}"
            )),
            Verdict::Checked(c) if c.label != BEST => out.push(format!(
                "check: the best that keeps 80 % in each check is {} (fitness {}; {}){}",
                c.label,
                c.fitness,
                shares_text(&c.shares),
                dir.map_or(String::new(), |d| format!(
                    ": wrote {}",
                    d.join("checked.toml").display()
                ))
            )),
            Verdict::Checked(_) | Verdict::NotPositive => {}
            Verdict::NoOther => {
                out.push("check: the run has no other candidate to try: no checked.toml".into())
            }
            Verdict::NoneOf(n) => out.push(format!(
                "check: none of the {n} next best keeps 80 % in each check either: no checked.toml"
            )),
        }
        out
    }
}

/// The best's label.
const BEST: &str = "the best";

/// A run's candidate: its label, file, logged fitness and where its scene
/// comes from (made only for the candidates tried).
struct Candidate<'a> {
    label: String,
    file: String,
    fitness: f64,
    source: Source<'a>,
}

/// Where a candidate's scene comes from.
enum Source<'a> {
    Best,
    Lane(usize),
    Elite(&'a Elite),
}

impl Candidate<'_> {
    fn text(&self, state: &State) -> Result<String, String> {
        match &self.source {
            Source::Best => state
                .best_toml()?
                .ok_or_else(|| "the run has no best yet".into()),
            Source::Lane(l) => state
                .lane_toml(*l)?
                .ok_or_else(|| format!("lane {l} has no best")),
            Source::Elite(e) => state.elite_toml(e),
        }
    }

    /// Each check of `text`, this candidate's scene, with the share of the
    /// logged fitness it kept.
    fn checks(&self, text: &str) -> Result<Vec<Check>, String> {
        let runs = animats_scene::evaluate::checks_finer(|| {
            animats_scene::parse(text, &self.file).map_err(|e| e.to_string())
        })?;
        Ok(runs
            .into_iter()
            .map(|(integrator, dt, evaluation)| Check {
                integrator,
                dt,
                share: (self.fitness > 0.0).then(|| evaluation.fitness / self.fitness),
                evaluation,
            })
            .collect())
    }

    fn checked(&self, toml: String, checks: &[Check]) -> Checked {
        Checked {
            label: self.label.clone(),
            file: self.file.clone(),
            fitness: self.fitness,
            shares: checks.iter().map(|c| c.share).collect(),
            toml,
        }
    }
}

/// The shares of the logged fitness the checks kept, as `98.1 % and
/// 99.4 %`.
fn shares_text(shares: &[Option<f64>]) -> String {
    let kept: Vec<String> = shares
        .iter()
        .map(|s| format!("{:.1} %", 100.0 * s.unwrap_or(f64::NAN)))
        .collect();
    kept.join(" and ")
}

/// Whether every check kept at least [`BELIEVED`] of the logged fitness.
fn believed(checks: &[Check]) -> bool {
    !checks.is_empty()
        && checks
            .iter()
            .all(|c| c.share.is_some_and(|s| s >= BELIEVED))
}

/// The run's other candidates, best first: each other lane's best and
/// each elite of a quality-diversity archive, each genome once and not
/// the best's.
fn other_candidates<'a>(state: &'a State, best: &'a [f64]) -> Vec<Candidate<'a>> {
    let mut out = Vec::new();
    let mut seen: Vec<&[f64]> = vec![best];
    for l in &state.lanes {
        let Some(b) = &l.best else { continue };
        if seen.contains(&b.genome.as_slice()) {
            continue;
        }
        seen.push(&b.genome);
        out.push(Candidate {
            label: format!("lane {}", l.lane),
            file: format!("lanes/{}.toml", l.lane),
            fitness: b.fitness,
            source: Source::Lane(l.lane),
        });
    }
    for e in state.archive().map_or(&[][..], |a| a.elites()) {
        if seen.contains(&e.genome.as_slice()) {
            continue;
        }
        out.push(Candidate {
            label: format!("elite {}", e.index),
            file: format!("elites/{}.toml", e.index),
            fitness: e.objective,
            source: Source::Elite(e),
        });
    }
    // Best first; NaN last; equal fitness in the order found.
    let key = |f: f64| if f.is_nan() { f64::NEG_INFINITY } else { f };
    out.sort_by(|a, b| key(b.fitness).total_cmp(&key(a.fitness)));
    out
}

/// How many candidates are checked at once: half the threads of the
/// caller's rayon pool (each check is two runs side by side), at least one.
fn round() -> usize {
    (rayon::current_num_threads() / 2).max(1)
}

/// The first of `candidates`, in order, that keeps [`BELIEVED`] in each
/// check, all of them checked side by side. A candidate whose scene cannot
/// be made or run does not pass.
fn first_passing(candidates: &[Candidate], state: &State) -> Option<Checked> {
    use rayon::prelude::*;
    let found: Vec<Option<(String, Vec<Check>)>> = candidates
        .par_iter()
        .map(|c| {
            let text = c.text(state).ok()?;
            let checks = c.checks(&text).ok()?;
            Some((text, checks))
        })
        .collect();
    candidates.iter().zip(found).find_map(|(c, f)| {
        f.filter(|(_, kept)| believed(kept))
            .map(|(t, k)| c.checked(t, &k))
    })
}

/// Checks `state`'s best, and where it fails, its next [`CANDIDATES`] best
/// until one passes. `None` where the run has no best yet; an error where
/// the best's scene cannot be written out.
///
/// On four threads or more the candidates are checked a round at a time,
/// half as many as threads, the first round beside the best's own checks:
/// at the end of a run on many cores the checks are all there is to do,
/// and a best that fails no longer leaves the cores waiting on each next
/// candidate in turn. The verdict is the first that passes, best first,
/// whatever the thread count.
pub fn check(state: &State) -> Result<Option<Report>, String> {
    let Some(best) = state.best_lane().and_then(|l| l.best.as_ref()) else {
        return Ok(None);
    };
    let first = Candidate {
        label: BEST.into(),
        file: "best.toml".into(),
        fitness: best.fitness,
        source: Source::Best,
    };
    let fitness = best.fitness;
    let report = |best: Vec<Check>, verdict| {
        Ok(Some(Report {
            fitness,
            best,
            verdict,
        }))
    };
    let text = first.text(state)?;
    // The others are tried only where the best fails with a fitness above 0.
    let positive = !best.fitness.is_nan() && best.fitness > 0.0;
    let mut others = if positive {
        other_candidates(state, &best.genome)
    } else {
        Vec::new()
    };
    others.truncate(CANDIDATES);
    let round = round();
    let ahead = (round - 1).min(others.len());
    let (checks, first_round) = rayon::join(
        || first.checks(&text),
        || first_passing(&others[..ahead], state),
    );
    let checks = match checks {
        Ok(c) => c,
        Err(e) => return report(Vec::new(), Verdict::NotRun(e)),
    };
    if believed(&checks) {
        let checked = first.checked(text, &checks);
        return report(checks, Verdict::Checked(checked));
    }
    if !positive {
        return report(checks, Verdict::NotPositive);
    }
    let passed = first_round.or_else(|| {
        others[ahead..]
            .chunks(round)
            .find_map(|c| first_passing(c, state))
    });
    if let Some(checked) = passed {
        return report(checks, Verdict::Checked(checked));
    }
    let tried = others.len();
    report(
        checks,
        if tried == 0 {
            Verdict::NoOther
        } else {
            Verdict::NoneOf(tried)
        },
    )
}
