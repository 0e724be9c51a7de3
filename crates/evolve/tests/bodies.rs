//! Bodies evolve (issue 39): from random starts, with each encoding (and
//! graph bodies with each controller),
//! fitness rises, the best body differs in structure from every start
//! body, and its `best.toml` evaluates to the logged fitness exactly; the
//! same seed gives the same log and best on 1 and 2 threads and after a
//! checkpoint is written, read back and continued.

use animats_evolve::optimiser::AnyOptimiser;
use animats_evolve::screen::Screen;
use animats_evolve::{checkpoint, Choices, Config, Outcome, Problem, ProblemSpec, State};
use animats_scene::evaluate::SceneProblem;
use animats_scene::morphology::MorphologyProblem;

const GRAPH: &str = r#"
[world]
dt = 0.001
integrator = "symplectic"
[floor]
[morphology]
encoding = "graph"
max_particles = 12
max_springs = 40
[evolve]
duration = 1.5
distance_weight = 1.0
time_weight = 0.0
"#;

const LATTICE: &str = r#"
[world]
dt = 0.0005
integrator = "symplectic"
[floor]
[morphology]
encoding = "lattice"
cells = [3, 2, 1]
cell = 0.08
max_particles = 24
max_springs = 100
mass = [0.001, 0.3]
damping = 0.5
[evolve]
duration = 1.0
distance_weight = 1.0
time_weight = 0.0
"#;

fn config(text: &str, generations: u64) -> Config {
    searched(text, generations, None)
}

/// [`config`] searched by MAP-Elites.
fn map_elites(text: &str, generations: u64) -> Config {
    searched(
        text,
        generations,
        Some(animats_evolve::OptimiserKind::MapElites),
    )
}

/// `text` run for `generations` of 8 bodies from seed 5, by `optimiser`
/// (the scene's own when `None`).
fn searched(
    text: &str,
    generations: u64,
    optimiser: Option<animats_evolve::OptimiserKind>,
) -> Config {
    let spec = ProblemSpec {
        file: "bodies.toml".into(),
        text: text.into(),
    };
    let choices = Choices {
        generations: Some(generations),
        population: Some(8),
        seed: Some(5),
        optimiser,
        ..Choices::default()
    };
    Config::new(spec, &choices).unwrap()
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// A body's structure: its particles, and its springs as (a, b, muscle).
fn structure(p: &MorphologyProblem, genes: &[f64]) -> (usize, Vec<(usize, usize, bool)>) {
    let b = p.body(genes).unwrap();
    let mut springs: Vec<_> = b
        .edges
        .iter()
        .map(|e| (e.a.min(e.b), e.a.max(e.b), e.muscle.is_some()))
        .collect();
    springs.sort_unstable();
    (b.nodes.len(), springs)
}

fn parents(s: &State) -> Vec<Vec<f64>> {
    match &s.lanes[0].optimiser {
        AnyOptimiser::BodyGa(o) => o.parents().iter().map(|(g, _)| g.clone()).collect(),
        other => panic!(
            "a [morphology] scene evolves with body-ga, not {:?}",
            other.kind()
        ),
    }
}

#[test]
fn bodies_evolve_from_random_starts_with_each_encoding() {
    let neural = GRAPH.replace(
        "encoding = \"graph\"",
        "encoding = \"graph\"\ncontroller = \"neural\"",
    );
    for (name, text, generations) in [
        ("graph", GRAPH, 8),
        ("lattice", LATTICE, 8),
        ("graph, neural", &neural[..], 8),
    ] {
        let p = MorphologyProblem::parse(text, "bodies.toml").unwrap();
        let mut s = State::new(config(text, generations)).unwrap();
        let threads = pool(2);
        threads.install(|| s.advance(1)).unwrap();
        let starts = parents(&s);
        let first = s.best_fitness().unwrap();
        while !s.done() {
            threads.install(|| s.advance(1)).unwrap();
        }
        let best = s.lanes[0].best.clone().unwrap();
        println!(
            "{name}: best {} m after {generations} generations (the first generation's {first} m); refused {:?}",
            best.fitness,
            s.refusals()
        );
        assert!(
            best.fitness > first,
            "{name}: fitness rose from {first} to {}",
            best.fitness
        );
        let shape = structure(&p, &best.genome);
        for start in &starts {
            assert_ne!(
                shape,
                structure(&p, start),
                "{name}: the best body is a start body"
            );
        }
        // best.toml is an ordinary scene, and it scores what the log says.
        let text = s.best_toml().unwrap().unwrap();
        assert!(!text.contains("[morphology]"));
        assert_eq!(
            text.contains("kind = \"neural\""),
            name.contains("neural"),
            "{name}"
        );
        let back = SceneProblem::parse(&text, "best.toml").unwrap();
        let again = back.evaluate(back.start()).unwrap();
        assert_eq!(again.fitness.to_bits(), best.fitness.to_bits(), "{name}");
        let log = s.log_csv();
        assert!(log.starts_with(
            "lane,generation,evaluations,fitness,best_fitness,time,distance,ended,particles,springs,muscles,mass,refused\n"
        ));
        assert_eq!(log.lines().count(), 1 + generations as usize);
    }
}

#[test]
fn a_body_run_is_the_same_on_any_thread_count_and_after_a_checkpoint() {
    let run = |threads: usize| {
        let mut s = State::new(config(GRAPH, 6)).unwrap();
        let p = pool(threads);
        while !s.done() {
            p.install(|| s.advance(2)).unwrap();
        }
        s
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one.log_csv(), two.log_csv());
    assert_eq!(one.best_toml().unwrap(), two.best_toml().unwrap());
    assert_eq!(one, two);
    // Stop after 3 generations, write the checkpoint, read it back, go on.
    let dir = std::env::temp_dir().join(format!("animats-bodies-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("checkpoint.json");
    let mut s = State::new(config(GRAPH, 6)).unwrap();
    pool(2).install(|| s.advance(3)).unwrap();
    checkpoint::save(&path, &s).unwrap();
    let mut back = checkpoint::load(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(back, s);
    pool(1).install(|| back.advance(3)).unwrap();
    assert_eq!(back.log_csv(), one.log_csv());
    assert_eq!(back.best_toml().unwrap(), one.best_toml().unwrap());
    // The same through ask and tell (a generation evaluated elsewhere).
    let mut s = State::new(config(GRAPH, 6)).unwrap();
    let problem = s.config.problem.build().unwrap();
    while !s.done() {
        let g = s.ask().unwrap();
        let outcomes: Vec<_> = g
            .genomes()
            .enumerate()
            .map(|(i, x)| problem.evaluate_screened(x, g.screen(i)).unwrap())
            .collect();
        s.tell(&g, &outcomes).unwrap();
    }
    assert_eq!(s.log_csv(), one.log_csv());
}

/// A problem that scores every candidate in full (ignores screens).
struct Full(Box<dyn Problem>);

impl Problem for Full {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn start(&self) -> Vec<f64> {
        self.0.start()
    }
    fn bounds(&self) -> Option<animats_evolve::optimiser::Bounds> {
        self.0.bounds()
    }
    fn evaluate(&self, genome: &[f64]) -> Result<Outcome, String> {
        self.0.evaluate(genome)
    }
    fn spec(&self) -> Option<&animats_scene::evaluate::EvolveSpec> {
        self.0.spec()
    }
    fn variation(&self) -> Option<&dyn animats_evolve::optimiser::body_ga::Variation> {
        self.0.variation()
    }
    fn stats(&self, genome: &[f64]) -> Option<animats_scene::morphology::BodyStats> {
        self.0.stats(genome)
    }
    fn grid(&self) -> Option<&animats_scene::archive::Grid> {
        self.0.grid()
    }
    fn scene_toml(&self, genome: &[f64], comment: &str) -> Result<String, String> {
        self.0.scene_toml(genome, comment)
    }
}

/// A run of `config` to its end on 2 threads, every candidate scored in
/// full if `full`, else as the optimiser's screens say.
fn run_to_end(config: Config, full: bool) -> State {
    let generations = config.generations;
    let mut s = State::new(config).unwrap();
    let problem = s.config.problem.build().unwrap();
    let problem: Box<dyn Problem> = if full {
        Box::new(Full(problem))
    } else {
        problem
    };
    pool(2)
        .install(|| s.advance_with(problem.as_ref(), generations))
        .unwrap();
    s
}

/// Robust evaluation (the default for bodies: at the step and at half of
/// it, the worse counting) skips the half-step run of a child that cannot
/// survive, since the robust score is never above the score at the step:
/// the body GA keeps the same survivors, the same best and `best.toml` as
/// with every child scored in full, and only log rows whose best child did
/// not survive may differ, by showing its score at the step (never below
/// its robust score). So does the quarter step's run (`robust_halvings =
/// 2`) of a child whose worse of the first two cannot survive.
#[test]
fn screened_robust_evaluation_keeps_every_survivor_and_the_best() {
    // At the step and half of it, and with a quarter of it too.
    let quarter = GRAPH.replace("[evolve]\n", "[evolve]\nrobust_halvings = 2\n");
    for text in [GRAPH, quarter.as_str()] {
        let run = |full: bool, generations: u64| run_to_end(config(text, generations), full);
        let screened = run(false, 10);
        let full = run(true, 10);
        assert_eq!(screened.lanes[0].optimiser, full.lanes[0].optimiser);
        assert_eq!(screened.lanes[0].best, full.lanes[0].best);
        assert_eq!(screened.best_toml().unwrap(), full.best_toml().unwrap());
        let (a, b) = (screened.log_csv(), full.log_csv());
        let mut differ = 0;
        for (x, y) in a.lines().zip(b.lines()).skip(1) {
            let (x, y): (Vec<&str>, Vec<&str>) = (x.split(',').collect(), y.split(',').collect());
            // lane, generation, evaluations, best_fitness and the body columns
            // are the same; the generation's best may show its score at the step.
            for k in [0, 1, 2, 4, 8, 9, 10, 11, 12] {
                assert_eq!(x[k], y[k], "column {k}: {x:?} against {y:?}");
            }
            let (fx, fy): (f64, f64) = (x[3].parse().unwrap(), y[3].parse().unwrap());
            assert!(fx >= fy, "{fx} below the robust {fy}");
            differ += (x[3] != y[3]) as usize;
        }
        println!("{differ} of 10 rows show a score at the step");
        // The next generation's children: those at or below the worst
        // survivor are scored once, the rest in full.
        let mut s = run(false, 10);
        s.config.generations = 11;
        let problem = s.config.problem.build().unwrap();
        let g = s.ask().unwrap();
        let bar = match g.screen(0) {
            Screen::Above { bar } => *bar,
            other => panic!("a full population screens by its worst: {other:?}"),
        };
        let (mut cut, mut scored, mut quartered) = (0, 0, 0);
        let halved = config(GRAPH, 1).problem.build().unwrap();
        for (i, x) in g.genomes().enumerate() {
            let once = problem.evaluate_screened(x, g.screen(i)).unwrap();
            let robust = problem.evaluate(x).unwrap();
            quartered += (robust != halved.evaluate(x).unwrap()) as usize;
            if once.fitness > bar {
                assert_eq!(once, robust, "child {i} above the bar is scored in full");
                scored += 1;
            } else {
                assert!(robust.fitness <= once.fitness, "child {i}");
                cut += 1;
            }
        }
        println!("bar {bar}: {cut} children scored once, {scored} in full, {quartered} scored lower at a quarter of the step");
        assert_eq!(quartered > 0, text != GRAPH);
        assert!(cut > 0, "no child was screened out");
    }
}

/// MAP-Elites screens a child by its cell's threshold; with measures of the
/// body as built (the same at either step) the archive is the same as with
/// every child scored in full.
#[test]
fn screened_map_elites_over_build_measures_fills_the_same_archive() {
    let text = format!(
        "{GRAPH}[archive]\nmeasures = [{{ kind = \"size\" }}, {{ kind = \"particles\" }}]\nbins = [4, 4]\nranges = [[0.0, 0.4], [1.5, 13.5]]\n"
    );
    let run = |full: bool| run_to_end(map_elites(&text, 8), full);
    let (screened, full) = (run(false), run(true));
    let (a, b) = (screened.archive().unwrap(), full.archive().unwrap());
    assert!(a.len() > 2, "{} elites", a.len());
    assert_eq!(a.elites(), b.elites());
    assert_eq!(screened.best_toml().unwrap(), full.best_toml().unwrap());
}

#[test]
fn a_screen_reads_back_from_json_with_infinite_bars() {
    for s in [
        Screen::All,
        Screen::Above {
            bar: f64::NEG_INFINITY,
        },
        Screen::Above { bar: 1.25 },
    ] {
        assert_eq!(Screen::from_json(&s.to_json()).unwrap(), s);
    }
    assert!(Screen::from_json("{\"kind\":\"sideways\"}").is_err());
}

#[test]
fn a_body_run_refuses_what_does_not_fit_it() {
    let spec = ProblemSpec {
        file: "bodies.toml".into(),
        text: GRAPH.into(),
    };
    let cma = Choices {
        optimiser: Some(animats_evolve::OptimiserKind::CmaEs),
        ..Choices::default()
    };
    let e = Config::new(spec.clone(), &cma).unwrap_err();
    assert!(e.contains("body-ga or map-elites, not cma-es"), "{e}");
    let improvements = GRAPH.replace("[evolve]\n", "[evolve]\nlog = \"improvements\"\n");
    let e = Config::new(
        ProblemSpec {
            text: improvements,
            ..spec
        },
        &Choices::default(),
    )
    .unwrap_err();
    assert!(e.contains("logs generations"), "{e}");
    let crawler = ProblemSpec {
        file: "crawler.toml".into(),
        text: std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../cli/tests/crawler.toml"
        ))
        .unwrap(),
    };
    let bodyga = Choices {
        optimiser: Some(animats_evolve::OptimiserKind::BodyGa),
        ..Choices::default()
    };
    let e = Config::new(crawler, &bodyga).unwrap_err();
    assert!(e.contains("[morphology]"), "{e}");
}

/// `[archive] overlap = true`: each generation is asked before the last
/// is told (its parents from the archive a generation older), and one
/// lane's two generations are evaluated at once. The run is a pure
/// function of its seed: the same log, best and state on 1 and 3 threads,
/// advanced in batches across a checkpoint, by `advance_while` stopping
/// and going on, and through `ask`/`tell` one generation at a time; and it
/// is not the run without overlap.
#[test]
fn overlapped_generations_are_one_run_on_any_threads_and_paths() {
    let text = |overlap: bool| {
        format!(
            "{GRAPH}[archive]\nmeasures = [{{ kind = \"size\" }}, {{ kind = \"feet\" }}]\nbins = [4, 4]\nranges = [[0.0, 0.4], [0.0, 8.0]]\ntournament = 2\noverlap = {overlap}\n"
        )
    };
    let config = |overlap: bool| map_elites(&text(overlap), 8);
    let whole = |threads: usize| {
        let mut s = State::new(config(true)).unwrap();
        pool(threads).install(|| s.advance(8)).unwrap();
        s
    };
    let one = whole(1);
    assert_eq!(one.log.len(), 8);
    assert!(one.lanes[0].ahead.is_some(), "the next generation waits");
    let three = whole(3);
    assert_eq!(one.log_csv(), three.log_csv());
    assert_eq!(one, three);
    // In batches, across a checkpoint.
    let dir = std::env::temp_dir().join(format!("animats-overlap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("checkpoint.json");
    let mut s = State::new(config(true)).unwrap();
    pool(2).install(|| s.advance(3)).unwrap();
    checkpoint::save(&path, &s).unwrap();
    let mut back = checkpoint::load(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(back, s);
    pool(2).install(|| back.advance(5)).unwrap();
    assert_eq!(back, one);
    // Stopping after every few generations, as `animats evolve` does.
    let mut s = State::new(config(true)).unwrap();
    let problem = s.config.problem.build().unwrap();
    while !s.done() {
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let more = || calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) < 2;
        pool(2)
            .install(|| s.advance_while(problem.as_ref(), None, &more, &|_| ()))
            .unwrap();
    }
    assert_eq!(s, one);
    // Through ask and tell, one generation at a time (asked twice untold,
    // refused, and the run goes on as if it had not been).
    let mut s = State::new(config(true)).unwrap();
    while !s.done() {
        let g = s.ask().unwrap();
        let e = s.ask().unwrap_err();
        assert!(e.contains("one generation ahead"), "{e}");
        let outcomes: Vec<_> = g
            .genomes()
            .enumerate()
            .map(|(i, x)| problem.evaluate_screened(x, g.screen(i)).unwrap())
            .collect();
        s.tell(&g, &outcomes).unwrap();
    }
    assert_eq!(s, one);
    // Not the run without overlap.
    let mut plain = State::new(config(false)).unwrap();
    pool(2).install(|| plain.advance(8)).unwrap();
    assert_ne!(plain.log_csv(), one.log_csv());
    // The first generation is the same (its refusals aside: the overlapped
    // run has made the second's children too).
    let (a, b) = (&plain.log[0], &one.log[0]);
    assert_eq!(
        (a.fitness, &a.improved, a.archive),
        (b.fitness, &b.improved, b.archive)
    );
    assert!(a.refused < b.refused, "{:?} {:?}", a.refused, b.refused);
}

/// With a start body and `[archive] overlap`, the first generation holds
/// the start body once (its first candidate) and the second, asked before
/// the first is told, only its mutants.
#[test]
fn an_overlapped_run_evaluates_its_start_body_once() {
    let text = LATTICE.replace(
        "[morphology]\n",
        "[morphology]\nstructure = [[3, 3, 3], [4, 0, 4]]\n",
    ) + "[archive]\nmeasures = [{ kind = \"size\" }]\nbins = [4]\nranges = [[0.0, 0.4]]\noverlap = true\n";
    let spec = ProblemSpec {
        file: "bodies.toml".into(),
        text,
    };
    let choices = Choices {
        generations: Some(1),
        population: Some(4),
        seed: Some(2),
        optimiser: Some(animats_evolve::OptimiserKind::MapElites),
        ..Choices::default()
    };
    let mut s = State::new(Config::new(spec, &choices).unwrap()).unwrap();
    let start = s.config.problem.build().unwrap().start();
    let g = s.ask().unwrap();
    let first: Vec<&[f64]> = g.genomes().collect();
    assert_eq!(first[0], start.as_slice());
    let ahead = &s.lanes[0].ahead.as_ref().unwrap().population;
    assert_eq!(ahead.len(), 4);
    assert!(ahead.iter().all(|x| x != &start), "the start body again");
}

/// A generation told outcomes its archive refuses (here the last
/// candidate's measures are one too few) is refused whole: the run stays
/// as it was, and told again rightly it is the run never refused.
#[test]
fn outcomes_the_archive_refuses_leave_the_run_as_it_was() {
    let text = format!(
        "{GRAPH}[archive]\nmeasures = [{{ kind = \"size\" }}, {{ kind = \"feet\" }}]\nbins = [4, 4]\nranges = [[0.0, 0.4], [0.0, 8.0]]\n"
    );
    let config = map_elites(&text, 3);
    let mut never = State::new(config.clone()).unwrap();
    pool(1).install(|| never.advance(3)).unwrap();
    let problem = config.problem.build().unwrap();
    let mut s = State::new(config).unwrap();
    while !s.done() {
        let g = s.ask().unwrap();
        let outcomes: Vec<Outcome> = g
            .genomes()
            .enumerate()
            .map(|(i, x)| problem.evaluate_screened(x, g.screen(i)).unwrap())
            .collect();
        let mut bad = outcomes.clone();
        bad.last_mut().unwrap().measures.pop();
        let before = s.clone();
        let e = s.tell(&g, &bad).unwrap_err();
        assert!(e.contains("1 measures told, the archive has 2"), "{e}");
        assert_eq!(s, before, "a refused generation moved the run");
        s.tell(&g, &outcomes).unwrap();
    }
    assert_eq!(s.log_csv(), never.log_csv());
    assert_eq!(s, never);
}

/// `state` as a checkpoint after `edit` of its JSON, written with its
/// checksum made again: what loading it says.
fn load_edited(state: &State, edit: &dyn Fn(&mut serde_json::Value)) -> Result<State, String> {
    let mut v = serde_json::to_value(state).unwrap();
    edit(&mut v);
    let edited: State = serde_json::from_value(v).unwrap();
    let dir = std::env::temp_dir().join(format!("animats-edited-bodies-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("checkpoint.json");
    checkpoint::save(&path, &edited).unwrap();
    let out = checkpoint::load(&path);
    let _ = std::fs::remove_dir_all(&dir);
    out
}

/// A checkpoint of a body GA, of MAP-Elites over bodies and of CMA-ME
/// edited into a state its run could not have made is refused as it loads,
/// naming the lane and the part: a body the scene's [morphology] does not
/// accept (a parent, an elite), a population or batch of 2^40, a CMA-ME
/// emitter's mean one short. Untouched, each loads as it was saved.
#[test]
fn an_edited_body_or_archive_checkpoint_is_refused_unless_its_run_could_have_made_it() {
    use serde_json::json;
    let archive = "[archive]\nmeasures = [{ kind = \"size\" }, { kind = \"feet\" }]\nbins = [4, 4]\nranges = [[0.0, 0.4], [0.0, 8.0]]\n";
    let hop_map = ProblemSpec {
        file: "hop_map.toml".into(),
        text: include_str!("../../../scenes/hop_map.toml").into(),
    };
    let cma_me = Choices {
        lanes: Some(1),
        generations: Some(3),
        seed: Some(5),
        optimiser: Some(animats_evolve::OptimiserKind::CmaMe),
        ..Choices::default()
    };
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    type Case = (&'static str, Config, Vec<(Edit, &'static str)>);
    let set = |pointer: &'static str, to: serde_json::Value| -> Edit {
        Box::new(move |v| *v.pointer_mut(pointer).unwrap() = to.clone())
    };
    let cases: Vec<Case> = vec![
        (
            "body GA",
            config(GRAPH, 3),
            vec![
                (
                    set("/lanes/0/optimiser/parents/0/0", json!([1.0, 2.0])),
                    "lane 0's optimiser: parent 0 is not a body of the scene's [morphology]",
                ),
                (
                    set("/lanes/0/optimiser/size", json!(1u64 << 40)),
                    "lane 0's optimiser: its population's size",
                ),
            ],
        ),
        (
            "MAP-Elites over bodies",
            map_elites(&format!("{GRAPH}{archive}"), 3),
            vec![
                (
                    set("/lanes/0/optimiser/archive/elites/0/genome", json!([1.0])),
                    "lane 0's optimiser: the elite of cell",
                ),
                (
                    set("/lanes/0/optimiser/emitters/0/batch", json!(1u64 << 40)),
                    "lane 0's optimiser: emitter 0 is not",
                ),
            ],
        ),
        (
            "CMA-ME",
            Config::new(hop_map, &cma_me).unwrap(),
            vec![(
                Box::new(|v: &mut serde_json::Value| {
                    let mean = v.pointer_mut("/lanes/0/optimiser/emitters/0/mean").unwrap();
                    mean.as_array_mut().unwrap().pop();
                }),
                "lane 0's optimiser: emitter 0: its mean: 13 numbers, not 14",
            )],
        ),
    ];
    for (name, config, edits) in cases {
        let mut s = State::new(config).unwrap();
        pool(2).install(|| s.advance(2)).unwrap();
        assert_eq!(load_edited(&s, &|_| {}).unwrap(), s, "{name}");
        for (edit, expected) in edits {
            match load_edited(&s, &*edit) {
                Ok(_) => panic!("{name}: an edit that should say \"{expected}\" loaded"),
                Err(e) => assert!(
                    e.contains("the checkpoint is inconsistent") && e.contains(expected),
                    "{name}: {e}"
                ),
            }
        }
    }
}
