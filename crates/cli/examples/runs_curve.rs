//! Plots the best fitness of several `animats evolve` runs against the
//! evaluations they had made (each run's `log.csv`, its `evaluations` and
//! `best_fitness` columns, the best over its rows so far), with level
//! lines to compare them with: the curve of docs/BODIES.md's five seeds.
//!
//! ```sh
//! cargo run --release -p animats --example runs_curve -- docs/img/bodies_walk_curve.png \
//!     "Best body of scenes/bodies_walk.toml, five seeds, 10 minutes each on 2 cores" \
//!     "best distance in 10 s, m" \
//!     "seed 1=walk1/log.csv" "seed 2=walk2/log.csv" "seed 3=walk3/log.csv" \
//!     "seed 4=walk4/log.csv" "seed 5=walk5/log.csv" \
//!     --line "the evolved walker, 4.31 m=4.31" --line "1.5 times it, 6.465 m=6.465"
//! ```
//!
//! (`LABEL=LOG.csv` names a run's line; a bare `LOG.csv` is named by its
//! run's directory.)
//!
//! A log of several lanes counts each lane's evaluations on its own rows:
//! plot one lane's runs (the shipped body scenes have one).

use animats_render::{step_plot_png, Plot, Series};

/// A run's best so far, one point per improvement and one at its last row.
fn curve(log: &str) -> Result<Vec<(f64, f64)>, String> {
    let text = std::fs::read_to_string(log).map_err(|e| format!("{log}: {e}"))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or_else(|| format!("{log}: empty"))?
        .split(',')
        .collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| format!("{log}: no `{name}` column"))
    };
    let (e, b) = (column("evaluations")?, column("best_fitness")?);
    let mut points: Vec<(f64, f64)> = Vec::new();
    let mut last = None;
    for (k, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| -> Result<f64, String> {
            f.get(i)
                .and_then(|s| s.parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{log}: line {}: not a log.csv row", k + 2))
        };
        let (evaluations, best) = (num(e)?, num(b)?);
        if points.last().is_none_or(|&(_, p)| best > p) {
            points.push((evaluations, best));
        }
        last = Some(evaluations);
    }
    match (points.last().copied(), last) {
        (Some((_, best)), Some(at)) => points.push((at, best)),
        _ => return Err(format!("{log}: no rows")),
    }
    Ok(points)
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage =
        "usage: runs_curve OUT.png TITLE Y_LABEL [LABEL=]LOG.csv... [--line LABEL=VALUE]...";
    let [out, title, y_label, rest @ ..] = args.as_slice() else {
        return Err(usage.into());
    };
    let (mut logs, mut lines) = (Vec::new(), Vec::new());
    let mut it = rest.iter();
    while let Some(a) = it.next() {
        if a == "--line" {
            let spec = it.next().ok_or(usage)?;
            let (label, value) = spec
                .rsplit_once('=')
                .and_then(|(l, v)| Some((l, v.parse::<f64>().ok()?)))
                .ok_or_else(|| format!("--line {spec}: want LABEL=VALUE"))?;
            lines.push((label.to_string(), value));
        } else {
            // LABEL=LOG.csv, or LOG.csv labelled by its run's directory.
            logs.push(match a.split_once('=') {
                Some((label, log)) => (label.to_string(), log.to_string()),
                None => {
                    let run = std::path::Path::new(a)
                        .parent()
                        .and_then(|p| p.file_name())
                        .map_or(a.clone(), |n| n.to_string_lossy().into_owned());
                    (run, a.clone())
                }
            });
        }
    }
    if logs.is_empty() {
        return Err(usage.into());
    }
    let mut series = Vec::new();
    let mut most = 0.0f64;
    for (label, log) in logs {
        let points = curve(&log)?;
        most = most.max(points.last().map_or(0.0, |p| p.0));
        series.push(Series { label, points });
    }
    for (label, value) in lines {
        series.push(Series {
            label,
            points: vec![(0.0, value), (most, value)],
        });
    }
    let plot = Plot {
        title: title.clone(),
        x_label: "evaluations".into(),
        y_label: y_label.clone(),
        series,
        size: (900, 600),
    };
    std::fs::write(out, step_plot_png(&plot)?).map_err(|e| format!("{out}: {e}"))?;
    println!("wrote {out}");
    Ok(())
}
