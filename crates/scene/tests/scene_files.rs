//! Every scene shipped in `scenes/` loads, validates and runs.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use std::path::{Path, PathBuf};

/// The `scenes/` folder and its scene files, sorted.
fn shipped_scenes() -> (PathBuf, Vec<PathBuf>) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("toml"))
        .collect();
    paths.sort();
    (dir, paths)
}

#[test]
fn every_shipped_scene_builds_and_runs_a_second() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let mut scene = animats_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!scene.names.is_empty(), "{}: empty scene", path.display());
        let steps = (1.0 / scene.dt).round() as usize;
        for _ in 0..steps {
            scene
                .step(scene.dt)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
        count += 1;
    }
    assert!(count >= 5, "only {count} scenes found in {}", dir.display());
}

#[test]
fn errors_name_the_line_of_the_field() {
    let text = "[world]\ndt = 0.01\n\n[[particle]]\nname = \"a\"\nmass = 1.0\nposition = [0, 0, 0]\nradius = 0.1\n\n[[particle]]\nname = \"b\"\nmass = -1.0\nposition = [1, 0, 0]\nradius = 0.1\n";
    let e = animats_scene::parse(text, "x.toml").err().unwrap();
    assert_eq!(e.line, Some(12), "the line of `mass`, not of [[particle]]");
    assert_eq!(e.entry.as_deref(), Some("particle[1]"));
    assert_eq!(e.field.as_deref(), Some("mass"));
    assert_eq!(
        e.to_string(),
        "x.toml:12: particle[1].mass: must be > 0, got -1"
    );
    // A field after a line whose comment names it: the assignment counts.
    let text = "[[particle]]\nname = \"a\"\nmass = 1.0\nposition = [0, 0, 0]\nradius = 0.1\n[[particle]]\nname = \"b\"\nmass = 1.0\nposition = [1, 0, 0]\nradius = 0.1\n[[spring]]\na = \"a\"\nb = \"b\"\nstiffness = 10.0 # rest_length = 1\nrest_length = -2.0\n";
    let e = animats_scene::parse(text, "y.toml").err().unwrap();
    assert_eq!(
        (e.line, e.field.as_deref()),
        (Some(15), Some("rest_length"))
    );
}

#[test]
fn defaults_are_those_of_the_contract() {
    let s = animats_scene::parse(
        "[[particle]]\nname = \"p\"\nmass = 2\nposition = [0, 1, 0]\nvolume = 0.001\n",
        "d.toml",
    )
    .unwrap();
    let p = s.world.particles();
    assert_eq!(
        (p.mu_s[0], p.mu_k[0], p.restitution[0], p.fixed[0]),
        (0.5, 0.3, 0.5, false)
    );
    // radius follows from volume for a sphere
    let r = (3.0 * 0.001 / (4.0 * std::f64::consts::PI)).cbrt();
    assert!((p.radius[0] - r).abs() < 1e-15);
    assert_eq!(s.dt, 0.001);
    assert_eq!(s.duration, 5.0);
    assert_eq!(s.world.integrator(), animats_engine::IntegratorKind::Rk4);
    assert_eq!(
        s.world.forces().g(),
        animats_engine::DVec3::new(0.0, -9.8, 0.0)
    );
}

/// A particle named twice in a list would be acted on (or counted) twice,
/// and an n-body group would pull it towards itself at no distance (its
/// energy −∞): every list of particles refuses it, naming the entry, the
/// field and the particle.
#[test]
fn a_particle_named_twice_in_a_list_is_refused() {
    let two = "[[particle]]\nname = \"a\"\nmass = 1.0\nposition = [0, 0.5, 0]\nradius = 0.1\n\
               [[particle]]\nname = \"b\"\nmass = 1.0\nposition = [1, 0.5, 0]\nradius = 0.1\n\
               [[spring]]\na = \"a\"\nb = \"b\"\nstiffness = 10.0\n";
    let list = "[\"a\", \"b\", \"a\"]";
    for (table, field) in [
        (format!("[[nbody]]\nparticles = {list}\n"), "nbody[0].particles"),
        (
            format!("[fluid]\ndensity = 1000.0\nparticles = {list}\n"),
            "fluid.particles",
        ),
        (format!("[floor]\nparticles = {list}\n"), "floor.particles"),
        (format!("[contacts]\nparticles = {list}\n"), "contacts.particles"),
        (
            format!("[[constant_force]]\nforce = [0, 1, 0]\nparticles = {list}\n"),
            "constant_force[0].particles",
        ),
        (
            format!("[evolve]\nduration = 1.0\nparticles = {list}\n"),
            "evolve.particles",
        ),
        (
            format!(
                "[evolve]\nduration = 1.0\n[archive]\nmeasures = [{{ kind = \"mean_height\", particles = {list} }}]\nbins = [4]\nranges = [[0.0, 1.0]]\n"
            ),
            "archive.measures[0].particles",
        ),
    ] {
        let text = format!("{two}{table}");
        let message = match animats_scene::parse(&text, "twice.toml") {
            Ok(_) => panic!("accepted {table}"),
            Err(e) => e.to_string(),
        };
        assert!(
            message.starts_with("twice.toml:")
                && message.contains(&format!(": {field}: `a` is listed twice")),
            "{table}: {message}"
        );
        // Each once is a scene.
        let once = text.replace(list, "[\"a\", \"b\"]");
        if let Err(e) = animats_scene::parse(&once, "once.toml") {
            panic!("{once}: {e}");
        }
    }
}

/// Every shipped scene, stepped a while, snapshot, stepped on (the
/// positions and velocities recorded at each step), then restored and
/// stepped again: the same states, bit for bit. Its brains' and
/// creatures' own state (an FSM's state, a network's activations, an
/// oscillator's phase, a jellyfish's timer) is part of the snapshot.
#[test]
fn a_restored_snapshot_of_every_shipped_scene_steps_to_the_same_bits() {
    let (dir, mut paths) = shipped_scenes();
    // The shipped CTRNN walker holds every weight at 0 (evolution writes
    // them): one with weights of its own, whose activations move.
    let ctrnn = std::fs::read_to_string(dir.join("walker_ctrnn.toml")).unwrap();
    let tau = "tau = [0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1]\n";
    assert!(ctrnn.contains(tau));
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let mut draw = |n: usize| -> String {
        let v: Vec<String> = (0..n)
            .map(|_| {
                x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                format!(
                    "{:.3}",
                    ((x >> 11) as f64 / (1u64 << 53) as f64) * 8.0 - 4.0
                )
            })
            .collect();
        format!("[{}]", v.join(", "))
    };
    let moving = ctrnn.replace(
        tau,
        &format!(
            "{tau}weights = {}\ninput_weights = {}\n",
            draw(64),
            draw(16)
        ),
    );
    let scratch = std::env::temp_dir().join(format!("animats-snap-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).unwrap();
    paths.push(scratch.join("walker_ctrnn_moving.toml"));
    std::fs::write(paths.last().unwrap(), moving).unwrap();
    let mut failed = Vec::new();
    for path in &paths {
        let mut scene = animats_scene::load(path).unwrap_or_else(|e| panic!("{e}"));
        let dt = scene.dt;
        // Past a second (a brain's first states, a muscle's first swing),
        // then half a second recorded twice.
        let (before, after) = ((1.3 / dt).round() as usize, (0.5 / dt).round() as usize);
        for _ in 0..before {
            scene
                .step(dt)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
        let snap = scene.snapshot();
        let record = |scene: &mut animats_scene::Scene| -> Vec<u64> {
            let mut bits = Vec::new();
            for _ in 0..after {
                scene
                    .step(dt)
                    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                for i in 0..scene.world.len() {
                    let id = animats_engine::ParticleId::from_index(i);
                    for v in [scene.world.position(id), scene.world.velocity(id)] {
                        bits.extend([v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]);
                    }
                }
            }
            bits
        };
        let first = record(&mut scene);
        scene
            .restore(&snap)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let again = record(&mut scene);
        if first != again {
            failed.push(path.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    let _ = std::fs::remove_dir_all(&scratch);
    assert!(
        failed.is_empty(),
        "restored and stepped differently: {failed:?}"
    );
}

/// Hostile values in every shipped scene: each key's line left out, and
/// each number written (the first of an array) replaced in turn by NaN,
/// ±∞, −1, 0, 10³⁰⁰ and 10⁻³⁰⁰. Whatever the scene,
/// its `[evolve]` and its `[morphology]` make of it, each is refused with
/// an error or builds and steps (until it blows up, for at most 100 steps
/// or 50 ms),
/// never panics, and takes at most a few seconds (`dt = 1e-300` in a
/// lattice scene once settled its start body for ever; a walker on rough
/// ground blown up to 10³⁰⁰ m overflowed the terrain's cell index).
#[test]
fn hostile_edits_of_every_shipped_scene_are_refused_or_run_never_panic() {
    use animats_scene::evaluate::SceneProblem;
    use animats_scene::morphology::MorphologyProblem;
    use std::panic::{catch_unwind, AssertUnwindSafe};
    const VALUES: [&str; 7] = ["nan", "inf", "-inf", "-1.0", "0", "1e300", "1e-300"];
    let (_, paths) = shipped_scenes();
    let (mut cases, mut refused, mut failures) = (0, 0, Vec::new());
    let mut slowest = (0.0, String::new());
    for path in &paths {
        let file = path.to_str().unwrap();
        let text = std::fs::read_to_string(path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let Some((key, value)) = line.split_once('=') else {
                continue;
            };
            let (key, value) = (key.trim(), value.trim_start());
            let is_key =
                !key.is_empty() && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !is_key {
                continue;
            }
            // The line left out, and the first number of the value (of an
            // array's first element) replaced by each of VALUES.
            let mut edits = vec![String::new()];
            let start = value.find(|c: char| c.is_ascii_digit() || c == '-');
            if let Some(start) = start.filter(|&s| value[..s].chars().all(|c| c == '[' || c == ' '))
            {
                let end = value[start..]
                    .find(|c: char| {
                        !(c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '+' | '_'))
                    })
                    .map_or(value.len(), |e| start + e);
                let prefix = &line[..line.len() - value.len()];
                edits.extend(
                    VALUES
                        .iter()
                        .map(|v| format!("{prefix}{}{v}{}", &value[..start], &value[end..])),
                );
            }
            for new_line in &edits {
                let mut edited = lines.clone();
                edited[i] = new_line;
                let text = edited.join("\n");
                let what = format!("{file}:{}: `{}` → `{new_line}`", i + 1, line.trim());
                let began = std::time::Instant::now();
                let outcome = catch_unwind(AssertUnwindSafe(|| {
                    let ok = if text.contains("[morphology]") {
                        MorphologyProblem::parse(&text, file).is_ok()
                    } else if text.contains("[evolve]") {
                        SceneProblem::parse(&text, file).is_ok()
                    } else {
                        true
                    };
                    match animats_scene::parse(&text, file) {
                        Ok(mut scene) if ok => {
                            // 100 steps, or fewer for a step past 0.5 ms
                            // (one of 10³⁰⁰ s, its collisions located by
                            // halving, takes a pile of rocks 1.5 s).
                            let steps = (0.05 / scene.dt).ceil().clamp(1.0, 100.0) as usize;
                            for _ in 0..steps {
                                if scene.step(scene.dt).is_err() {
                                    break;
                                }
                            }
                            true
                        }
                        _ => false,
                    }
                }));
                let took = began.elapsed().as_secs_f64();
                if took > slowest.0 {
                    slowest = (took, what.clone());
                }
                cases += 1;
                match outcome {
                    Ok(true) => {}
                    Ok(false) => refused += 1,
                    Err(_) => failures.push(what),
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} panicked:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(
        cases > 8000 && refused > cases / 4,
        "{cases} cases, {refused} refused"
    );
    assert!(slowest.0 < 10.0, "{:.1} s: {}", slowest.0, slowest.1);
    eprintln!(
        "{cases} cases, {refused} refused; slowest {:.2} s: {}",
        slowest.0, slowest.1
    );
}
