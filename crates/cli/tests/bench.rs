//! `animats bench --json`: one object per measurement, with every run.

mod common;
use common::{animats, scratch, text};

/// `--json`'s output: one object per line.
fn json_rows(out: &str) -> Vec<serde_json::Value> {
    out.lines()
        .map(|l| serde_json::from_str(l).expect("one JSON object per line"))
        .collect()
}

#[test]
fn json_has_every_run_the_checks_the_machine_and_the_date() {
    let o = animats(&["bench", "chain-64", "--json"]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let rows = json_rows(&out);
    let variants: Vec<&str> = rows
        .iter()
        .map(|r| r["variant"].as_str().unwrap())
        .collect();
    assert_eq!(variants, ["symplectic", "rk4"]);
    for r in &rows {
        assert_eq!(r["workload"], "chain-64");
        let runs = r["engine"]["runs_s"].as_array().unwrap();
        assert_eq!(runs.len(), 5);
        let median = r["engine"]["median_s"].as_f64().unwrap();
        let mut sorted: Vec<f64> = runs.iter().map(|t| t.as_f64().unwrap()).collect();
        sorted.sort_by(f64::total_cmp);
        assert_eq!(median, sorted[2], "the median is the middle run");
        assert_eq!(
            r["baseline"]["timing"]["runs_s"].as_array().unwrap().len(),
            5
        );
        let checks = r["checks"].as_array().unwrap();
        assert!(checks
            .iter()
            .any(|c| c["name"] == "com_y" && c["passed"] == true));
        assert!(r["machine"]["cores"].as_u64().unwrap() >= 1);
        let simd = r["machine"]["simd"].as_str().unwrap();
        assert!(
            simd.starts_with("arithmetic ") && simd.contains(", updates "),
            "{simd}"
        );
        // The build's instruction sets, as the engine reports them.
        let built = r["machine"]["built_for"].as_str().unwrap();
        match animats_engine::cpu::required_features() {
            "" => assert_eq!(built, "baseline"),
            f => assert_eq!(built, f),
        }
        assert_eq!(
            built.contains("avx2"),
            cfg!(target_feature = "avx2"),
            "{built}"
        );
        let date = r["date"].as_str().unwrap();
        assert!(date.len() == 10 && date.starts_with("20"), "{date}");
    }
}

/// `scene-load --quick`: the cloth scene files of side 16 and 32 load with
/// every particle and spring, and the larger's row compares time per byte.
#[test]
fn scene_load_builds_every_particle_and_spring() {
    let o = animats(&["bench", "scene-load", "--quick", "--json"]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let rows = json_rows(&out);
    assert_eq!(rows.len(), 2);
    for (r, side) in rows.iter().zip([16.0, 32.0]) {
        let checks = r["checks"].as_array().unwrap();
        let value = |name: &str| {
            checks
                .iter()
                .find(|c| c["name"] == name)
                .and_then(|c| c["value"].as_f64())
        };
        assert_eq!(value("particles"), Some(side * side));
        assert_eq!(value("springs"), Some(2.0 * side * (side - 1.0)));
    }
    let last = rows[1]["checks"].as_array().unwrap();
    assert!(last
        .iter()
        .any(|c| c["name"] == "time per byte against the 4x smaller file"));
}

/// `bench scaling` (issue 41's instrument) is `evolve --schedule`: the same
/// run (log.csv the same bytes), schedule.csv with every evaluation, and
/// the model's table for 1 to 64 workers, whose one worker is the recorded
/// work; a missing scene is refused by name (exit 2), and an unknown
/// workload still is beside it.
#[test]
fn bench_scaling_is_evolve_with_its_schedule() {
    let dir = scratch("bench-scaling");
    let (a, b) = (dir.join("bench"), dir.join("evolve"));
    let common = [
        "--generations",
        "4",
        "--lanes",
        "2",
        "--seed",
        "5",
        "--threads",
        "2",
        "--no-check",
    ];
    let mut args = vec!["bench", "scaling"];
    args.extend(common);
    args.extend(["--out", a.to_str().unwrap()]);
    let o = animats(&args);
    let (stdout, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let mut args = vec!["evolve"];
    args.extend(common);
    args.extend(["--schedule", "--out", b.to_str().unwrap()]);
    let o = animats(&args);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o).1);
    let log = |d: &std::path::Path| std::fs::read_to_string(d.join("log.csv")).unwrap();
    assert_eq!(log(&a), log(&b));
    let csv = std::fs::read_to_string(a.join("schedule.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    // 2 lanes × 4 generations of the hill climber: one evaluation each.
    assert_eq!(rows.iter().filter(|r| r.contains(",evaluate,")).count(), 8);
    let work: f64 = rows
        .iter()
        .map(|r| r.split(',').nth(7).unwrap().parse::<f64>().unwrap())
        .sum();
    let predicted = |w: &str| -> f64 {
        let line = stdout
            .lines()
            .skip_while(|l| !l.contains("workers   predicted wall"))
            .find(|l| l.split_whitespace().next() == Some(w))
            .unwrap_or_else(|| panic!("no row for {w} workers: {stdout}"));
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    assert!((predicted("1") - work).abs() < 2e-3, "{stdout}");
    // Two lanes of one evaluation a generation, which never wait for each
    // other: two workers hold each its own lane's chain, no third has
    // anything to do, and neither can beat half the work.
    assert!(predicted("2") >= work / 2.0 - 2e-3, "{stdout}");
    for w in ["4", "8", "16", "32", "64"] {
        assert_eq!(predicted(w), predicted("2"), "{w} workers: {stdout}");
    }
    let missing = dir.join("no-such-scene.toml");
    let o = animats(&[
        "bench",
        "scaling",
        missing.to_str().unwrap(),
        "--out",
        dir.join("m").to_str().unwrap(),
    ]);
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("no-such-scene.toml"), "{err}");
    let o = animats(&["bench", "nonesuch", "--runs", "5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("unknown workload `nonesuch`"));
}
