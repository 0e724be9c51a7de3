//! The evolver: Appendix B's scheme, reproducibility, checkpoints, and the
//! thesis's result (§5.4) in a smaller run.

use animats_creatures::random::Random;
use animats_evolve::hill_climber::HillClimber;
use animats_evolve::optimiser::Optimiser;
use animats_evolve::{checkpoint, Config, State};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

fn run(config: Config, threads: usize, batch: u64) -> State {
    let mut s = State::new(config).unwrap();
    let p = pool(threads);
    while !s.done() {
        p.install(|| s.advance(batch)).unwrap();
    }
    s
}

#[test]
fn mutation_follows_appendix_b() {
    // 1 + round(3u) mutations: 1 and 4 with probability 1/6, 2 and 3 with 1/3;
    // each changes a parameter by p × 0.5 (lane + 1) × (u − 0.5).
    let n = 60_000;
    let mut counts = [0usize; 5];
    for lane in [0usize, 3] {
        let bound = 0.25 * (lane as f64 + 1.0);
        let start = vec![1.0; 14];
        let mut c = HillClimber::new(start.clone(), lane, 9);
        assert_eq!(
            c.ask(),
            vec![start.clone()],
            "the first candidate is the start itself"
        );
        c.tell(&[1.0]).unwrap();
        let mut rng = Random::for_evaluation(9, lane, 0);
        let (mut singles, mut within, mut largest) = (0, 0, 0.0f64);
        for _ in 0..n {
            let child = c.mutate(&start, &mut rng);
            let changed = child.iter().filter(|x| **x != 1.0).count();
            assert!((1..=4).contains(&changed));
            if lane == 0 {
                counts[changed] += 1;
            }
            // A parameter picked repeatedly compounds, at most four times.
            assert!(child
                .iter()
                .all(|x| (x - 1.0).abs() <= (1.0 + bound).powi(4) - 1.0 + 1e-12));
            if changed == 1 {
                let d = (child.iter().find(|x| **x != 1.0).unwrap() - 1.0).abs();
                singles += 1;
                within += (d <= bound) as usize;
                largest = largest.max(d.min(bound));
            }
        }
        // Most single changes are one mutation, uniform in ±bound; only the
        // few repeated picks of one parameter go beyond.
        assert!(
            within as f64 / singles as f64 > 0.8,
            "lane {lane}: {within}/{singles} within ±{bound}"
        );
        assert!(
            largest > 0.99 * bound,
            "lane {lane}: mutations reach ±{largest}, expected ±{bound}"
        );
    }
    // Distinct parameters changed: 1 mutation always changes 1; k mutations
    // change fewer when they repeat a parameter. P(1 changed) = 1/6 + (1/3)(1/14)
    // + (1/3)(1/14²) + (1/6)(1/14³) ≈ 0.1927; sampling sd ≈ 0.0016.
    let p1 = counts[1] as f64 / n as f64;
    assert!(
        (p1 - 0.1927).abs() < 0.01,
        "P(one parameter changed) = {p1}"
    );
    let p4 = counts[4] as f64 / n as f64;
    let expected4 = (1.0 / 6.0) * (13.0 * 12.0 * 11.0) / (14.0f64.powi(3));
    assert!(
        (p4 - expected4).abs() < 0.01,
        "P(four changed) = {p4}, expected {expected4}"
    );
}

#[test]
fn the_same_seed_gives_the_same_log_whatever_the_threads_and_batches() {
    let config = Config::thesis(4, 30, 7);
    let a = run(config.clone(), 1, 30);
    let b = run(config.clone(), 2, 7);
    let c = run(config, 3, 1);
    assert_eq!(a.log_csv(), b.log_csv());
    assert_eq!(a.log_csv(), c.log_csv());
    assert_eq!(a, b);
    assert!(
        a.log.len() >= 4,
        "every lane logs at least its first generation"
    );
    // A different seed gives a different run.
    let d = run(Config::thesis(4, 30, 8), 2, 10);
    assert_ne!(a.log_csv(), d.log_csv());
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("animats-evolve-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_checkpointed_and_resumed_run_equals_one_never_stopped() {
    let config = Config::thesis(3, 40, 11);
    let whole = run(config.clone(), 2, 10);
    let dir = scratch("resume");
    let path = dir.join("checkpoint.json");
    let mut part = State::new(config).unwrap();
    let p = pool(2);
    p.install(|| part.advance(13)).unwrap();
    checkpoint::save(&path, &part).unwrap();
    drop(part);
    let mut resumed = checkpoint::load(&path).unwrap();
    while !resumed.done() {
        p.install(|| resumed.advance(9)).unwrap();
    }
    assert_eq!(resumed.log_csv(), whole.log_csv());
    assert_eq!(resumed, whole);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn corrupt_checkpoints_are_refused() {
    let dir = scratch("corrupt");
    let path = dir.join("checkpoint.json");
    let mut s = State::new(Config::thesis(2, 5, 3)).unwrap();
    s.advance(3).unwrap();
    checkpoint::save(&path, &s).unwrap();
    assert_eq!(checkpoint::load(&path).unwrap(), s);
    let good = std::fs::read_to_string(&path).unwrap();

    // One digit changed in the body.
    let i = good.rfind("\"evaluations\":").unwrap() + "\"evaluations\":".len();
    let mut flipped = good.clone().into_bytes();
    flipped[i] = if flipped[i] == b'9' { b'8' } else { b'9' };
    std::fs::write(&path, &flipped).unwrap();
    let e = checkpoint::load(&path).unwrap_err();
    assert!(e.contains("corrupt"), "{e}");

    // Truncated.
    std::fs::write(&path, &good[..good.len() / 2]).unwrap();
    assert!(checkpoint::load(&path).unwrap_err().contains("corrupt"));

    // Not a checkpoint at all, or empty.
    std::fs::write(&path, "hello\nworld\n").unwrap();
    assert!(checkpoint::load(&path)
        .unwrap_err()
        .contains("not an animats checkpoint"));
    std::fs::write(&path, "").unwrap();
    assert!(checkpoint::load(&path).is_err());
    // Missing.
    assert!(checkpoint::load(&dir.join("nope.json"))
        .unwrap_err()
        .contains("cannot read"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `state` as a checkpoint after `edit` of its JSON, written with its
/// checksum made again (as a hand edit or another program could): what
/// loading it says.
fn load_edited(
    state: &State,
    path: &std::path::Path,
    edit: &dyn Fn(&mut serde_json::Value),
) -> Result<State, String> {
    let mut v = serde_json::to_value(state).unwrap();
    edit(&mut v);
    let edited: State = serde_json::from_value(v).unwrap();
    checkpoint::save(path, &edited).unwrap();
    checkpoint::load(path)
}

/// An edit: the number at `pointer` set to `to`.
fn set(pointer: &'static str, to: serde_json::Value) -> Box<dyn Fn(&mut serde_json::Value)> {
    Box::new(move |v| *v.pointer_mut(pointer).unwrap() = to.clone())
}

/// An edit: the last element of the array at `pointer` left out.
fn shorten(pointer: &'static str) -> Box<dyn Fn(&mut serde_json::Value)> {
    Box::new(move |v| {
        v.pointer_mut(pointer)
            .unwrap()
            .as_array_mut()
            .unwrap()
            .pop();
    })
}

/// A checkpoint whose optimiser was edited into a state its run could not
/// have made (found by fuzzing: a population of 2^63 or a vector one short
/// panicked part way through the next generation) is refused as it loads,
/// naming the lane and the part, for the hill climber, the GA and CMA-ES;
/// untouched, each loads as it was saved.
#[test]
fn an_edited_checkpoint_is_refused_unless_its_run_could_have_made_it() {
    use animats_evolve::{Choices, OptimiserKind, ProblemSpec};
    use serde_json::json;
    let dir = scratch("edited");
    let path = dir.join("checkpoint.json");
    type Edits = Vec<(Box<dyn Fn(&mut serde_json::Value)>, &'static str)>;
    let cases: Vec<(OptimiserKind, Edits)> = vec![
        (
            OptimiserKind::HillClimber,
            vec![
                (
                    set("/lanes/0/optimiser/population", json!(1u64 << 63)),
                    "lane 0's optimiser: its population",
                ),
                (
                    set("/lanes/1/optimiser/start/0", json!(7.0)),
                    "lane 1's optimiser: its start",
                ),
                (
                    set("/lanes/1/optimiser/best/genome", json!([1.0])),
                    "lane 1's optimiser: the best has 1 genes, not 14",
                ),
                (
                    set("/lanes/0/best/genome", json!([1.0, f64::MAX])),
                    "lane 0: its best has 2 genes, not 14",
                ),
            ],
        ),
        (
            OptimiserKind::Ga,
            vec![
                (
                    set("/lanes/0/optimiser/size", json!(1u64 << 63)),
                    "lane 0's optimiser: its population's size",
                ),
                (
                    shorten("/lanes/1/optimiser/fitness"),
                    "lane 1's optimiser: a population of 32 with 31 fitnesses",
                ),
                (
                    set("/lanes/0/optimiser/bounds/hi/0", json!(-1.0)),
                    "lane 0's optimiser: its bounds",
                ),
            ],
        ),
        (
            OptimiserKind::CmaEs,
            vec![
                (
                    shorten("/lanes/0/optimiser/d"),
                    "lane 0's optimiser: its axes' lengths: 13 numbers, not 14",
                ),
                (
                    set("/lanes/1/optimiser/sigma", json!(-1.0)),
                    "lane 1's optimiser: its σ: a number that is not finite and above 0",
                ),
                (
                    set("/lanes/0/optimiser/lambda", json!(12)),
                    "lane 0's optimiser: its population",
                ),
                (
                    set("/lanes/0/optimiser/restarts_done", json!(40)),
                    "lane 0's optimiser: its restarts",
                ),
                (
                    set("/lanes/1/optimiser/pending", json!([[1.0]])),
                    "lane 1's optimiser: 1 candidates pending in a population of 11",
                ),
            ],
        ),
    ];
    for (kind, edits) in cases {
        let choices = Choices {
            lanes: Some(2),
            generations: Some(3),
            seed: Some(5),
            optimiser: Some(kind),
            ..Choices::default()
        };
        let config = Config::new(ProblemSpec::thesis(), &choices).unwrap();
        let mut s = State::new(config).unwrap();
        pool(2).install(|| s.advance(2)).unwrap();
        assert_eq!(load_edited(&s, &path, &|_| {}).unwrap(), s, "{kind:?}");
        for (edit, expected) in edits {
            match load_edited(&s, &path, &*edit) {
                Ok(_) => panic!("{kind:?}: an edit that should say \"{expected}\" loaded"),
                Err(e) => assert!(
                    e.contains("the checkpoint is inconsistent") && e.contains(expected),
                    "{kind:?}: {e}"
                ),
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The thesis's result (§5.4) in a run small enough for CI: with 6 lanes
/// and 100 generations, at least 4 of 6 lanes evolve a stable hop (20 s
/// upright) — for each of three seeds — and a longer run keeps improving.
/// The full 1000-generation runs are in docs/ROOBOT.md.
#[test]
fn stable_hopping_evolves_within_100_generations_in_most_lanes() {
    for seed in 1..=3 {
        let s = run(Config::thesis(6, 100, seed), 2, 25);
        let stable = s
            .lanes
            .iter()
            .filter(|l| l.best.as_ref().unwrap().time >= 20.0)
            .count();
        let best: Vec<f64> = s
            .lanes
            .iter()
            .map(|l| l.best.as_ref().unwrap().fitness)
            .collect();
        println!("seed {seed}: {stable}/6 lanes stable, best {best:.1?}");
        assert!(
            stable >= 4,
            "seed {seed}: only {stable} of 6 lanes hop for 20 s"
        );
        // Every lane started from Appendix B's parameters, which fall.
        assert!(s
            .log
            .iter()
            .filter(|r| r.generation == 1)
            .all(|r| r.time < 20.0));
    }
}

#[test]
fn fitness_keeps_rising_after_stable_hopping_is_found() {
    let mut s = State::new(Config::thesis(6, 100, 1)).unwrap();
    let p = pool(2);
    while !s.done() {
        p.install(|| s.advance(25)).unwrap();
    }
    let at_100: Vec<f64> = s
        .lanes
        .iter()
        .map(|l| l.best.as_ref().unwrap().fitness)
        .collect();
    s.config.generations = 300;
    while !s.done() {
        p.install(|| s.advance(25)).unwrap();
    }
    let at_300: Vec<f64> = s
        .lanes
        .iter()
        .map(|l| l.best.as_ref().unwrap().fitness)
        .collect();
    let higher = at_100.iter().zip(&at_300).filter(|(a, b)| b > a).count();
    assert!(
        higher >= 5,
        "only {higher} of 6 lanes improved between generations 100 and 300"
    );
}

/// A run whose generations are evaluated elsewhere (`ask`, then `tell` with
/// the outcomes in any order of computation) is the run `advance` makes.
fn external(config: Config, reverse: bool) -> State {
    let mut s = State::new(config).unwrap();
    let problem = s.config.problem.build().unwrap();
    while !s.done() {
        let g = s.ask().unwrap();
        let genomes: Vec<&[f64]> = g.genomes().collect();
        // Evaluated back to front, as workers finishing in any order would.
        let mut outcomes = vec![None; genomes.len()];
        let order: Vec<usize> = if reverse {
            (0..genomes.len()).rev().collect()
        } else {
            (0..genomes.len()).collect()
        };
        for i in order {
            outcomes[i] = Some(problem.evaluate(genomes[i]).unwrap());
        }
        let outcomes: Vec<_> = outcomes.into_iter().map(Option::unwrap).collect();
        s.tell(&g, &outcomes).unwrap();
    }
    s
}

#[test]
fn a_run_evaluated_elsewhere_equals_one_advanced_here() {
    let config = Config::thesis(3, 25, 11);
    let a = run(config.clone(), 2, 25);
    let b = external(config, true);
    assert_eq!(a.log_csv(), b.log_csv());
    assert_eq!(a, b);
    assert_eq!(a.best_toml().unwrap(), b.best_toml().unwrap());

    let text = include_str!("../../cli/tests/crawler.toml");
    let scene = Config {
        optimiser: animats_evolve::optimiser::OptimiserKind::CmaEs,
        problem: animats_evolve::run::ProblemSpec {
            file: "crawler.toml".into(),
            text: text.into(),
        },
        generations: 4,
        log: animats_evolve::LogMode::Generations,
        ..Config::thesis(2, 4, 5)
    };
    let a = run(scene.clone(), 2, 4);
    let b = external(scene, false);
    assert_eq!(a.log_csv(), b.log_csv());
    assert_eq!(a.log.len(), 8, "a scene logs every lane's every generation");
    assert_eq!(a.best_toml().unwrap(), b.best_toml().unwrap());
    // Outcomes of the wrong count are refused.
    let mut s = State::new(a.config.clone()).unwrap();
    let g = s.ask().unwrap();
    assert!(s.tell(&g, &[]).is_err());
}

/// The roobot's problem, counting and recording its evaluations, failing
/// from the `fail_after`-th on.
struct Counted {
    inner: Box<dyn animats_evolve::Problem>,
    seen: std::sync::Mutex<Vec<Vec<f64>>>,
    fail_after: usize,
}

impl animats_evolve::Problem for Counted {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn start(&self) -> Vec<f64> {
        self.inner.start()
    }
    fn bounds(&self) -> Option<animats_evolve::optimiser::Bounds> {
        self.inner.bounds()
    }
    fn relative_mutation(&self) -> bool {
        self.inner.relative_mutation()
    }
    fn evaluate(&self, genome: &[f64]) -> Result<animats_evolve::Outcome, String> {
        let n = {
            let mut seen = self.seen.lock().unwrap();
            seen.push(genome.to_vec());
            seen.len()
        };
        if n > self.fail_after {
            return Err(format!("evaluation {n}: budget spent"));
        }
        self.inner.evaluate(genome)
    }
}

fn counted(config: &Config, fail_after: usize) -> Counted {
    Counted {
        inner: config.problem.build().unwrap(),
        seen: std::sync::Mutex::new(Vec::new()),
        fail_after,
    }
}

#[test]
fn lanes_advance_together_and_a_failure_stops_the_batch() {
    // On one thread the lanes take turns, the least advanced first: the
    // first generation of every lane (the starting parameters) before any
    // lane's second.
    let config = Config::thesis(3, 20, 5);
    let problem = counted(&config, usize::MAX);
    let mut s = State::new(config.clone()).unwrap();
    pool(1).install(|| s.advance_with(&problem, 4)).unwrap();
    let seen = problem.seen.into_inner().unwrap();
    assert_eq!(seen.len(), 12);
    let start = config.problem.build().unwrap().start();
    assert!(seen[..3].iter().all(|g| *g == start), "{:?}", &seen[..4]);
    assert!(seen[3..].iter().all(|g| *g != start));
    // A failing evaluation ends the batch with its message, on any number
    // of threads, and nothing waits for it forever.
    for threads in [1, 2, 3] {
        let problem = counted(&config, 5);
        let mut s = State::new(config.clone()).unwrap();
        let err = pool(threads)
            .install(|| s.advance_with(&problem, 10))
            .unwrap_err();
        assert!(err.contains("budget spent"), "{threads} threads: {err}");
        let evaluated = problem.seen.into_inner().unwrap().len();
        assert!(evaluated <= 5 + threads, "{threads} threads: {evaluated}");
    }
}

/// `advance_while` (how `animats evolve` runs): every lane one generation
/// when `more` says no at once; lanes left at different generations when
/// it stops them part way; and the same log, best and checkpoint, bit for
/// bit, as lanes advanced together, on 1 to 3 threads.
#[test]
fn lanes_that_never_wait_for_each_other_log_what_lanes_in_step_do() {
    let config = Config::thesis(3, 30, 7);
    let together = run(config.clone(), 1, 5);
    let problem = config.problem.build().unwrap();

    let mut s = State::new(config.clone()).unwrap();
    pool(2)
        .install(|| s.advance_while(problem.as_ref(), None, &|| false, &|_| ()))
        .unwrap();
    let gens: Vec<u64> = s.lanes.iter().map(|l| l.generation).collect();
    assert_eq!(gens, vec![1, 1, 1]);

    for threads in [1, 2, 3] {
        let mut s = State::new(config.clone()).unwrap();
        let (taken, rows) = (AtomicU64::new(0), AtomicU64::new(0));
        // At most 17 generations more after each lane's first: a stop part
        // way, whatever lane holds the last.
        let more = || taken.fetch_add(1, Ordering::SeqCst) < 17;
        let seen = |_: &animats_evolve::LogRow| {
            rows.fetch_add(1, Ordering::SeqCst);
        };
        pool(threads)
            .install(|| s.advance_while(problem.as_ref(), None, &more, &seen))
            .unwrap();
        let gens: Vec<u64> = s.lanes.iter().map(|l| l.generation).collect();
        assert_eq!(
            gens.iter().sum::<u64>(),
            3 + 17,
            "{threads} threads: {gens:?}"
        );
        assert_eq!(rows.load(Ordering::SeqCst), 20);
        // A checkpoint now, resumed and run to the end.
        // (20 generations over 3 lanes: never level.)
        let path = scratch(&format!("uneven-{threads}")).join("checkpoint.json");
        checkpoint::save(&path, &s).unwrap();
        let mut back = checkpoint::load(&path).unwrap();
        if let Some(dir) = path.parent() {
            let _ = std::fs::remove_dir_all(dir);
        }
        while !back.done() {
            pool(threads)
                .install(|| back.advance_while(problem.as_ref(), None, &|| true, &|_| ()))
                .unwrap();
        }
        assert_eq!(back.log_csv(), together.log_csv(), "{threads} threads");
        assert_eq!(back.best_toml(), together.best_toml(), "{threads} threads");
    }
}

#[test]
fn lanes_advanced_towards_goals_of_their_own_stop_there_and_log_the_same() {
    // Python's `Evolution.run(generations=n, checkpoint=...)`: each lane
    // towards its own goal, in stretches of one generation a lane, the
    // lanes uneven between them.
    let config = Config::thesis(3, 30, 7);
    let together = run(config.clone(), 1, 30);
    let problem = config.problem.build().unwrap();
    let mut s = State::new(config).unwrap();
    let taken = AtomicU64::new(0);
    let more = || taken.fetch_add(1, Ordering::SeqCst) < 4;
    pool(2)
        .install(|| s.advance_towards(problem.as_ref(), &[30, 30, 30], None, &more, None))
        .unwrap();
    let uneven: Vec<u64> = s.lanes.iter().map(|l| l.generation).collect();
    assert_eq!(uneven.iter().sum::<u64>(), 3 + 4, "{uneven:?}");
    let goals: Vec<u64> = uneven.iter().map(|g| g + 5).collect();
    for _ in 0..20 {
        pool(2)
            .install(|| s.advance_towards(problem.as_ref(), &goals, None, &|| false, None))
            .unwrap();
    }
    let at: Vec<u64> = s.lanes.iter().map(|l| l.generation).collect();
    assert_eq!(at, goals, "each lane stops at its goal");
    // Goals past the total stop at it.
    while !s.done() {
        pool(2)
            .install(|| s.advance_towards(problem.as_ref(), &[99, 99, 99], None, &|| true, None))
            .unwrap();
    }
    assert!(s.lanes.iter().all(|l| l.generation == 30));
    assert_eq!(s.log_csv(), together.log_csv());
    assert_eq!(s.best_toml(), together.best_toml());
    let err = s
        .advance_towards(problem.as_ref(), &[1, 2], None, &|| true, None)
        .unwrap_err();
    assert!(err.contains("2 goals for 3 lanes"), "{err}");
}

#[test]
fn a_runs_defaults_and_checks_are_the_librarys() {
    use animats_evolve::optimiser::OptimiserKind;
    use animats_evolve::{Choices, LogMode, ProblemSpec};
    // The thesis's scene says its lanes (6) and its log (Table 6's shape);
    // `Config::thesis` is that scene's run.
    let thesis = Config::new(ProblemSpec::thesis(), &Choices::default()).unwrap();
    assert_eq!(thesis, Config::thesis(6, 100, 1));
    assert_eq!(thesis.log, LogMode::Improvements);
    // A scene that says nothing: CMA-ES, one lane, a row per generation.
    let crawler = ProblemSpec {
        file: "crawler.toml".into(),
        text: include_str!("../../cli/tests/crawler.toml").into(),
    };
    let c = Config::new(crawler.clone(), &Choices::default()).unwrap();
    assert_eq!(
        (c.lanes, c.log, c.optimiser),
        (1, LogMode::Generations, OptimiserKind::CmaEs)
    );
    // One that names its optimiser gets it; a name it misspells is refused.
    let said = |name: &str| ProblemSpec {
        file: "crawler.toml".into(),
        text: format!(
            "{}optimiser = \"{name}\"\n",
            include_str!("../../cli/tests/crawler.toml")
        ),
    };
    let c = Config::new(said("ga"), &Choices::default()).unwrap();
    assert_eq!(c.optimiser, OptimiserKind::Ga);
    let e = Config::new(said("annealing"), &Choices::default()).unwrap_err();
    assert!(
        e.starts_with("[evolve] optimiser: unknown optimiser `annealing`"),
        "{e}"
    );
    let chosen = Choices {
        lanes: Some(3),
        optimiser: Some(OptimiserKind::CmaEs),
        restarts: Some(2),
        ..Choices::default()
    };
    let c = Config::new(crawler.clone(), &chosen).unwrap();
    assert_eq!(
        (c.lanes, c.optimiser, c.restarts),
        (3, OptimiserKind::CmaEs, 2)
    );
    // Refused, naming the field.
    for (choices, expect) in [
        (
            Choices {
                restarts: Some(1),
                optimiser: Some(OptimiserKind::Ga),
                ..Choices::default()
            },
            "restarts",
        ),
        (
            Choices {
                lanes: Some(0),
                ..Choices::default()
            },
            "lanes",
        ),
        (
            Choices {
                lanes: Some(5000),
                ..Choices::default()
            },
            "lanes",
        ),
    ] {
        let e = Config::new(crawler.clone(), &choices).unwrap_err();
        assert!(e.starts_with(expect), "{e}");
    }
    let bad = ProblemSpec {
        file: "bad.toml".into(),
        text: "[world]\nwings = 2\n".into(),
    };
    assert!(Config::new(bad, &Choices::default())
        .unwrap_err()
        .contains("bad.toml"));

    // A resumed run takes only new generations, not fewer than done.
    let mut s = run(Config::thesis(2, 10, 3), 1, 10);
    let keep = s.clone();
    for choices in [
        Choices {
            seed: Some(4),
            ..Choices::default()
        },
        Choices {
            lanes: Some(3),
            ..Choices::default()
        },
        Choices {
            generations: Some(5),
            ..Choices::default()
        },
    ] {
        assert!(s.resume(&choices).is_err(), "{choices:?}");
        assert_eq!(s, keep);
    }
    s.resume(&Choices {
        generations: Some(20),
        seed: Some(3),
        ..Choices::default()
    })
    .unwrap();
    assert_eq!(s.config.generations, 20);
}

/// FNV-1a of `bytes` (the checkpoint's checksum).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    })
}

#[test]
fn the_thesis_runs_log_is_the_one_users_rely_on() {
    // `animats evolve --generations 300 --lanes 6 --seed 3` writes this
    // log.csv (sha256 ada097e748b0d84e...): the roobot's evolution, now the
    // scene scenes/hop_evolver.toml, scores every genome as the thesis's
    // own evaluation loop did, bit for bit.
    let s = run(Config::thesis(6, 300, 3), 2, 50);
    let log = s.log_csv();
    assert!(log.starts_with("lane,generation,fitness,time_up,distance,p0,"));
    assert_eq!(
        fnv1a(log.as_bytes()),
        THESIS_LOG_FNV,
        "{:#018x}",
        fnv1a(log.as_bytes())
    );
}

const THESIS_LOG_FNV: u64 = 0xb221_e0c9_338c_ceb1;
