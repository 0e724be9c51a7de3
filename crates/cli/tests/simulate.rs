//! `animats simulate`: the output contracts and every bad-input case of the
//! scene format, run through the real binary.

mod common;
use common::*;

const TWO_BALLS: &str = r#"
[world]
dt = 0.001
duration = 0.01

[floor]

[[particle]]
name = "a"
mass = 1.0
position = [0.0, 1.0, 0.0]
velocity = [0.3, 0.0, 0.1]
radius = 0.1

[[particle]]
name = "b"
mass = 2.0
position = [1.0, 1.0, 0.0]
radius = 0.1

[[spring]]
a = "a"
b = "b"
stiffness = 10.0
damping = 0.1
"#;

#[test]
fn summary_reports_steps_backtracks_speed_and_energy() {
    let o = animats(&["simulate", "scenes/oscillator.toml", "--duration", "10"]);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    assert!(out.contains("1000 steps to t = 10 s"), "{out}");
    assert!(out.contains("backtracks: 0"), "{out}");
    assert!(out.contains("simulated s per wall s"), "{out}");
    assert!(
        out.contains("drift"),
        "a conservative scene reports its energy drift: {out}"
    );
}

#[test]
fn csv_has_the_header_one_row_per_particle_per_recorded_step_and_full_precision() {
    let dir = scratch("csv");
    let scene = write(&dir, "two.toml", TWO_BALLS);
    let out = dir.join("run.csv");
    let o = animats(&[
        "simulate",
        &scene,
        "--every",
        "3",
        "--output",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o).1);
    let csv = std::fs::read_to_string(&out).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("t,particle,x,y,z,vx,vy,vz"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // 10 steps, every 3rd recorded, plus t = 0 and the last: steps 0, 3, 6, 9, 10.
    assert_eq!(rows.len(), 5 * 2);
    let times: Vec<f64> = rows
        .iter()
        .step_by(2)
        .map(|r| r[0].parse().unwrap())
        .collect();
    let expected = [0.0, 0.003, 0.006, 0.009, 0.01];
    for (t, e) in times.iter().zip(expected) {
        assert!((t - e).abs() < 1e-15, "times {times:?}");
    }
    assert_eq!(rows[0][1], "a");
    assert_eq!(rows[1][1], "b");

    // The numbers read back to exactly the f64s the library computes.
    let mut scene = animats_scene::parse(TWO_BALLS, "two.toml").unwrap();
    for _ in 0..10 {
        scene.step(0.001).unwrap();
    }
    let last = &rows[rows.len() - 2];
    let a = scene.particle("a").unwrap();
    let (p, v) = (scene.world.position(a), scene.world.velocity(a));
    let got: Vec<f64> = last[2..].iter().map(|x| x.parse().unwrap()).collect();
    assert_eq!(got, vec![p.x, p.y, p.z, v.x, v.y, v.z]);
}

#[test]
fn jsonl_has_one_object_per_recorded_step() {
    let dir = scratch("jsonl");
    let scene = write(&dir, "two.toml", TWO_BALLS);
    let out = dir.join("run.jsonl");
    let o = animats(&[
        "simulate",
        &scene,
        "--every",
        "5",
        "--output",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o).1);
    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect();
    assert_eq!(lines.len(), 3); // steps 0, 5, 10
    assert_eq!(lines[2]["step"], 10);
    assert_eq!(lines[0]["particles"][1]["name"], "b");
    assert_eq!(lines[0]["particles"][0]["velocity"][0], 0.3);
    assert_eq!(
        lines[0]["particles"][0]["position"]
            .as_array()
            .unwrap()
            .len(),
        3
    );
}

#[test]
fn command_line_overrides_the_world_table_and_steps_are_rounded() {
    let dir = scratch("override");
    let scene = write(&dir, "two.toml", TWO_BALLS);
    let out = dir.join("o.csv");
    // 0.0104 / 0.002 = 5.2 → 5 steps, ending at 0.01 s, not one step past.
    let o = animats(&[
        "simulate",
        &scene,
        "--dt",
        "0.002",
        "--duration",
        "0.0104",
        "--integrator",
        "midpoint",
        "-o",
        out.to_str().unwrap(),
    ]);
    let (stdout, err) = text(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        stdout.contains("integrator midpoint, dt 0.002 s, 5 steps"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(&out).unwrap();
    assert_eq!(csv.lines().count(), 1 + 6 * 2);
    let last_t: f64 = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((last_t - 0.01).abs() < 1e-15);
}

fn refused(scene_text: &str, expect: &[&str]) {
    let dir = scratch(&format!("bad-{:x}", scene_text.len() * 31 + expect.len()));
    let scene = write(&dir, "bad.toml", scene_text);
    let o = animats(&["simulate", &scene]);
    let (_, err) = text(&o);
    assert_eq!(
        o.status.code(),
        Some(2),
        "expected exit 2 for {expect:?}, stderr: {err}"
    );
    assert!(
        err.contains("bad.toml"),
        "message should name the file: {err}"
    );
    for e in expect {
        assert!(err.contains(e), "message should mention `{e}`: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn every_bad_scene_is_refused_with_file_entry_and_field() {
    let ok = TWO_BALLS;
    refused(
        &ok.replace("damping = 0.1", "damping = 0.1\nstifness = 3"),
        &["spring[0]", "stifness", "unknown field"],
    );
    refused(
        &ok.replace("b = \"b\"", "b = \"c\""),
        &["spring[0].b", "unknown particle `c`"],
    );
    refused(
        &ok.replace("name = \"b\"", "name = \"a\""),
        &["particle[1].name", "duplicate"],
    );
    refused(
        &ok.replace("mass = 2.0", "mass = -2.0"),
        &["particle[1].mass", "> 0"],
    );
    refused(
        &ok.replace("mass = 2.0", "mass = 0"),
        &["particle[1].mass", "> 0"],
    );
    refused(&ok.replace("dt = 0.001", "dt = 0.0"), &["world.dt", "> 0"]);
    refused(&ok.replace("dt = 0.001", "dt = -1e-3"), &["world.dt"]);
    refused(
        &ok.replace("mass = 1.0", "mass = nan"),
        &["particle[0].mass", "finite"],
    );
    refused(
        &ok.replace("velocity = [0.3, 0.0, 0.1]", "velocity = [0.3, inf, 0.1]"),
        &["particle[0].velocity", "finite"],
    );
    refused(
        &ok.replace("stiffness = 10.0", "stiffness = inf"),
        &["spring[0].stiffness", "finite"],
    );
    refused(
        &ok.replace(
            "radius = 0.1\n\n[[particle]]",
            "radius = 0.1\nrestitution = 1.2\n\n[[particle]]",
        ),
        &["particle[0].restitution", "between 0 and 1"],
    );
    refused(
        &ok.replace("position = [1.0, 1.0, 0.0]", "position = [0.0, 1.0, 0.0]"),
        &["spring[0]", "zero length"],
    );
    refused(
        &ok.replace("damping = 0.1", "damping = 0.1\nrest_length = 0.0"),
        &["spring[0].rest_length", "> 0"],
    );
    refused(
        &ok.replace("[floor]", "[floor]\nparticles = [\"zz\"]"),
        &["floor.particles", "unknown particle `zz`"],
    );
    refused(
        &ok.replace("integrator", "x")
            .replace("duration = 0.01", "duration = 0.01\nintegrator = \"rk5\""),
        &["world.integrator", "rk5"],
    );
    refused(
        &ok.replace("radius = 0.1\n\n[[particle]]", "\n[[particle]]"),
        &["particle[0].radius", "volume"],
    );
    refused("[world\n", &["bad.toml:1"]);
    refused("this is not toml", &["bad.toml:1"]);
}

#[test]
fn missing_files_bad_options_and_unwritable_outputs_exit_2() {
    let o = animats(&["simulate", "no/such/scene.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("no/such/scene.toml"));
    for args in [
        vec!["simulate", "scenes/oscillator.toml", "--dt", "0"],
        vec!["simulate", "scenes/oscillator.toml", "--dt", "nan"],
        vec!["simulate", "scenes/oscillator.toml", "--duration", "-1"],
        vec![
            "simulate",
            "scenes/oscillator.toml",
            "--integrator",
            "verlet",
        ],
        vec!["simulate", "scenes/oscillator.toml", "--every", "0"],
        vec![
            "simulate",
            "scenes/oscillator.toml",
            "--output",
            "/no/such/dir/out.csv",
        ],
        vec!["simulate", "scenes/oscillator.toml", "--output", "out.txt"],
        vec!["simulate", "scenes/oscillator.toml", "--duration", "0.001"],
    ] {
        let o = animats(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o).1);
        assert!(!text(&o).1.contains("panicked"));
    }
    // A huge step count is refused at once, in one readable line.
    let o = animats(&["simulate", "scenes/oscillator.toml", "--duration", "1e300"]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o).1;
    assert!(
        err.contains("1.0e302 steps") && err.contains("too many"),
        "{err}"
    );
    // Naming the file, and where the step and the duration came from.
    assert!(
        err.contains("scenes/oscillator.toml: ")
            && err.contains("of --duration")
            && err.contains("of [world] dt"),
        "{err}"
    );
    assert!(err.len() < 200, "{err}");
    // A stream that never ends, whose stated size is 0, is refused at the
    // bound as it is read (it was read until memory ran out), by every
    // command that reads a scene or a parameter file.
    if std::path::Path::new("/dev/zero").exists() {
        for command in ["simulate", "evaluate", "evolve", "hop"] {
            let o = animats(&[command, "/dev/zero"]);
            let err = text(&o).1;
            assert_eq!(o.status.code(), Some(2), "{command}: {err}");
            assert!(
                err.contains("/dev/zero: ") && err.contains("more than"),
                "{command}: {err}"
            );
        }
    }
}

#[test]
fn a_blow_up_exits_3_naming_time_and_particle_and_leaves_no_complete_output() {
    // A stiff spring and a huge step under explicit Euler: the amplitude
    // grows by about ωh ≈ 300 per step and overflows within a few hundred steps.
    let dir = scratch("blowup");
    let scene = write(&dir, "stiff.toml", STIFF_SCENE);
    let out = dir.join("traj.csv");
    let o = animats(&["simulate", &scene, "--output", out.to_str().unwrap()]);
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains("non-finite at t = "), "{err}");
    assert!(err.contains("`wobbly`"), "{err}");
    assert!(
        !out.exists(),
        "a failed run must not leave a file under the requested name"
    );
    assert!(
        dir.join("traj.csv.partial").exists(),
        "what was computed is kept as .partial"
    );
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

/// A chain of ten 10 g beads on damped springs hanging from a nail, under
/// symplectic Euler at 4 ms: stable at k = 300 N/m; at k = 600 N/m past its
/// step limit it tangles at tens of m/s without ever going non-finite.
fn chain(stiffness: f64) -> String {
    let mut s = String::from(
        "[world]\ndt = 0.004\nintegrator = \"symplectic\"\nduration = 20.0\n\n[floor]\n\n",
    );
    for i in 0..10 {
        s += &format!(
            "[[particle]]\nname = \"p{i}\"\nmass = 0.01\nposition = [{}, 0.5, 0.0]\nradius = 0.01\nfixed = {}\n\n",
            0.05 * i as f64,
            i == 0
        );
    }
    for i in 0..9 {
        s += &format!(
            "[[spring]]\na = \"p{i}\"\nb = \"p{}\"\nstiffness = {stiffness}\ndamping = 0.2\n\n",
            i + 1
        );
    }
    s
}

#[test]
fn a_run_that_diverges_without_going_non_finite_is_a_blow_up_too() {
    let dir = scratch("diverge");
    let fine = write(&dir, "fine.toml", &chain(300.0));
    let o = animats(&["simulate", &fine]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o).1);
    assert!(!text(&o).1.contains("warning"), "{}", text(&o).1);

    let bad = write(&dir, "tangled.toml", &chain(600.0));
    let out = dir.join("tangled.csv");
    let o = animats(&["simulate", &bad, "--output", out.to_str().unwrap()]);
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains("diverged at t = "), "{err}");
    assert!(err.contains("particle `p"), "{err}");
    assert!(err.contains("times the"), "{err}");
    assert!(!out.exists());
    assert!(dir.join("tangled.csv.partial").exists());
}

#[test]
fn suspicious_scenes_get_warnings_naming_what_and_still_run() {
    let dir = scratch("warnings");
    let scene = write(
        &dir,
        "odd.toml",
        r#"
[world]
dt = 0.01
duration = 0.1
integrator = "rk4"

[floor]

[[particle]]
name = "sunk"
mass = 1.0
position = [0.0, 0.05, 0.0]
radius = 0.1

[[particle]]
name = "nail"
mass = 1.0
position = [0.0, 1.0, 0.0]
radius = 0.01
fixed = true
velocity = [1.0, 0.0, 0.0]

[[particle]]
name = "bead"
mass = 0.001
position = [0.0, 0.9, 0.0]
radius = 0.01

[[spring]]
a = "nail"
b = "bead"
stiffness = 1000.0
"#,
    );
    let o = animats(&["simulate", &scene]);
    let (_, err) = text(&o);
    assert!(
        err.contains("warning:") && err.contains("`sunk` starts 0.0500 m inside the floor"),
        "{err}"
    );
    assert!(err.contains("`nail` is fixed, so its velocity"), "{err}");
    // ω² ≤ 2 k / m = 2e6: ω ≈ 1414 rad/s, RK4 stable below 2.83 / ω = 2.0 ms.
    assert!(err.contains("dt = 0.01 s is 5.0 times"), "{err}");
    assert!(err.contains("`nail`–`bead`"), "{err}");
}

#[test]
fn summary_gives_the_recommended_step_and_a_step_past_it_from_the_command_line_is_warned() {
    // pendulum_chain: 50 g bobs on 400 N/m springs; a bob between two
    // springs has ω² ≤ 2·800/0.05 = 32,000 s⁻², so symplectic Euler's step
    // is 2/√32000 = 1.118e-2 s and RK4's 2√2/√32000 = 1.581e-2 s.
    let ok = animats(&[
        "simulate",
        "scenes/pendulum_chain.toml",
        "--duration",
        "0.1",
    ]);
    let (out, err) = text(&ok);
    assert!(ok.status.success(), "{err}");
    assert!(!err.contains("warning"), "{err}");
    let kind_line = out.lines().find(|l| l.starts_with("recommended step for"));
    let line = kind_line.unwrap_or_default();
    let want = |kind: &str, h: f64| format!("recommended step for {kind}: {h:.3e} s");
    let rk4 = 2.0 * std::f64::consts::SQRT_2 / 32000f64.sqrt();
    let symplectic = 2.0 / 32000f64.sqrt();
    assert!(
        line.starts_with(&want("rk4", rk4)) || line.starts_with(&want("symplectic", symplectic)),
        "{out}"
    );
    let fast = animats(&[
        "simulate",
        "scenes/pendulum_chain.toml",
        "--duration",
        "0.1",
        "--dt",
        "0.05",
        "--integrator",
        "symplectic",
    ]);
    let (out, err) = text(&fast);
    assert!(out.contains(&want("symplectic", symplectic)), "{out}");
    assert!(
        err.contains("warning") && err.contains("expect a blow-up"),
        "{err}"
    );
    assert!(err.contains("set by the spring `b"), "{err}");
}

#[test]
fn implicit_runs_a_step_past_the_explicit_limit_without_a_warning() {
    // The same pendulum chain at 0.05 s, 4.5× symplectic Euler's limit:
    // implicit Euler takes it, says which step it avoids, and how hard its
    // linear solves worked.
    let run = animats(&[
        "simulate",
        "scenes/pendulum_chain.toml",
        "--duration",
        "2",
        "--dt",
        "0.05",
        "--integrator",
        "implicit",
    ]);
    let (out, err) = text(&run);
    assert!(run.status.success(), "{err}");
    assert!(!err.contains("warning"), "{err}");
    let symplectic = 2.0 / 32000f64.sqrt();
    assert!(
        out.contains(&format!(
            "recommended step for implicit: any (stable at every step; symplectic Euler would need below {symplectic:.3e} s)"
        )),
        "{out}"
    );
    let solves = out
        .lines()
        .find_map(|l| l.strip_prefix("linear solves: "))
        .unwrap_or_default();
    let per_step: f64 = solves
        .split_whitespace()
        .next()
        .and_then(|x| x.parse().ok())
        .unwrap_or(-1.0);
    assert!(per_step > 0.0, "{out}");
}

#[test]
fn realtime_runs_to_the_duration_and_a_blow_up_there_names_the_particle_and_keeps_a_partial() {
    let dir = scratch("realtime");
    let out = dir.join("rt.csv");
    let o = animats(&[
        "simulate",
        "scenes/oscillator.toml",
        "--realtime",
        "--duration",
        "0.2",
        "--fps",
        "100",
        "--output",
        out.to_str().unwrap(),
    ]);
    let (stdout, err) = text(&o);
    assert!(o.status.success(), "{err}");
    assert!(stdout.contains("to t = 0.200 s"), "{stdout}");
    let csv = std::fs::read_to_string(&out).unwrap();
    let last: f64 = csv
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .and_then(|t| t.parse().ok())
        .unwrap();
    assert!((last - 0.2).abs() < 1e-9, "the last row is at t = {last}");

    // The stiff spring blows up within a few hundred steps (the guard
    // calls it diverged, or it goes non-finite), as without --realtime:
    // exit 3, the particle by name, the step, and the trajectory so far
    // kept as .partial only.
    let scene = write(&dir, "stiff.toml", STIFF_SCENE);
    let out = dir.join("stiff.csv");
    let o = animats(&[
        "simulate",
        &scene,
        "--realtime",
        "--fps",
        "240",
        "--output",
        out.to_str().unwrap(),
    ]);
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(
        err.contains(" at t = ") && err.contains("`wobbly`") && err.contains("(step "),
        "{err}"
    );
    assert!(!out.exists(), "no file under the requested name");
    assert!(dir.join("stiff.csv.partial").exists(), "{err}");
}

/// A 6 × 6 net of 36 particles (110 springs: the springs' blocks and the
/// flat updates, both vectorised), under mutual gravitation as well (the
/// all-pairs gather), dropped onto the floor with RK4: the bytes of its
/// trajectory must not depend on the vector instructions the engine
/// chose, whatever `ANIMATS_SIMD` caps them to (docs/DESIGN.md, "Determinism"). On an Intel CPU the caps reach only the
/// arithmetic's choice (its updates stay SSE2); the loops' own unit tests
/// compare every width this CPU has directly.
#[test]
fn every_vector_instruction_set_writes_the_same_trajectory() {
    let dir = scratch("simd");
    let mut scene = String::from(
        "[world]\ndt = 0.001\nduration = 0.5\nintegrator = \"rk4\"\n\n[floor]\n\n[[nbody]]\nG = 0.01\n",
    );
    let name = |i: usize, j: usize| format!("p{i}_{j}");
    for i in 0..6 {
        for j in 0..6 {
            let y = 0.3 + 0.01 * ((i * 7 + j * 3) % 5) as f64;
            scene += &format!(
                "\n[[particle]]\nname = \"{}\"\nmass = 0.01\nposition = [{}, {y}, {}]\nradius = 0.02\n",
                name(i, j),
                0.1 * i as f64,
                0.1 * j as f64
            );
        }
    }
    let spring = |a: String, b: String| {
        format!("\n[[spring]]\na = \"{a}\"\nb = \"{b}\"\nstiffness = 50.0\ndamping = 0.05\n")
    };
    for i in 0..6 {
        for j in 0..6 {
            if i + 1 < 6 {
                scene += &spring(name(i, j), name(i + 1, j));
            }
            if j + 1 < 6 {
                scene += &spring(name(i, j), name(i, j + 1));
            }
            if i + 1 < 6 && j + 1 < 6 {
                scene += &spring(name(i, j), name(i + 1, j + 1));
                scene += &spring(name(i + 1, j), name(i, j + 1));
            }
        }
    }
    let scene = write(&dir, "net.toml", &scene);
    let run = |cap: Option<&str>| {
        let out = dir.join(format!("{}.csv", cap.unwrap_or("chosen")));
        let mut cmd = command();
        cmd.args(["simulate", &scene, "--output", out.to_str().unwrap()]);
        match cap {
            Some(c) => cmd.env("ANIMATS_SIMD", c),
            None => cmd.env_remove("ANIMATS_SIMD"),
        };
        let o = cmd.output().expect("run animats");
        let (_, err) = text(&o);
        assert!(o.status.success(), "{cap:?}: {err}");
        std::fs::read(&out).expect("trajectory written")
    };
    let chosen = run(None);
    let rows = chosen.iter().filter(|&&b| b == b'\n').count();
    assert!(rows > 36 * 400, "a row per particle per step: {rows}");
    // It moved: p0_0 fell from 0.3 m towards the floor.
    let last_y = String::from_utf8_lossy(&chosen)
        .lines()
        .rfind(|l| l.split(',').nth(1) == Some("p0_0"))
        .and_then(|l| l.split(',').nth(3).and_then(|y| y.parse::<f64>().ok()))
        .expect("p0_0's last row");
    assert!(last_y < 0.25, "p0_0 ends at y = {last_y}");
    // An unknown word caps nothing.
    assert!(run(Some("fast")) == chosen);
    for cap in ["base", "avx2", "avx512"] {
        assert!(
            run(Some(cap)) == chosen,
            "ANIMATS_SIMD={cap} changed the trajectory"
        );
    }
}

/// A trajectory that cannot fit on the disk is refused before anything
/// is simulated: 10¹¹ recorded steps of the walker (at least 29 bytes a
/// particle a step: over 10 TB) exit 2 at once, naming the file, the
/// size and the free space, and leave no file. Without the check the
/// run would write for days; the test gives it 60 s.
#[test]
fn a_trajectory_too_big_for_the_disk_is_refused_before_the_run() {
    let dir = scratch("no-room");
    let out = dir.join("huge.csv");
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/walker.toml");
    let o = animats_within(
        &[
            "simulate",
            scene.to_str().unwrap(),
            "--dt",
            "1e-6",
            "--duration",
            "1e5",
            "--output",
            out.to_str().unwrap(),
        ],
        60,
    );
    let Some(o) = o else {
        let _ = std::fs::remove_dir_all(&dir);
        panic!("still writing after 60 s: the trajectory's size was not checked");
    };
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("huge.csv: the trajectory would take at least"),
        "{err}"
    );
    assert!(err.contains("100000000001 recorded steps of"), "{err}");
    assert!(
        err.contains(" free there") && err.contains("--every"),
        "{err}"
    );
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert!(left.is_empty(), "files left: {left:?}");
}
