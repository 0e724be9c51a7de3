//! `[morphology]` (issue 39): how a body develops into scene entries, how
//! a lattice grows into one, every check on the way, and 100,000 random
//! variations from the shipped start bodies, each valid or refused with a
//! reason.

use animats_creatures::random::Random;
use animats_engine::DVec3;
use animats_scene::evaluate::SceneProblem;
use animats_scene::morphology::check::{static_checks, Refusal};
use animats_scene::morphology::lattice::{Lattice, Material};
use animats_scene::morphology::{Body, Edge, MorphologyProblem, Muscle, Node};

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

fn walk() -> String {
    std::fs::read_to_string(format!("{ROOT}/scenes/bodies_walk.toml")).unwrap()
}

fn with(morphology: &str) -> String {
    format!(
        "[world]\ndt = 0.001\n[floor]\n[morphology]\n{morphology}\n[evolve]\nduration = 1.0\ndistance_weight = 1.0\ntime_weight = 0.0\n"
    )
}

fn node(x: f64, y: f64, z: f64) -> Node {
    Node {
        position: DVec3::new(x, y, z),
        mass: 0.1,
        radius: 0.02,
    }
}

fn edge(a: usize, b: usize, muscle: bool) -> Edge {
    Edge {
        a,
        b,
        stiffness: 400.0,
        muscle: muscle.then_some(Muscle {
            amplitude: 0.3,
            phase: 0.5,
            offset: 0.5,
            touch: [0.0; 2],
            duty: 0.5,
        }),
    }
}

/// A tetrahedron with one muscle (not symmetric in x, or the muscle could
/// not move its centre of mass along x at all).
fn tetra() -> Body {
    Body {
        nodes: vec![
            node(0.0, 0.0, 0.0),
            node(0.2, 0.0, 0.0),
            node(0.1, 0.0, 0.17),
            node(0.15, 0.15, 0.06),
        ],
        edges: vec![
            edge(0, 1, true),
            edge(0, 2, false),
            edge(1, 2, false),
            edge(0, 3, false),
            edge(1, 3, false),
            edge(2, 3, false),
        ],
        frequency: 2.0,
        neural: false,
        skewed: false,
    }
}

#[test]
fn a_body_develops_into_ordinary_entries_on_the_floor() {
    let p = MorphologyProblem::parse(&walk(), "bodies_walk.toml").unwrap();
    let body = tetra();
    let text = p.develop(&body.to_genes(), "a tetrahedron").unwrap();
    assert!(text.starts_with("# a tetrahedron\n"));
    assert!(!text.contains("[morphology]"));
    let scene = animats_scene::parse(&text, "t.toml").unwrap();
    assert_eq!(scene.world.len(), 4);
    // The lowest sphere rests on the floor; the bounding box is centred on
    // the origin in x and z; the shape is the genome's.
    let y: Vec<f64> = (0..4).map(|i| scene.world.particles().radius[i]).collect();
    let at: Vec<DVec3> = scene
        .world
        .particle_ids()
        .map(|p| scene.world.position(p))
        .collect();
    let bottom = at
        .iter()
        .zip(&y)
        .map(|(p, r)| p.y - r)
        .fold(f64::INFINITY, f64::min);
    assert!(bottom.abs() < 1e-15, "{bottom}");
    assert!((at[0].x + at[1].x).abs() < 1e-15 && (at[0].z + at[2].z).abs() < 1e-15);
    assert!(((at[3] - at[0]) - (body.nodes[3].position - body.nodes[0].position)).length() < 1e-15);
    // The muscle: a spring actuator from 0.7 to 1.3 of its built length.
    let length = (at[1] - at[0]).length();
    assert!(text.contains(&format!("min = {}", length * 0.7)), "{text}");
    assert!(text.contains(&format!("max = {}", length * 1.3)));
    assert!(text.contains("rate = 4.0"));
    assert!(text.contains("model = \"penalty\""));
    // The [evolve] table is the scene's, targeting the body's oscillator,
    // robust by default.
    let problem = SceneProblem::parse(&text, "t.toml").unwrap();
    assert_eq!(problem.spec().controller.as_deref(), Some("body"));
    assert!(problem.spec().robust);
    assert_eq!(problem.start(), &[2.0, 0.3, 0.5, 0.5][..]);
    // What evolution scores is what `evaluate` scores, to the bit.
    let e = p.evaluate(&body.to_genes()).unwrap();
    let again = problem.evaluate(problem.start()).unwrap();
    assert_eq!(e.fitness.to_bits(), again.fitness.to_bits());
}

/// Two spheres and a muscle with touch weights `touch`, no oscillation
/// (amplitude 0, offset ½), built with their lowest points at `height`;
/// the muscle's length over its built length after 1 s.
fn reflex(touch: [f64; 2], height: f64) -> f64 {
    let text = with(&format!(
        "controller = \"neural\"\norigin = [0.0, {height}, 0.0]"
    ));
    let p = MorphologyProblem::parse(&text, "n.toml").unwrap();
    let body = Body {
        nodes: vec![node(0.0, 0.0, 0.0), node(0.2, 0.0, 0.0)],
        edges: vec![Edge {
            a: 0,
            b: 1,
            stiffness: 400.0,
            muscle: Some(Muscle {
                amplitude: 0.0,
                phase: 0.0,
                offset: 0.5,
                touch,
                duty: 0.5,
            }),
        }],
        frequency: 1.0,
        neural: true,
        skewed: false,
    };
    let genes = body.to_genes();
    assert_eq!(p.check(&genes), Ok(()), "a valid neural body");
    let developed = p.develop(&genes, "").unwrap();
    assert!(developed.contains("kind = \"touch\"") && developed.contains("kind = \"neural\""));
    let mut scene = animats_scene::parse(&developed, "n.toml").unwrap();
    let (a, b) = (
        scene.particle("body.p0").unwrap(),
        scene.particle("body.p1").unwrap(),
    );
    let built = (scene.world.position(a) - scene.world.position(b)).length();
    scene.steps(1000, 0.001).unwrap();
    (scene.world.position(a) - scene.world.position(b)).length() / built
}

/// A `neural` body's muscles feel the floor: with both touch weights 1 a
/// muscle whose ends rest on the floor is driven to σ(4) = 0.982 of its
/// range, a rest length of 0.7 + 0.6 × 0.982 = 1.289 of its built length,
/// give or take what static friction can hold (μ_s m g = 0.98 N on a
/// 400 N/m spring of 0.2 m: 0.012 of its length); the same muscle falling
/// through the air (10 m up: 4.9 m of fall in the second), or with both
/// weights 0, stays at level ½, its built length.
#[test]
fn a_neural_body_feels_the_floor() {
    let on_floor = reflex([1.0, 1.0], 0.0);
    let in_air = reflex([1.0, 1.0], 10.0);
    let numb = reflex([0.0, 0.0], 0.0);
    println!("on the floor {on_floor}, in the air {in_air}, numb {numb}");
    assert!((on_floor - 1.289).abs() < 0.013, "{on_floor}");
    assert!((in_air - 1.0).abs() < 1e-3, "{in_air}");
    assert!((numb - 1.0).abs() < 1e-3, "{numb}");
    // A neural genome is not an oscillator body's.
    let p = MorphologyProblem::parse(&walk(), "bodies_walk.toml").unwrap();
    let mut b = tetra();
    b.neural = true;
    assert_eq!(static_checks(&b, p.morphology()), Err(Refusal::Malformed));
}

#[test]
fn robust_evaluation_keeps_the_worse_of_the_step_and_half_of_it() {
    let p = MorphologyProblem::parse(&walk(), "bodies_walk.toml").unwrap();
    let text = p.develop(&tetra().to_genes(), "").unwrap();
    let robust = SceneProblem::parse(&text, "t.toml").unwrap();
    let once = |dt_scale: f64| {
        let mut s = robust.scene(robust.start()).unwrap();
        s.dt *= dt_scale;
        animats_scene::evaluate::evaluate(s).unwrap().fitness
    };
    let (coarse, fine) = (once(1.0), once(0.5));
    assert_ne!(coarse, fine, "the two steps give different numbers");
    let r = robust.evaluate(robust.start()).unwrap().fitness;
    assert_eq!(r, coarse.min(fine));
}

/// `robust_halvings = h` keeps the worst of the runs at the step and at
/// each of its `h` halvings, each the engine's run at that step to the
/// bit; a screen that says no after the first run keeps that run alone,
/// and one that says no after the half step keeps the worse of the two.
/// The body: the land task's seed-5 best (`fragile_walker.toml`), whose
/// gait has a second mode: robust scoring at the step and half of it lets
/// it through (6.36 m, both runs alike to 1e-3), but its own integrator at
/// a quarter of the step falls into a gait worth a tenth of that.
#[test]
fn robust_halvings_keep_the_worst_of_every_finer_step() {
    let text = include_str!("fragile_walker.toml");
    let at = |halvings: u32| {
        let t = text.replacen(
            "[evolve]",
            &format!("[evolve]\nrobust_halvings = {halvings}"),
            1,
        );
        SceneProblem::parse(&t, "fragile_walker.toml").unwrap()
    };
    let base = at(1);
    assert!(base.spec().robust);
    let once = |dt_scale: f64| {
        let mut s = base.scene(base.start()).unwrap();
        s.dt *= dt_scale;
        animats_scene::evaluate::evaluate(s).unwrap().fitness
    };
    let runs = [once(1.0), once(0.5), once(0.25), once(0.125)];
    println!("at dt, dt/2, dt/4, dt/8: {runs:?}");
    // Robust scoring lets the gait through; a quarter of the step does not.
    assert!(
        runs[0] > 6.0 && (runs[0] - runs[1]).abs() < 1e-3 * runs[0],
        "{runs:?}"
    );
    assert!(runs[2] < 0.2 * runs[0], "{runs:?}");
    let worst = |n: usize| runs[..n].iter().copied().fold(f64::INFINITY, f64::min);
    for h in 1..=3u32 {
        let p = at(h);
        assert_eq!(p.spec().robust_halvings, h);
        let got = p.evaluate(p.start()).unwrap().fitness;
        assert_eq!(got, worst(h as usize + 1), "{h} halvings");
        // Screened: after the first run nothing more; after the half step
        // nothing more (the quarter step's run is not made).
        let make = || p.scene(p.start());
        let first = animats_scene::evaluate::score_screened(make, &|_| false).unwrap();
        assert_eq!(first.fitness, runs[0]);
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let two = animats_scene::evaluate::score_screened(make, &|_| {
            calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) == 0
        })
        .unwrap();
        assert_eq!(two.fitness, worst(2), "{h} halvings, screened after two");
        assert_eq!(calls.into_inner(), 2.min(h as usize), "{h} halvings");
    }
}

#[test]
fn a_lattice_grows_shared_corners_and_muscles_along_their_axis() {
    let text = with("encoding = \"lattice\"\ncells = [2, 1, 1]\ncell = 0.1\nmax_particles = 12\nmax_springs = 60\nmass = [0.001, 0.3]");
    let p = MorphologyProblem::parse(&text, "l.toml").unwrap();
    let shape = p.morphology().lattice.clone().unwrap();
    let one = Lattice {
        materials: vec![Material::MuscleX, Material::Empty],
        muscles: vec![
            Muscle {
                amplitude: 0.2,
                phase: 0.0,
                offset: 0.5,
                touch: [0.0; 2],
                duty: 0.5,
            };
            2
        ],
        frequency: 1.0,
        neural: false,
    };
    let b = one.develop(&shape, p.morphology());
    // A cube: 8 corners, 12 edges and 12 face diagonals; its 4 x edges are
    // muscles; the cell weighs the budget over the lattice's 2 cells.
    assert_eq!((b.nodes.len(), b.edges.len(), b.muscles()), (8, 24, 4));
    assert!((b.mass() - 0.8 / 2.0).abs() < 1e-12);
    for e in b.edges.iter().filter(|e| e.muscle.is_some()) {
        let d = b.nodes[e.b].position - b.nodes[e.a].position;
        assert!(d.y == 0.0 && d.z == 0.0 && (d.x.abs() - 0.1).abs() < 1e-15);
    }
    // Two cells share a face: 12 corners, 24 + 24 − 6 springs.
    let two = Lattice {
        materials: vec![Material::Soft, Material::Rigid],
        ..one.clone()
    };
    let b = two.develop(&shape, p.morphology());
    assert_eq!((b.nodes.len(), b.edges.len(), b.muscles()), (12, 42, 0));
    assert!(p.check(&two.to_genes(&shape)).unwrap_err() == Refusal::NoMuscle);
    assert!(
        p.check(&one.to_genes(&shape)).is_ok(),
        "{:?}",
        p.check(&one.to_genes(&shape))
    );
}

/// One muscle cell of a `neural` lattice (its four x edges muscles, touch
/// weights `touch`, no oscillation), its lowest points at `height`: the
/// bottom muscles' mean length over their built length after 1 s.
fn lattice_reflex(touch: [f64; 2], height: f64) -> f64 {
    let text = with(&format!(
        "encoding = \"lattice\"\ncells = [1, 1, 1]\ncell = 0.1\nmax_particles = 8\nmax_springs = 24\nmass = [0.001, 0.3]\ncontroller = \"neural\"\norigin = [0.0, {height}, 0.0]"
    ));
    let p = MorphologyProblem::parse(&text, "nl.toml").unwrap();
    let shape = p.morphology().lattice.clone().unwrap();
    let cell = Lattice {
        materials: vec![Material::MuscleX],
        muscles: vec![Muscle {
            amplitude: 0.0,
            phase: 0.0,
            offset: 0.5,
            touch,
            duty: 0.5,
        }],
        frequency: 1.0,
        neural: true,
    };
    let genes = cell.to_genes(&shape);
    // [4, nx, ny, nz, f], a material, then five genes a cell.
    assert_eq!(genes.len(), 5 + 1 + 5);
    assert_eq!(genes[0], 4.0);
    assert_eq!(Lattice::from_genes(&genes, &shape).unwrap(), cell);
    let body = p.body(&genes).unwrap();
    assert!(body.neural);
    assert!(body
        .edges
        .iter()
        .filter_map(|e| e.muscle)
        .all(|m| m.touch == touch));
    assert_eq!(p.check(&genes), Ok(()), "a valid neural lattice");
    let developed = p.develop(&genes, "").unwrap();
    assert!(developed.contains("kind = \"touch\"") && developed.contains("kind = \"neural\""));
    let mut scene = animats_scene::parse(&developed, "nl.toml").unwrap();
    let bottom: Vec<_> = body
        .edges
        .iter()
        .filter(|e| e.muscle.is_some())
        .filter(|e| body.nodes[e.a].position.y == 0.0 && body.nodes[e.b].position.y == 0.0)
        .map(|e| {
            let (a, b) = (
                scene.particle(&format!("body.p{}", e.a)).unwrap(),
                scene.particle(&format!("body.p{}", e.b)).unwrap(),
            );
            (a, b)
        })
        .collect();
    assert_eq!(bottom.len(), 2, "two x muscles on the bottom face");
    let length = |s: &animats_scene::Scene| -> f64 {
        bottom
            .iter()
            .map(|&(a, b)| (s.world.position(a) - s.world.position(b)).length())
            .sum::<f64>()
            / 2.0
    };
    let built = length(&scene);
    scene.steps(1000, 0.001).unwrap();
    length(&scene) / built
}

/// A `neural` lattice's muscles feel the floor as a graph body's do: with
/// touch weights 1 the bottom muscles, their ends on the floor, are driven
/// towards σ(4) = 0.982 of their range and lengthen (the cube's other
/// springs resist, so by less than the bare muscle's 29 %); with weights
/// 0, or falling through the air, the network's inputs are zero and the
/// muscles hold level ½, to the bit the same either way.
#[test]
fn a_neural_lattice_feels_the_floor() {
    let on_floor = lattice_reflex([1.0, 1.0], 0.0);
    let numb = lattice_reflex([0.0, 0.0], 0.0);
    let in_air = lattice_reflex([1.0, 1.0], 10.0);
    let numb_in_air = lattice_reflex([0.0, 0.0], 10.0);
    println!(
        "on the floor {on_floor}, numb {numb}, in the air {in_air}, numb in the air {numb_in_air}"
    );
    assert!(on_floor > numb + 0.05, "{on_floor} vs {numb}");
    assert!((numb - 1.0).abs() < 0.01, "{numb}");
    assert_eq!(in_air.to_bits(), numb_in_air.to_bits());
    // A neural lattice genome is not an oscillator lattice's.
    let text = std::fs::read_to_string(format!("{ROOT}/scenes/bodies_lattice.toml")).unwrap();
    let p = MorphologyProblem::parse(&text, "bodies_lattice.toml").unwrap();
    let shape = p.morphology().lattice.clone().unwrap();
    let mut l = Lattice::from_genes(p.start().unwrap(), &shape).unwrap();
    l.neural = true;
    assert_eq!(p.check(&l.to_genes(&shape)), Err(Refusal::Malformed));
}

#[test]
fn an_evogym_structure_is_a_starting_body() {
    let text = std::fs::read_to_string(format!("{ROOT}/scenes/bodies_lattice.toml")).unwrap();
    let p = MorphologyProblem::parse(&text, "bodies_lattice.toml").unwrap();
    let start = p.start().expect("the structure is the start");
    let shape = p.morphology().lattice.clone().unwrap();
    let l = Lattice::from_genes(start, &shape).unwrap();
    // EvoGym's rows run top to bottom: the bottom row is y = 0.
    let [nx, ny, nz] = shape.cells;
    let painted = l
        .materials
        .iter()
        .filter(|m| **m != Material::Empty)
        .count();
    assert!(painted > 0 && painted < nx * ny * nz);
    assert!(p.check(start).is_ok(), "{:?}", p.check(start));
    let scene = animats_scene::parse(&text, "bodies_lattice.toml").unwrap();
    assert_eq!(scene.world.len(), p.body(start).unwrap().nodes.len());
}

/// A step too small for the evaluation is refused as it is on a random
/// start (`evolve.duration` names the steps), before the start body's
/// settle would take 0.5 s of them: with `dt = 1e-300` that settle ran on
/// for ever. The error names the line of the user's file where `[evolve]`'s
/// `duration` is written (it named the line of the body's developed text).
#[test]
fn a_start_body_with_a_step_too_small_is_refused_before_it_settles() {
    for name in ["bodies_lattice", "bodies_walk"] {
        let text = std::fs::read_to_string(format!("{ROOT}/scenes/{name}.toml")).unwrap();
        let tiny = text.replacen("dt = 0.0005", "dt = 1e-300", 1);
        assert_ne!(tiny, text);
        let evolve = text.lines().position(|l| l == "[evolve]").unwrap();
        let line = evolve
            + 1
            + text
                .lines()
                .skip(evolve)
                .position(|l| l.starts_with("duration ="))
                .unwrap();
        let e = MorphologyProblem::parse(&tiny, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!("m.toml:{line}: evolve.duration: "))
                && e.contains("more than 1e12"),
            "{name}: {e}"
        );
    }
}

#[test]
fn every_check_names_its_reason() {
    let p = MorphologyProblem::parse(&walk(), "bodies_walk.toml").unwrap();
    let m = p.morphology();
    let ok = tetra();
    assert_eq!(static_checks(&ok, m), Ok(()));
    let mut b = ok.clone();
    b.edges.push(edge(1, 0, false));
    assert_eq!(static_checks(&b, m), Err(Refusal::Malformed));
    let mut b = ok.clone();
    b.nodes.push(node(0.3, 0.0, 0.0));
    assert_eq!(static_checks(&b, m), Err(Refusal::Disconnected));
    let mut b = ok.clone();
    b.nodes[3].position = DVec3::new(0.01, 0.0, 0.0);
    assert_eq!(static_checks(&b, m), Err(Refusal::Overlap));
    let mut b = ok.clone();
    b.nodes[1].position.x = 0.5;
    assert_eq!(static_checks(&b, m), Err(Refusal::Size));
    let mut b = ok.clone();
    b.nodes.iter_mut().for_each(|n| n.mass = 0.25);
    assert_eq!(static_checks(&b, m), Err(Refusal::Mass));
    let mut b = ok.clone();
    b.edges[2].stiffness = 900.0;
    assert_eq!(static_checks(&b, m), Err(Refusal::Range));
    let mut b = ok.clone();
    b.edges[0].muscle = None;
    assert_eq!(static_checks(&b, m), Err(Refusal::NoMuscle));
    let mut b = ok.clone();
    b.nodes.truncate(1);
    b.edges.clear();
    assert_eq!(static_checks(&b, m), Err(Refusal::Particles));
    // The settle: the tetrahedron stands; a triangle standing on its edge,
    // leaning 14° off the vertical, falls flat.
    assert_eq!(p.check(&ok.to_genes()), Ok(()));
    let triangle = Body {
        nodes: vec![
            node(0.0, 0.0, 0.0),
            node(0.2, 0.0, 0.0),
            node(0.1, 0.2, 0.05),
        ],
        edges: vec![edge(0, 1, true), edge(1, 2, false), edge(0, 2, false)],
        frequency: 1.0,
        neural: false,
        skewed: false,
    };
    assert_eq!(static_checks(&triangle, m), Ok(()));
    assert_eq!(p.check(&triangle.to_genes()), Err(Refusal::SettleFlat));
}

#[test]
fn bad_morphology_keys_are_refused_naming_the_field() {
    let cases = [
        ("total_mass = 0.0", "morphology.total_mass"),
        ("max_particles = 1", "morphology.max_particles"),
        (
            "max_particles = 4\nmax_springs = 7",
            "morphology.max_springs",
        ),
        (
            "stiffness = [800.0, 50.0]",
            "morphology.stiffness: must be [lo, hi] with 0 < lo <= hi, got [800, 50]",
        ),
        ("encoding = \"voxels\"", "voxels"),
        (
            "encoding = \"lattice\"\ncells = [101, 100, 1]",
            "morphology.cells",
        ),
        // (Its corners' penalty contact named `contacts.particles` of the
        // developed text, at line 1,070,220 of a 12-line file.)
        (
            "encoding = \"lattice\"\ncells = [40, 40, 1]",
            "morphology.cells: [40, 40, 1]: up to 3362 particles",
        ),
        (
            "encoding = \"lattice\"\ncells = [2, 1, 1]\nstructure = [[1, 7]]",
            "morphology.structure",
        ),
        (
            "encoding = \"lattice\"\ncells = [2, 1, 1]\nstructure = [[1]]",
            "morphology.structure",
        ),
        ("cells = [2, 2, 2]", "morphology.cells"),
        ("waveform = \"square\"", "square"),
        (
            "waveform = \"skewed\"\ncontroller = \"neural\"",
            "morphology.waveform",
        ),
        (
            "waveform = \"skewed\"\nencoding = \"lattice\"\ncells = [2, 1, 1]",
            "morphology.waveform",
        ),
        ("start = \"nowhere.toml\"", "morphology.start"),
        ("size = 0.01", "morphology.size"),
        // (Far past a kilometre its built lengths overflowed: the error
        // named a spring of the developed text.)
        ("size = 1e300", "morphology.size: must be at most 1000 m"),
        ("wings = 2", "wings"),
    ];
    for (key, expect) in cases {
        let e = MorphologyProblem::parse(&with(key), "m.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.toml:") && e.contains(expect), "{key}: {e}");
    }
    // Touch sensors need a floor.
    let e = MorphologyProblem::parse(
        &with("controller = \"neural\"").replace("[floor]\n", ""),
        "m.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("morphology.controller") && e.contains("no [floor]"),
        "{e}"
    );
    // An [evolve] that names another controller; a body that fails its own
    // checks as a start.
    let t = with("").replace("[evolve]\n", "[evolve]\ncontroller = \"gait\"\n");
    let e = MorphologyProblem::parse(&t, "m.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("evolve.controller"), "{e}");
    let dir = std::env::temp_dir().join(format!("animats-morph-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("lone.toml"),
        "[[particle]]\nname = \"a\"\nmass = 0.1\nposition = [0.0, 0.1, 0.0]\nradius = 0.02\n",
    )
    .unwrap();
    let e = MorphologyProblem::parse(
        &with("start = \"lone.toml\""),
        dir.join("m.toml").to_str().unwrap(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("morphology.start") && e.contains("fails its own checks: particles"),
        "{e}"
    );
    // A start that is itself a [morphology] scene (here, the scene itself:
    // it recursed until the stack overflowed) is refused.
    let itself = with("start = \"self.toml\"");
    std::fs::write(dir.join("self.toml"), &itself).unwrap();
    let e = MorphologyProblem::parse(&itself, dir.join("self.toml").to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("morphology.start") && e.contains("has a [morphology] table of its own"),
        "{e}"
    );
    // A start whose oscillator has `duty`: refused by a sine body, which
    // would drop it; a skewed body takes it, and a duty outside its genes'
    // range fails the start's checks rather than being moved.
    let walker = std::fs::read_to_string(format!("{ROOT}/scenes/walker.toml")).unwrap();
    let offsets = "offset = [0.5, 0.5, 0.5, 0.5, 0.5, 0.5]\n";
    assert!(walker.contains(offsets));
    for (duty, waveform, expect) in [
        ("0.3", "", Some("add `waveform = \"skewed\"`")),
        ("0.3", "waveform = \"skewed\"", None),
        (
            "0.95",
            "waveform = \"skewed\"",
            Some("fails its own checks: range"),
        ),
    ] {
        let skewed = walker.replace(
            offsets,
            &format!("{offsets}duty = [{duty}, 0.5, 0.5, 0.5, 0.5, 0.5]\n"),
        );
        std::fs::write(dir.join("skewed.toml"), skewed).unwrap();
        let got = MorphologyProblem::parse(
            &with(&format!("start = \"skewed.toml\"\n{waveform}")),
            dir.join("m.toml").to_str().unwrap(),
        );
        match (got, expect) {
            (Ok(p), None) => {
                // The first muscle's duty is the start's, to the bit.
                let body = p.body(p.start().unwrap()).unwrap();
                let first = body.edges.iter().find_map(|e| e.muscle.as_ref()).unwrap();
                assert_eq!(first.duty, 0.3);
            }
            (Err(e), Some(expect)) => {
                let e = e.to_string();
                assert!(e.contains("morphology.start") && e.contains(expect), "{e}");
            }
            (got, _) => panic!("duty {duty}, `{waveform}`: {:?}", got.err()),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    // A scene with [morphology] is not built as it is.
    let e = animats_scene::build::build(
        &animats_scene::parse_def(&animats_scene::source::Source {
            file: "m.toml",
            text: &with(""),
        })
        .unwrap(),
        &animats_scene::source::Source {
            file: "m.toml",
            text: &with(""),
        },
    )
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("describes bodies"), "{e}");
}

/// 100,000 variations (mutants and crossovers, chained as evolution chains
/// them) from each shipped start (random graph bodies, with either
/// controller; the soft walker; the EvoGym lattice, with either controller):
/// every one is a body that passes the
/// checks that need no simulation or is refused with a reason, none
/// panics; every 100th also runs the settle.
#[test]
fn a_hundred_thousand_random_variations_are_valid_or_refused_with_a_reason() {
    let walker_start = with("start = \"walker.toml\"");
    let scenes = [
        (walk(), "bodies_walk.toml".to_string()),
        (
            std::fs::read_to_string(format!("{ROOT}/scenes/bodies_walk_neural.toml")).unwrap(),
            "bodies_walk_neural.toml".to_string(),
        ),
        (walker_start, format!("{ROOT}/scenes/from_walker.toml")),
        (
            std::fs::read_to_string(format!("{ROOT}/scenes/bodies_lattice.toml")).unwrap(),
            "bodies_lattice.toml".to_string(),
        ),
        (
            std::fs::read_to_string(format!("{ROOT}/scenes/bodies_lattice.toml"))
                .unwrap()
                .replace("controller = \"oscillator\"", "controller = \"neural\""),
            "bodies_lattice.toml, neural".to_string(),
        ),
        (
            std::fs::read_to_string(format!("{ROOT}/scenes/bodies_swim.toml"))
                .unwrap()
                .replace("[morphology]\n", "[morphology]\nwaveform = \"skewed\"\n"),
            "bodies_swim.toml, skewed".to_string(),
        ),
    ];
    let per = 100_000 / scenes.len() + 1;
    let mut refused = std::collections::BTreeMap::<&str, usize>::new();
    let mut valid = 0usize;
    for (k, (text, file)) in scenes.iter().enumerate() {
        let p = MorphologyProblem::parse(text, file).unwrap();
        let mut rng = Random::for_entry(7, k as u64);
        let start = p
            .start()
            .map(<[f64]>::to_vec)
            .unwrap_or_else(|| p.random(&mut rng));
        let mut pool = vec![start];
        for i in 0..per {
            let a = &pool[(rng.uniform() * pool.len() as f64) as usize];
            let child = if rng.uniform() < 0.25 {
                let b = &pool[(rng.uniform() * pool.len() as f64) as usize];
                p.crossover(a, b, &mut rng)
            } else {
                p.mutate(a, &mut rng)
            };
            let body = p.body(&child).expect("variation keeps the genome's layout");
            let verdict = if i % 100 == 0 {
                p.check(&child)
            } else {
                static_checks(&body, p.morphology())
            };
            match verdict {
                Ok(()) => {
                    valid += 1;
                    if pool.len() < 64 {
                        pool.push(child);
                    } else {
                        let j = (rng.uniform() * 64.0) as usize;
                        pool[j] = child;
                    }
                }
                Err(r) => *refused.entry(r.name()).or_insert(0) += 1,
            }
        }
    }
    let total: usize = valid + refused.values().sum::<usize>();
    println!("{total} variations: {valid} valid, refused {refused:?}");
    assert!(total >= 100_000);
    assert!(
        valid > total / 10,
        "variation mostly makes bodies: {valid} of {total}"
    );
}

/// The body the sphere-contact event pumped to 64 m in 10 s: with penalty
/// contact (what developed bodies get) its muscles move it centimetres.
#[test]
fn penalty_contact_gives_the_pumping_body_nothing() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/pumping_body.toml"
    ))
    .unwrap();
    let distance = |text: &str| {
        let p = SceneProblem::parse(text, "pumping_body.toml").unwrap();
        p.evaluate(p.start()).unwrap().distance
    };
    let event = distance(&text);
    let penalty = distance(&text.replace("[contacts]\n", "[contacts]\nmodel = \"penalty\"\n"));
    println!("the event: {event} m; penalty contact: {penalty} m");
    assert!(penalty.abs() < 0.5, "{penalty} m");
}

/// Issue 39's goal in water, held by the shipped winner: the evolved
/// swimmer (`scenes/bodies_swim_evolved.toml`, the farthest of five
/// 10-minute runs of `scenes/bodies_swim.toml`, docs/BODIES.md) scores
/// what its header logged, to the bit; keeps at least 80 % of its
/// distance at a quarter of the step, with its own integrator and with
/// RK4 (a stroke tuned to the step's errors would not); and goes at least
/// twice as far as the thesis's jellyfish in the same water, scored by
/// the same rule (`scenes/jellyfish_swim.toml`), with less mass.
#[test]
fn the_evolved_swimmer_goes_twice_as_far_as_the_jellyfish_with_less_mass() {
    use animats_scene::evaluate::{checks_finer, score};
    let read = |name: &str| std::fs::read_to_string(format!("{ROOT}/scenes/{name}")).unwrap();
    let swimmer = read("bodies_swim_evolved.toml");
    let jelly = read("jellyfish_swim.toml");
    let make = |text: &str, file: &'static str| {
        let text = text.to_string();
        move || animats_scene::parse(&text, file).map_err(|e| e.to_string())
    };
    // The creature's mass: the swimmer's every particle, the jellyfish's
    // own (its scene also holds the food it swims towards).
    let mass = |text: &str, of: &str| -> f64 {
        let scene = animats_scene::parse(text, "mass").unwrap();
        let mass = &scene.world.particles().mass;
        let own = scene
            .names
            .iter()
            .zip(mass)
            .filter(|(n, _)| n.starts_with(of));
        own.map(|(_, m)| m).sum()
    };
    let logged: f64 = swimmer
        .lines()
        .find_map(|l| l.strip_prefix("# fitness "))
        .and_then(|l| l.split(',').next())
        .unwrap()
        .parse()
        .unwrap();
    let s = score(make(&swimmer, "bodies_swim_evolved.toml")).unwrap();
    assert_eq!(
        s.fitness.to_bits(),
        logged.to_bits(),
        "{} against {logged}",
        s.fitness
    );
    for (kind, dt, e) in checks_finer(make(&swimmer, "bodies_swim_evolved.toml")).unwrap() {
        println!("{kind:?} at {dt} s: {} m of {} m", e.distance, s.distance);
        assert!(
            e.distance >= 0.8 * s.distance,
            "{kind:?} at {dt} s: {} m",
            e.distance
        );
    }
    let j = score(make(&jelly, "jellyfish_swim.toml")).unwrap();
    let (ms, mj) = (mass(&swimmer, ""), mass(&jelly, "jelly."));
    println!(
        "swimmer {} m, {ms} kg; jellyfish {} m, {mj} kg: {:.2} times as far",
        s.distance,
        j.distance,
        s.distance / j.distance
    );
    assert!(j.distance > 5.0, "the jellyfish swims: {} m", j.distance);
    assert!(
        s.distance >= 2.0 * j.distance,
        "{} against {}",
        s.distance,
        j.distance
    );
    assert!((mj - 0.84).abs() < 1e-9, "Appendix B's jellyfish: {mj} kg");
    assert!(ms <= mj, "{ms} kg against {mj} kg");
}
