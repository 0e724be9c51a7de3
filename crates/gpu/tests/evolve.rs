//! Evolution with every generation evaluated in batches by the C (what
//! `--device cuda` does on a GPU, here on the CPU) writes the engine's
//! log, optimiser state and best to the bit: CMA-ES on the soft walker
//! with robust evaluation (a batch at the step, then one at half of it for
//! the candidates that need it) and with perturbed trials, the body GA on
//! random bodies, MAP-Elites over bodies (its archive in the lanes'
//! state), and CMA-ES on the walker among rocks (sphere contact).

use animats_evolve::run::{Choices, Config, ProblemSpec, State};
use animats_evolve::OptimiserKind;
use animats_scene::evaluate::Batches;

const WALKER: &str = include_str!("../../../scenes/walker.toml");
const BODIES_WALK: &str = include_str!("../../../scenes/bodies_walk.toml");
const WALKER_ROCKS: &str = include_str!("../../../scenes/walker_rocks.toml");

/// `generations` of `text` with `choices`, on the engine or in the C's
/// batches: (log.csv, best.toml, the optimisers' states).
fn run(text: &str, choices: &Choices, batches: Option<Batches>) -> (String, String, String) {
    let spec = ProblemSpec {
        file: "scene.toml".into(),
        text: text.into(),
    };
    let config = Config::new(spec.clone(), choices).unwrap();
    let generations = config.generations;
    let mut s = State::new(config).unwrap();
    let problem = spec.build_on(batches).unwrap();
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| s.advance_with(problem.as_ref(), generations))
        .unwrap();
    let lanes = format!("{:?}", s.lanes);
    (
        s.log_csv(),
        s.best_toml().unwrap().unwrap_or_default(),
        lanes,
    )
}

fn assert_same(text: &str, choices: Choices, what: &str) {
    let engine = run(text, &choices, None);
    let c = run(text, &choices, Some(animats_gpu::c_batches()));
    assert_eq!(engine.0, c.0, "{what}: log.csv");
    assert_eq!(engine.1, c.1, "{what}: best.toml");
    assert_eq!(engine.2, c.2, "{what}: the lanes");
    assert!(engine.0.lines().count() > 3, "{what}: {}", engine.0);
}

fn walker(extra: &str) -> String {
    WALKER
        .replace("duration = 10.0", "duration = 1.0")
        .replace("[evolve]\n", &format!("[evolve]\n{extra}\n"))
}

#[test]
fn cma_es_on_the_walker_in_batches_writes_the_engine_s_log() {
    let choices = Choices {
        generations: Some(4),
        population: Some(8),
        seed: Some(3),
        lanes: Some(2),
        optimiser: Some(OptimiserKind::CmaEs),
        ..Choices::default()
    };
    assert_same(&walker("robust = true"), choices.clone(), "robust walker");
    assert_same(
        &walker("trials = 3\nnoise = 0.1\nrobust = true"),
        choices,
        "perturbed trials",
    );
}

/// The walker among its rocks (sphere contact, the event): CMA-ES in the
/// C's batches writes the engine's log.
#[test]
fn cma_es_on_the_walker_among_rocks_in_batches_writes_the_engine_s_log() {
    let choices = Choices {
        generations: Some(3),
        population: Some(8),
        seed: Some(5),
        lanes: Some(1),
        optimiser: Some(OptimiserKind::CmaEs),
        ..Choices::default()
    };
    let text = WALKER_ROCKS.replace("duration = 10.0", "duration = 3.0");
    assert!(text.contains("duration = 3.0") && text.contains("[contacts]"));
    assert_same(&text, choices, "walker among rocks");
}

#[test]
fn map_elites_over_bodies_in_batches_writes_the_engine_s_log_and_archive() {
    // The shipped land task (feet on the floor against size), 1 s each.
    let text = BODIES_WALK.replace("duration = 10.0", "duration = 1.0");
    let choices = Choices {
        generations: Some(3),
        population: Some(8),
        seed: Some(4),
        ..Choices::default()
    };
    assert_same(&text, choices, "MAP-Elites over bodies");
}

#[test]
fn the_body_ga_in_batches_writes_the_engine_s_log() {
    // The land task's bodies without the archive (the C does not measure
    // yet), by the body GA, 1 s each.
    let start = BODIES_WALK.find("[archive]").unwrap();
    let text = BODIES_WALK[..start]
        .replace("duration = 10.0", "duration = 1.0")
        .replace("optimiser = \"map-elites\"", "optimiser = \"body-ga\"");
    let choices = Choices {
        generations: Some(3),
        population: Some(8),
        seed: Some(2),
        ..Choices::default()
    };
    assert_same(&text, choices.clone(), "body GA");
    // With neural brains reading touch sensors.
    let neural = text.replace("controller = \"oscillator\"", "controller = \"neural\"");
    assert_same(&neural, choices, "body GA, neural brains");
}

#[test]
fn the_thesis_s_experiment_in_batches_writes_the_engine_s_log() {
    // scenes/hop_evolver.toml as shipped (Appendix B's hill climber, six
    // lanes, the improvements logged, Appendix B's starting parameters):
    // 40 generations, the lanes' bests hopping further as they go.
    let text = include_str!("../../../scenes/hop_evolver.toml");
    let choices = Choices {
        generations: Some(40),
        seed: Some(1),
        ..Choices::default()
    };
    assert_same(text, choices, "the roobot's hill climber");
}
