//! `animats bench`: the standard workloads, engine beside baseline.

use crate::Failure;
use animats_bench::{Options, Row, WORKLOADS};

/// Arguments of `animats bench`.
#[derive(clap::Args)]
pub struct Args {
    /// Workloads to run (default: all of chain-64, cloth-32, cloth-128,
    /// nbody5, allpairs-1000, hopper, seaworld, stability).
    workloads: Vec<String>,
    /// Shorter n-body runs (5M and 20 steps instead of 50M and 100).
    #[arg(long)]
    quick: bool,
    /// Timed runs per measurement, after one warm-up (at least 5).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(5..=1000))]
    runs: u64,
}

fn si(x: f64) -> String {
    let (v, unit) = if x >= 1e9 {
        (x / 1e9, "G")
    } else if x >= 1e6 {
        (x / 1e6, "M")
    } else if x >= 1e3 {
        (x / 1e3, "k")
    } else {
        (x, "")
    };
    format!("{v:.2}{unit}")
}

fn ms(t: f64) -> String {
    format!("{:.3}", t * 1e3)
}

fn print_row(r: &Row) {
    let rate = if r.springs > 0 {
        format!(
            "{}/s pstep, {}/s spring-eval",
            si(r.particle_steps_per_s()),
            si(r.spring_evals_per_s())
        )
    } else {
        format!(
            "{}/s pstep, {}/s pairs",
            si(r.particle_steps_per_s()),
            si(r.pairs_per_s())
        )
    };
    let base = match (&r.baseline, r.ratio()) {
        (Some((name, b)), Some(ratio)) => format!("{} ms {name}, ratio {ratio:.2}", ms(b.median)),
        _ => "-".into(),
    };
    println!(
        "{:<14} {:<34} {:>10} ms [{}–{}]  {}  {} sim-s/s  | baseline {}",
        r.workload,
        r.variant,
        ms(r.engine.median),
        ms(r.engine.min),
        ms(r.engine.max),
        rate,
        si(r.sim_per_wall()),
        base
    );
    for c in &r.checks {
        let verdict = match (c.passed(), c.target_met()) {
            (Some(true), _) => "ok".to_string(),
            (Some(false), _) => "MISMATCH".to_string(),
            (None, Some(true)) => "target met".to_string(),
            (None, Some(false)) => "target MISSED (reported, not a failure)".to_string(),
            (None, None) => "info".to_string(),
        };
        use animats_bench::Bound;
        let against = match c.bound {
            Bound::Near {
                expected,
                tolerance,
            } => format!("expected {expected:>+.10e} ± {tolerance:.1e}"),
            Bound::AtLeast(min) => format!("at least {min}"),
            Bound::AtMost(max) => format!("at most {max}"),
            Bound::Target(min) => format!("goal at least {min}"),
            Bound::Info => String::new(),
        };
        println!(
            "    {:<30} {:>+.10e}  {against}  {verdict}",
            c.name, c.value
        );
    }
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let names: Vec<String> = if args.workloads.is_empty() {
        WORKLOADS.iter().map(|s| s.to_string()).collect()
    } else {
        args.workloads.clone()
    };
    for n in &names {
        if !WORKLOADS.contains(&n.as_str()) {
            return Err(Failure::Input(format!(
                "unknown workload `{n}` (expected one of: {})",
                WORKLOADS.join(", ")
            )));
        }
    }
    let opts = Options {
        quick: args.quick,
        runs: args.runs as usize,
    };
    println!(
        "animats bench: f64, 1 thread unless noted; median [min–max] of {} runs after a warm-up{}",
        opts.runs,
        if opts.quick { " (quick)" } else { "" }
    );
    let mut failed = 0;
    for n in &names {
        let rows = animats_bench::run(n, opts).map_err(Failure::Input)?;
        for r in &rows {
            print_row(r);
            failed += r
                .checks
                .iter()
                .filter(|c| c.passed() == Some(false))
                .count();
        }
    }
    if failed > 0 {
        return Err(Failure::Other(format!(
            "{failed} correctness check(s) failed"
        )));
    }
    Ok(())
}
