//! `animats bench --json`: one object per measurement, with every run.

mod common;
use common::{animats, text};

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
