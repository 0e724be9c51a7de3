//! What the viewer runs: a scene file's stage (moving the food steers the
//! jellyfish; the pile's overlay counts its sleeping rocks) and the
//! exhibition of an evolution's best brain.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_viewer::{Exhibition, SceneStage, Stage};
use std::path::PathBuf;

fn seaworld() -> SceneStage {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/seaworld.toml");
    SceneStage::load(path).expect("scene")
}

/// Horizontal centre of each jellyfish's dome, from the stage's positions.
fn domes(stage: &SceneStage) -> Vec<[f64; 2]> {
    let d = stage.describe();
    let mut p = Vec::new();
    stage.positions(&mut p);
    d.domes
        .iter()
        .map(|dome| {
            let n = dome.particles.len() as f64;
            let sum = dome.particles.iter().fold([0.0, 0.0], |s, &i| {
                [s[0] + f64::from(p[3 * i]), s[1] + f64::from(p[3 * i + 2])]
            });
            [sum[0] / n, sum[1] / n]
        })
        .collect()
}

#[test]
fn moving_the_food_turns_the_jellyfish_towards_it() {
    // Food moved (as a click on the floor does) 0.6-0.85 m from the middle in
    // four directions, 5 s into SeaWorld. Over the next 15 s, at least two of
    // the three jellyfish must swim towards it: their horizontal path points
    // within 45° of the food (cos > 0.7) and they end 20% nearer. (Measured:
    // 21 of 24 jellyfish-cases pass, the other three still end nearer.)
    for food in [[0.6, 0.6], [-0.6, -0.6], [0.8, 0.0], [0.0, -0.8]] {
        let mut stage = seaworld();
        let dt = stage.dt();
        while stage.time() < 5.0 {
            stage.step(dt).expect("step");
        }
        assert!(stage.move_food(food[0], food[1]));
        let start = domes(&stage);
        while stage.time() < 20.0 {
            stage.step(dt).expect("step");
        }
        let end = domes(&stage);
        let mut heading = 0;
        for (a, b) in start.iter().zip(&end) {
            let to = [food[0] - a[0], food[1] - a[1]];
            let went = [b[0] - a[0], b[1] - a[1]];
            let d0 = to[0].hypot(to[1]);
            let d1 = (food[0] - b[0]).hypot(food[1] - b[1]);
            let cos = (to[0] * went[0] + to[1] * went[1]) / (d0 * went[0].hypot(went[1]));
            if cos > 0.7 && d1 < 0.8 * d0 {
                heading += 1;
            }
        }
        assert!(
            heading >= 2,
            "food at {food:?}: only {heading} of 3 jellyfish headed for it"
        );
    }
}

#[test]
fn the_food_cannot_be_moved_where_there_is_none() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/pendulum_chain.toml");
    let mut stage = SceneStage::load(path).expect("scene");
    assert!(stage.describe().food.is_none());
    assert!(!stage.move_food(1.0, 1.0));
}

#[test]
fn the_thesis_exhibition_plays_the_best_gait_as_its_fitness_was_measured() {
    use animats_scene::evaluate::{evaluate_with, SceneProblem};
    use animats_viewer::BestBrain;
    let problem =
        SceneProblem::parse(animats_scene::HOP_EVOLVER, animats_scene::HOP_EVOLVER_FILE).unwrap();
    let board = BestBrain::default();
    let mut show = Exhibition::new(problem.clone(), board.clone()).expect("exhibition");
    let d = show.describe();
    assert_eq!(d.particles.len(), 5, "one roobot of five masses");
    assert!(d.floor);
    let dt = show.dt();

    // Until there is a best, the scene's own brain (Appendix B's initial
    // gait) plays; it falls after 2.616 s and starts again from the start.
    let mut restarted_at = None;
    for k in 1..400 {
        let before = show.time();
        show.step(dt).unwrap();
        if show.time() < before {
            restarted_at = Some(k);
            break;
        }
    }
    assert_eq!(restarted_at, Some(328), "327 steps up, then a restart");

    // With a best, the next run plays it exactly as `evaluate` measured it.
    let evolved = animats_scene::params::load("evolved", None).expect("evolved params");
    board.set_best(&evolved.0, 2172.09, 2);
    board.set_generation(1000, 1000);
    show.reset().unwrap();
    let mut reference = Vec::new();
    evaluate_with(problem.scene(&evolved.0).unwrap(), |s| {
        reference.push(s.world.position(s.particle("roobot.hip").unwrap()));
    })
    .expect("evaluate");
    let mut p = Vec::new();
    for (k, r) in reference.iter().enumerate().take(626).skip(1) {
        show.step(dt).expect("step");
        if k % 125 == 0 {
            show.positions(&mut p);
            let hip = [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])];
            assert!(
                (hip[0] - r.x).abs() < 1e-5 && (hip[1] - r.y).abs() < 1e-5,
                "step {k}: {hip:?} vs {r}"
            );
        }
    }
    // 5 s in, the camera follows it.
    let focus = show.focus().expect("focus");
    assert!(
        focus[0] > 5.0,
        "the evolved gait covers > 5 m in 5 s: {focus:?}"
    );
    let states = show.creatures();
    assert_eq!(states.len(), 1);
    assert_eq!(states[0].name, "roobot");
    assert!(["stance", "leap", "launch", "flight"].contains(&states[0].state.as_str()));
    let note = show.note().expect("note");
    assert!(
        note.contains("generation 1000 of 1000") && note.contains("2172.09 (lane 2)"),
        "{note}"
    );
}

/// `evolve SCENE --view`: the scene's own brain only until the first best
/// exists, then the best so far; when a run ends as an evaluation would,
/// it starts again with the newest best.
#[test]
fn a_scene_exhibition_replays_the_newest_best_brain() {
    use animats_viewer::BestBrain;
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/walker.toml"),
    )
    .unwrap()
    .replace("duration = 10.0\nparticles", "duration = 0.5\nparticles");
    let problem = animats_scene::evaluate::SceneProblem::parse(&text, "walker.toml").unwrap();
    let board = BestBrain::default();
    let mut show = Exhibition::new(problem.clone(), board.clone()).unwrap();
    assert!(show.note().unwrap().contains("the scene's own brain"));
    let dt = show.dt();
    for _ in 0..100 {
        show.step(dt).unwrap();
    }
    let mut g = problem.start().to_vec();
    g[0] = 3.0; // another frequency
    board.set_best(&g, 123.0, 0);
    // The first best is shown at once, from the start.
    show.step(dt).unwrap();
    assert_eq!(show.time(), 0.0);
    let note = show.note().unwrap();
    assert!(note.contains("showing fitness 123.00 (lane 0)"), "{note}");
    // A better one waits for the run shown (0.5 s) to end.
    g[0] = 2.5;
    board.set_best(&g, 150.0, 1);
    let mut steps = 0;
    loop {
        let before = show.time();
        show.step(dt).unwrap();
        steps += 1;
        if show.time() < before {
            break;
        }
        assert!(steps < 2000, "the run of 0.5 s ends");
    }
    assert!(steps >= 999, "it finished the run first: {steps} steps");
    assert!(show
        .note()
        .unwrap()
        .contains("showing fitness 150.00 (lane 1)"));
    assert!(show.focus().is_some(), "it follows the [evolve] particles");
}

/// `evolve SCENE --view` of a `[morphology]` scene: until the first best, a
/// random body that passes the checks; then the best body and brain, built
/// as `best.toml` is, from their start, moving as `evaluate` moves them.
#[test]
fn a_bodies_exhibition_shows_the_best_body_as_best_toml_builds_it() {
    use animats_creatures::random::Random;
    use animats_scene::evaluate::evaluate_with;
    use animats_scene::morphology::MorphologyProblem;
    use animats_viewer::BestBrain;
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/bodies_walk.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let problem = MorphologyProblem::parse(&text, "bodies_walk.toml").unwrap();
    let valid = |seed: u64| {
        (0..20)
            .map(|k| problem.random(&mut Random::for_entry(seed, k)))
            .find(|g| problem.check(g).is_ok())
            .expect("a random body that passes the checks")
    };
    let board = BestBrain::default();
    let mut show = Exhibition::bodies(problem.clone(), board.clone()).unwrap();
    let note = show.note().unwrap();
    assert!(
        note.contains("best fitness none yet; showing a random body"),
        "{note}"
    );
    let first = problem.body(&valid(0)).unwrap().nodes.len();
    assert_eq!(show.describe().particles.len(), first);
    assert!(show.describe().title.contains("best body and brain"));
    let dt = show.dt();
    for _ in 0..50 {
        show.step(dt).unwrap();
    }

    // Another body becomes the best: shown at once, from its start.
    let best = valid(7);
    let n = problem.body(&best).unwrap().nodes.len();
    board.set_best(&best, 1.5, 0);
    show.step(dt).unwrap();
    assert_eq!(show.time(), 0.0);
    assert_eq!(show.describe().particles.len(), n);
    let note = show.note().unwrap();
    assert!(note.contains("showing fitness 1.50 (lane 0)"), "{note}");

    // It moves as `evaluate` of its best.toml moves it.
    let scene = animats_scene::parse(&problem.develop(&best, "").unwrap(), "best.toml").unwrap();
    let mut reference = Vec::new();
    evaluate_with(scene, |s| {
        reference.push(s.world.position(s.particle("body.p0").unwrap()));
    })
    .expect("evaluate");
    let mut p = Vec::new();
    let mut compared = 0;
    for (k, r) in reference.iter().enumerate().take(2001).skip(1) {
        show.step(dt).expect("step");
        if k % 250 == 0 {
            show.positions(&mut p);
            let p0 = [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])];
            assert!(
                (p0[0] - r.x).abs() < 1e-5
                    && (p0[1] - r.y).abs() < 1e-5
                    && (p0[2] - r.z).abs() < 1e-5,
                "step {k}: {p0:?} vs {r}"
            );
            compared += 1;
        }
    }
    assert_eq!(compared, 8);
}

/// The overlay's distance and fitness are the evaluation's, step by step:
/// at the end of the run they are what `animats evaluate` prints.
#[test]
fn the_overlay_gives_the_distance_and_fitness_so_far() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/walker_evolved.toml");
    let e = animats_scene::evaluate::evaluate(animats_scene::load(&path).unwrap()).unwrap();
    let mut stage = SceneStage::load(path).unwrap();
    assert!(stage
        .note()
        .unwrap()
        .starts_with("distance 0.00 m · fitness 0.0"));
    let dt = stage.dt();
    for _ in 0..(e.time / dt).round() as usize {
        stage.step(dt).unwrap();
    }
    let (d, f) = stage.progress().unwrap();
    assert_eq!(d, e.distance);
    assert!(
        (f - e.fitness).abs() < 1e-9 * e.fitness,
        "{f} vs {}",
        e.fitness
    );
    let note = stage.note().unwrap();
    assert!(
        note.contains(&format!("distance {:.2} m", e.distance)),
        "{note}"
    );
}

#[test]
fn the_piles_overlay_counts_the_rocks_asleep() {
    // `scenes/pile.toml` lets its rocks sleep: none at the start, most once
    // the heap has settled (the count is the contact's own).
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/pile.toml");
    let mut stage = SceneStage::load(path).expect("scene");
    let count = |stage: &SceneStage| -> usize {
        let note = stage.note().expect("a note about sleeping");
        note.split_whitespace()
            .next()
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no count in {note:?}"))
    };
    assert_eq!(count(&stage), 0);
    let dt = stage.dt();
    while stage.time() < 6.0 {
        stage.step(dt).expect("the pile steps");
    }
    let asleep = count(&stage);
    println!("{:?}", stage.note());
    assert!(
        asleep > 100 && asleep <= 200,
        "{asleep} of 200 rocks asleep"
    );
    // SeaWorld has no sleeping spheres, and no note.
    assert_eq!(seaworld().note(), None);
}
