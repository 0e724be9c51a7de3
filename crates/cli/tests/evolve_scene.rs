//! Evolving a scene's brain through the real binary: a creature no shipped
//! scene contains, evolved by each optimiser; `evaluate` on `best.toml`
//! reproduces the logged best fitness bit for bit; thread counts and a
//! resume do not change a bit of the log.

mod common;
use common::*;

const CRAWLER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/crawler.toml");

/// The last `best_fitness` of `log.csv` and the column names.
fn last_best(log: &str) -> f64 {
    let header: Vec<&str> = log.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|c| *c == "best_fitness").unwrap();
    let last = log.lines().last().unwrap();
    last.split(',').nth(col).unwrap().parse().unwrap()
}

fn json_field(json: &str, key: &str) -> String {
    let v: serde_json::Value = serde_json::from_str(json).unwrap();
    v[key].to_string()
}

#[test]
fn a_crawler_learns_to_crawl_with_every_optimiser_and_best_toml_reproduces_it() {
    let start = animats(&["evaluate", CRAWLER, "--json"]);
    let (out, err) = text(&start);
    assert!(start.status.success(), "{err}");
    let start_distance: f64 = json_field(&out, "distance").parse().unwrap();
    for (optimiser, generations) in [("hill-climber", "150"), ("ga", "15"), ("cma-es", "40")] {
        let dir = scratch(&format!("crawler-{optimiser}"));
        let d = dir.to_str().unwrap();
        let o = animats(&[
            "evolve",
            CRAWLER,
            "--optimiser",
            optimiser,
            "--generations",
            generations,
            "--out",
            d,
        ]);
        let (out, err) = text(&o);
        assert!(o.status.success(), "{optimiser}: {err}");
        let log = std::fs::read_to_string(dir.join("log.csv")).unwrap();
        assert_eq!(
            log.lines().next(),
            Some("lane,generation,evaluations,fitness,best_fitness,time,distance,ended")
        );
        assert_eq!(
            log.lines().count(),
            1 + generations.parse::<usize>().unwrap()
        );
        let logged = last_best(&log);
        let best = dir.join("best.toml");
        let e = animats(&["evaluate", best.to_str().unwrap(), "--json"]);
        let (json, err) = text(&e);
        assert!(e.status.success(), "{err}");
        let fitness: f64 = json_field(&json, "fitness").parse().unwrap();
        assert_eq!(
            fitness.to_bits(),
            logged.to_bits(),
            "{optimiser}: evaluate best.toml gives {fitness}, the log says {logged}"
        );
        let distance: f64 = json_field(&json, "distance").parse().unwrap();
        println!("{optimiser}: {distance:.3} m in 5 s (the starting brain: {start_distance:.3} m); {out}");
        assert!(
            distance > 0.1 && distance > 3.0 * start_distance,
            "{optimiser}: the crawler moved {distance} m forward"
        );
        assert!(dir.join("fitness.png").exists() && dir.join("checkpoint.json").exists());
    }
}

#[test]
fn a_scene_run_is_the_same_at_any_thread_count_and_after_a_resume() {
    let run = |name: &str, extra: &[&str]| {
        let dir = scratch(name);
        let mut args = vec!["evolve", CRAWLER, "--optimiser", "cma-es", "--lanes", "2"];
        args.extend(extra);
        args.extend(["--out", dir.to_str().unwrap()]);
        let o = animats(&args);
        assert!(o.status.success(), "{}", text(&o).1);
        dir
    };
    let one = run("crawler-1t", &["--threads", "1", "--generations", "12"]);
    let two = run("crawler-2t", &["--threads", "2", "--generations", "12"]);
    let read = |d: &std::path::Path, f: &str| std::fs::read(d.join(f)).unwrap();
    assert_eq!(read(&one, "log.csv"), read(&two, "log.csv"));
    assert_eq!(read(&one, "best.toml"), read(&two, "best.toml"));
    // Stop at 5, resume to 12: the same log and best, bit for bit.
    let part = run("crawler-part", &["--generations", "5"]);
    let o = animats(&[
        "evolve",
        "--resume",
        part.to_str().unwrap(),
        "--generations",
        "12",
    ]);
    assert!(o.status.success(), "{}", text(&o).1);
    assert_eq!(read(&part, "log.csv"), read(&one, "log.csv"));
    assert_eq!(read(&part, "best.toml"), read(&one, "best.toml"));
}

#[test]
fn evaluate_and_evolve_refuse_what_they_cannot_use() {
    let dir = scratch("evaluate-bad");
    // No [evolve] table.
    let o = animats(&["evaluate", "scenes/pendulum_chain.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("no [evolve] table"), "{}", text(&o).1);
    let o = animats(&[
        "evolve",
        "scenes/pendulum_chain.toml",
        "--out",
        dir.join("x").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!dir.join("x").join("log.csv").exists());
    // A length or a step past every limit, named in a few digits.
    let walker = include_str!("../../../scenes/walker.toml");
    for (from, to, expect) in [
        (
            "duration = 10.0\n",
            "duration = 1e300\n",
            "evolve.duration: must be at most 86400 s (a simulated day), got 1e300",
        ),
        (
            "dt = 0.0005",
            "dt = 1e-300",
            "at dt = 1e-300 s is 1.000e301 steps, more than 1e12",
        ),
        (
            "dt = 0.0005",
            "dt = -1e300",
            "world.dt: must be > 0, got -1e300",
        ),
        // (A step longer than the evaluation scored nothing: fitness 0,
        // `ended timeout`, exit 0.)
        (
            "dt = 0.0005",
            "dt = 30.0",
            "evolve.duration: 10 s is shorter than half a step (30 s, [world] dt): nothing to evaluate",
        ),
    ] {
        let at = walker.rfind(from).expect(from);
        let scene = write(
            &dir,
            "far.toml",
            &format!("{}{to}{}", &walker[..at], &walker[at + from.len()..]),
        );
        let o = animats(&["evaluate", &scene]);
        assert_eq!(o.status.code(), Some(2));
        let err = text(&o).1;
        assert!(err.contains(expect), "{to}: {err}");
    }
    // A missing file, an unknown optimiser.
    let o = animats(&["evaluate", "nope.toml"]);
    assert_eq!(o.status.code(), Some(2));
    let o = animats(&["evolve", CRAWLER, "--optimiser", "annealing"]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o).1;
    assert!(
        err.contains("invalid value 'annealing' for '--optimiser")
            && err.contains(
                "[possible values: hill-climber, ga, cma-es, body-ga, map-elites, cma-me]"
            ),
        "{err}"
    );
}

/// `--device cuda`: a scene the GPU does not evaluate is refused by file
/// and entry, before anything runs; without a usable GPU (CI has none)
/// the message says what is missing; with one, `evaluate` gives the CPU's
/// bits. Exit 2 for every refusal.
#[test]
fn device_cuda_says_what_it_cannot_evaluate_or_gives_the_cpu_s_bits() {
    // The quadruped with its scripted step (the thesis's experiment) acts
    // by itself: refused by name.
    let dir = scratch("device-bodies");
    let dog = dir.join("dog.toml");
    let gait = include_str!("../../../scenes/quadruped3_gait.toml");
    assert!(gait.contains("demo_at = -1.0"));
    std::fs::write(&dog, gait.replace("demo_at = -1.0", "demo_at = 2.0")).unwrap();
    let dog = dog.to_str().unwrap();
    let o = animats(&["evaluate", dog, "--device", "cuda"]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o).1;
    assert!(
        err.contains(&format!("{dog}: --device cuda:"))
            && err.contains("the creature `dog`")
            && err.contains("not in the GPU evaluation yet"),
        "{err}"
    );
    let out = dir.join("x");
    let o = animats(&[
        "evolve",
        dog,
        "--device",
        "cuda",
        "--generations",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("the creature `dog`"), "{}", text(&o).1);
    assert!(!out.join("log.csv").exists());
    let cpu = animats(&["evaluate", "scenes/walker.toml", "--json"]);
    let gpu = animats(&[
        "evaluate",
        "scenes/walker.toml",
        "--json",
        "--device",
        "cuda",
    ]);
    if gpu.status.success() {
        assert_eq!(text(&gpu).0, text(&cpu).0);
    } else {
        assert_eq!(gpu.status.code(), Some(2));
        let err = text(&gpu).1;
        assert!(
            err.contains("--device cuda:")
                && (err.contains("driver") || err.contains("device") || err.contains("NVRTC")),
            "{err}"
        );
    }
    // A walker on rough ground (terrain) is evaluated: not refused.
    let rough = animats(&[
        "evaluate",
        "scenes/walker_rough.toml",
        "--json",
        "--device",
        "cuda",
    ]);
    if !rough.status.success() {
        let err = text(&rough).1;
        assert!(
            !err.contains("not in the GPU")
                && (err.contains("driver") || err.contains("device") || err.contains("NVRTC")),
            "{err}"
        );
    }
    // Fast mode: refused by name too, or a fitness (not the CPU's bits).
    let o = animats(&["evaluate", dog, "--device", "cuda-fast"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o).1.contains(&format!("{dog}: --device cuda-fast:")),
        "{}",
        text(&o).1
    );
    let fast = animats(&[
        "evaluate",
        "scenes/walker.toml",
        "--json",
        "--device",
        "cuda-fast",
    ]);
    if !fast.status.success() {
        assert_eq!(fast.status.code(), Some(2));
        let err = text(&fast).1;
        assert!(
            err.contains("--device cuda-fast:")
                && (err.contains("driver") || err.contains("device") || err.contains("NVRTC")),
            "{err}"
        );
    }
}
