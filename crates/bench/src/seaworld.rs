//! `seaworld`: SeaWorld's speed (issue 4). Flat out, one copy; and the
//! largest number of copies, tiled side by side in one world 3 m apart, that
//! one core still runs in real time at the thesis's step (10 ms, RK4).
//! Copies are made from `scenes/seaworld.toml` itself: every entry renamed
//! `cK.` and shifted, each copy's jellyfish tracking its own food.

use crate::{Check, Row, Timing};
use std::path::Path;
use std::time::Instant;
use toml::Value;

/// The text of a scene holding `n` copies of the scene at `path`.
pub fn tiled(path: &Path, n: usize) -> Result<String, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let scene: toml::Table = toml::from_str(&text).map_err(|e| e.to_string())?;
    let side = (n as f64).sqrt().ceil() as usize;
    let mut out = toml::Table::new();
    for key in ["world", "floor", "fluid"] {
        if let Some(v) = scene.get(key) {
            out.insert(key.into(), v.clone());
        }
    }
    let shift = |v: &mut Value, dx: f64, dz: f64| {
        if let Some(a) = v.as_array_mut() {
            if a.len() == 3 {
                let f = |x: &Value| {
                    x.as_float()
                        .or_else(|| x.as_integer().map(|i| i as f64))
                        .unwrap_or(0.0)
                };
                let p = [f(&a[0]) + dx, f(&a[1]), f(&a[2]) + dz];
                *a = p.iter().map(|x| Value::Float(*x)).collect();
            }
        }
    };
    for key in ["food", "jellyfish", "seaweed", "bubble_column", "rocks"] {
        let Some(entries) = scene.get(key).and_then(|v| v.as_array()) else {
            continue;
        };
        let mut all = Vec::new();
        for k in 0..n {
            let (dx, dz) = (3.0 * (k % side) as f64, 3.0 * (k / side) as f64);
            for (i, e) in entries.iter().enumerate() {
                let mut e = e.clone();
                let Some(t) = e.as_table_mut() else { continue };
                let default = match key {
                    "food" => "food".to_string(),
                    "rocks" => "rock".to_string(),
                    _ => format!("{key}{i}"),
                };
                let name = t
                    .get("name")
                    .and_then(|v| v.as_str())
                    .map(String::from)
                    .unwrap_or(default);
                t.insert("name".into(), Value::String(format!("c{k}.{name}")));
                if key == "jellyfish" {
                    let food = t
                        .get("food")
                        .and_then(|v| v.as_str())
                        .unwrap_or("food")
                        .to_string();
                    t.insert("food".into(), Value::String(format!("c{k}.{food}")));
                }
                for field in ["position", "from", "to"] {
                    if let Some(v) = t.get_mut(field) {
                        shift(v, dx, dz);
                    }
                }
                if key == "rocks" && !t.contains_key("from") {
                    let mut from = Value::Array(vec![
                        Value::Float(-0.5),
                        Value::Float(0.2),
                        Value::Float(-0.5),
                    ]);
                    let mut to = Value::Array(vec![
                        Value::Float(0.5),
                        Value::Float(1.2),
                        Value::Float(0.5),
                    ]);
                    shift(&mut from, dx, dz);
                    shift(&mut to, dx, dz);
                    t.insert("from".into(), from);
                    t.insert("to".into(), to);
                }
                all.push(e);
            }
        }
        out.insert(key.into(), Value::Array(all));
    }
    toml::to_string(&out).map_err(|e| e.to_string())
}

/// Simulated seconds per wall second of `n` copies, over `seconds` simulated.
pub fn ratio(path: &Path, n: usize, seconds: f64) -> Result<(f64, usize), String> {
    let text = tiled(path, n)?;
    let mut s = animats_scene::parse(&text, "tiled seaworld").map_err(|e| e.to_string())?;
    let dt = 0.01;
    let steps = (seconds / dt).round() as usize;
    s.step(dt).map_err(|e| e.to_string())?; // warm caches
    let t = Instant::now();
    for _ in 0..steps {
        s.step(dt).map_err(|e| e.to_string())?;
    }
    Ok((steps as f64 * dt / t.elapsed().as_secs_f64(), s.world.len()))
}

/// Runs the workload.
pub fn run(quick: bool, runs: usize) -> Result<Vec<Row>, String> {
    let path = Path::new("scenes/seaworld.toml");
    let seconds = if quick { 2.0 } else { 10.0 };
    let mut ratios = Vec::new();
    let mut particles = 0;
    for _ in 0..runs {
        let (r, p) = ratio(path, 1, seconds)?;
        ratios.push(seconds / r);
        particles = p;
    }
    let one = Timing::from_runs(ratios);
    let flat = Row {
        workload: "seaworld".into(),
        variant: "1 copy, flat out, rk4 10 ms".into(),
        particles,
        springs: 0,
        steps: (seconds / 0.01) as usize,
        dt: 0.01,
        evaluations: 4,
        pairs: 0,
        engine: one.clone(),
        baseline: None,
        checks: vec![Check::info("simulated s per wall s", seconds / one.median)],
    };
    // Bisect the largest n still at or above real time (1 simulated second
    // per probe; each probe is one measurement on a shared machine).
    let probe = if quick { 0.5 } else { 1.0 };
    let mut lo = 1usize;
    let mut hi = ((seconds / one.median) * 1.5).ceil() as usize + 1;
    while hi - lo > (lo / 50).max(1) {
        let mid = (lo + hi) / 2;
        if ratio(path, mid, probe)?.0 >= 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (r, p) = ratio(path, lo, probe)?;
    let tiled = Row {
        workload: "seaworld".into(),
        variant: format!("{lo} copies in real time"),
        particles: p,
        springs: 0,
        steps: (probe / 0.01) as usize,
        dt: 0.01,
        evaluations: 4,
        pairs: 0,
        engine: Timing::from_runs(vec![probe / r]),
        baseline: None,
        checks: vec![
            Check::target("copies at real time", lo as f64, 100.0),
            Check::info("simulated s per wall s", r),
        ],
    };
    Ok(vec![flat, tiled])
}
