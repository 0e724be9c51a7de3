//! Bodies evolve (issue 39): from random starts, with each encoding (and
//! graph bodies with each controller),
//! fitness rises, the best body differs in structure from every start
//! body, and its `best.toml` evaluates to the logged fitness exactly; the
//! same seed gives the same log and best on 1 and 2 threads and after a
//! checkpoint is written, read back and continued.

use animats_evolve::optimiser::AnyOptimiser;
use animats_evolve::{checkpoint, Choices, Config, ProblemSpec, State};
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
    let spec = ProblemSpec {
        file: "bodies.toml".into(),
        text: text.into(),
    };
    let choices = Choices {
        generations: Some(generations),
        population: Some(8),
        seed: Some(5),
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
    assert_eq!(back, s);
    pool(1).install(|| back.advance(3)).unwrap();
    assert_eq!(back.log_csv(), one.log_csv());
    assert_eq!(back.best_toml().unwrap(), one.best_toml().unwrap());
    // The same through ask and tell (a generation evaluated elsewhere).
    let mut s = State::new(config(GRAPH, 6)).unwrap();
    let problem = s.config.problem.build().unwrap();
    while !s.done() {
        let g = s.ask().unwrap();
        let outcomes: Vec<_> = g.genomes().map(|x| problem.evaluate(x).unwrap()).collect();
        s.tell(g, &outcomes).unwrap();
    }
    assert_eq!(s.log_csv(), one.log_csv());
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
