//! Plots an `animats evolve` run's best fitness against the thesis's run 6
//! (Appendix C, Table 6: the generations at which its best improved).
//!
//! ```sh
//! animats evolve --generations 5000 --lanes 6 --seed 1 --out run5000
//! cargo run --release -p animats --example thesis_curve -- run5000/log.csv docs/img/fitness-vs-thesis.png 5000
//! ```

use animats_render::{step_plot_png, Plot, Series};

/// Table 6 of the thesis: (generation, best fitness) of run 6.
const TABLE_6: [(f64, f64); 48] = [
    (1.0, 72.83171),
    (2.0, 96.82743),
    (4.0, 120.4535),
    (13.0, 332.256),
    (15.0, 332.541),
    (87.0, 337.7446),
    (92.0, 341.008),
    (164.0, 341.8737),
    (183.0, 344.4472),
    (239.0, 349.7336),
    (446.0, 350.8979),
    (460.0, 352.6674),
    (474.0, 352.7621),
    (501.0, 352.7622),
    (559.0, 362.6665),
    (568.0, 414.8785),
    (593.0, 420.0207),
    (602.0, 454.6375),
    (1332.0, 459.1914),
    (1725.0, 470.7535),
    (3621.0, 540.1346),
    (3657.0, 542.7413),
    (3666.0, 552.0757),
    (3672.0, 558.6879),
    (3680.0, 599.9052),
    (3801.0, 601.232),
    (4029.0, 603.6041),
    (4054.0, 663.1124),
    (4206.0, 669.2489),
    (4564.0, 671.0384),
    (4690.0, 687.8718),
    (4903.0, 688.3639),
    (5104.0, 699.1869),
    (5168.0, 705.3337),
    (5312.0, 714.6791),
    (5340.0, 734.3799),
    (5579.0, 763.1431),
    (5924.0, 764.1444),
    (5937.0, 776.2422),
    (5944.0, 780.2547),
    (6076.0, 793.8003),
    (6090.0, 827.2725),
    (6299.0, 830.5289),
    (6373.0, 844.2516),
    (6483.0, 846.5078),
    (6740.0, 862.2766),
    (7038.0, 878.8873),
    (7902.0, 881.4445),
];

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let (log, out, until) = match args.as_slice() {
        [_, log, out] => (log, out, None),
        [_, log, out, g] => (log, out, g.parse::<f64>().ok()),
        _ => return Err("usage: thesis_curve LOG.csv OUT.png [GENERATIONS]".into()),
    };
    let text = std::fs::read_to_string(log).map_err(|e| format!("{log}: {e}"))?;
    // One row per improvement: lane, generation, fitness, ...
    let mut rows: Vec<(f64, f64)> = Vec::new();
    let mut last_generation = 0.0f64;
    for (k, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| -> Result<f64, String> {
            f.get(i)
                .and_then(|s| s.parse().ok())
                .ok_or_else(|| format!("{log}: line {}: not a log.csv row", k + 1))
        };
        let (g, fitness) = (num(1)?, num(2)?);
        rows.push((g, fitness));
        last_generation = last_generation.max(g);
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = f64::NEG_INFINITY;
    let mut ours = Vec::new();
    for (g, f) in rows {
        if f > best {
            best = f;
            ours.push((g, f));
        }
    }
    if let Some(&(_, f)) = ours.last() {
        ours.push((until.unwrap_or(last_generation), f));
    }
    let mut thesis: Vec<(f64, f64)> = TABLE_6.to_vec();
    thesis.extend([(8158.0, 883.721), (8927.0, 887.432)]);
    let plot = Plot {
        title: "Best fitness over all lanes: animats against the thesis's run 6".into(),
        x_label: "generation".into(),
        y_label: "best fitness (time upright + 50 × distance)".into(),
        series: vec![
            Series {
                label: "animats, best of 6 lanes (seed 1)".into(),
                points: ours,
            },
            Series {
                label: "thesis, run 6 (Table 6)".into(),
                points: thesis,
            },
        ],
        size: (900, 600),
    };
    let png = step_plot_png(&plot)?;
    std::fs::write(out, png).map_err(|e| format!("{out}: {e}"))?;
    println!("wrote {out}");
    Ok(())
}
