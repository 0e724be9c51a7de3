//! `animats bench`: the standard workloads, engine beside baseline.

use crate::Failure;
use animats_bench::{Options, Row, WORKLOADS};

/// Arguments of `animats bench`.
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Args {
    #[command(subcommand)]
    instrument: Option<Instrument>,
    /// Workloads to run (default: all of chain-64, cloth-32, cloth-128,
    /// nbody5, allpairs-1000, hopper, brains, seaworld, stability,
    /// scene-load; `implicit`, `contacts`, `bodies` and `diversity` only
    /// when named).
    workloads: Vec<String>,
    /// Shorter n-body runs (5M and 20 steps instead of 50M and 100); the
    /// implicit race on cloth-32 instead of cloth-128.
    #[arg(long)]
    quick: bool,
    /// Timed runs per measurement, after one warm-up (at least 5).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(5..=1000))]
    runs: u64,
    /// Print one JSON object per measurement (every timed run, the checks,
    /// the machine and the date) instead of the table, for keeping results
    /// per machine.
    #[arg(long)]
    json: bool,
}

/// Instruments that measure a run of the user's own rather than a
/// standard workload.
#[derive(clap::Subcommand)]
enum Instrument {
    /// Where an evolution's time goes, and its speed-up predicted on 1 to 64
    /// workers (`animats evolve ... --schedule`).
    ///
    /// `animats bench scaling [SCENE] [OPTIONS]` is `animats evolve [SCENE]
    /// [OPTIONS] --schedule` (the same options, the same run, log and
    /// files; docs/PERFORMANCE.md, "Evolution on many cores"): it records every ask,
    /// evaluation and tell into DIR/schedule.csv and, from their measured
    /// times and the run's own dependencies, predicts the wall time and
    /// speed-up on 1, 2, 4, 8, 16, 32 and 64 workers, beside the wall time
    /// it took on --threads.
    Scaling(crate::evolve::Args),
}

/// The machine, for `--json`: CPU model (Linux's /proc/cpuinfo), cores, OS,
/// and the vector instructions the engine chose on it.
fn machine() -> serde_json::Value {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    serde_json::json!({
        "cpu": cpu,
        "cores": cores,
        "os": std::env::consts::OS,
        "arch": std::env::consts::ARCH,
        "simd": animats_engine::simd_summary(),
        "built_for": built_for(),
    })
}

/// The instruction sets the binary was compiled to use beyond its
/// architecture's baseline (`avx2,fma,…` for the workspace's x86-64-v3),
/// or `baseline`.
fn built_for() -> &'static str {
    match animats_engine::cpu::required_features() {
        "" => "baseline",
        f => f,
    }
}

/// Today's UTC date, YYYY-MM-DD (civil from days since 1970, Hinnant's algorithm).
fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let z = secs.div_euclid(86_400) + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

/// One measurement as a JSON object.
fn json_row(r: &Row, quick: bool, machine: &serde_json::Value, date: &str) -> serde_json::Value {
    use animats_bench::Bound;
    let timing = |t: &animats_bench::Timing| serde_json::json!({ "median_s": t.median, "min_s": t.min, "max_s": t.max, "runs_s": t.times });
    let checks: Vec<serde_json::Value> = r
        .checks
        .iter()
        .map(|c| {
            let (kind, bound) = match c.bound {
                Bound::Near { expected, tolerance } => ("near", serde_json::json!({ "expected": expected, "tolerance": tolerance })),
                Bound::AtLeast(min) => ("at_least", serde_json::json!({ "min": min })),
                Bound::AtMost(max) => ("at_most", serde_json::json!({ "max": max })),
                Bound::Target(min) => ("target", serde_json::json!({ "min": min })),
                Bound::TargetAtMost(max) => ("target", serde_json::json!({ "max": max })),
                Bound::Info => ("info", serde_json::Value::Null),
            };
            serde_json::json!({ "name": c.name, "value": c.value, "kind": kind, "bound": bound, "passed": c.passed(), "target_met": c.target_met() })
        })
        .collect();
    let (threads, mode) = r.threads();
    serde_json::json!({
        "workload": r.workload,
        "variant": r.variant,
        "threads": threads,
        "mode": mode,
        "particles": r.particles,
        "springs": r.springs,
        "steps": r.steps,
        "dt": r.dt,
        "evaluations": r.evaluations,
        "pairs": r.pairs,
        "quick": quick,
        "engine": timing(&r.engine),
        "baseline": r.baseline.as_ref().map(|(name, t)| serde_json::json!({ "name": name, "timing": timing(t) })),
        "sim_s_per_wall_s": r.sim_per_wall(),
        "checks": checks,
        "machine": machine,
        "date": date,
    })
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
    let rate = if r.dt == 0.0 && r.particles == 0 {
        // A row timed per item (a body evaluated, a child made): items a
        // second.
        format!("{}/s", si(1.0 / r.engine.median))
    } else if r.dt == 0.0 {
        // Nothing simulated (scene-load): what was built, per second.
        format!(
            "{}/s particles built",
            si(r.particles as f64 / r.engine.median)
        )
    } else if r.springs > 0 {
        format!(
            "{}/s pstep, {}/s spring-eval",
            si(r.particle_steps_per_s()),
            si(r.spring_evals_per_s())
        )
    } else if r.pairs > 0 {
        format!(
            "{}/s pstep, {}/s pairs",
            si(r.particle_steps_per_s()),
            si(r.pairs_per_s())
        )
    } else {
        // Neither springs nor force pairs (the contact piles).
        format!("{}/s pstep", si(r.particle_steps_per_s()))
    };
    let base = match (&r.baseline, r.ratio()) {
        (Some((name, b)), Some(ratio)) => format!("{} ms {name}, ratio {ratio:.2}", ms(b.median)),
        _ => "-".into(),
    };
    let sim = if r.dt == 0.0 {
        String::new()
    } else {
        format!("  {} sim-s/s", si(r.sim_per_wall()))
    };
    say!(
        "{:<14} {:<34} {:>10} ms [{}–{}]  {}{}  | baseline {}",
        r.workload,
        r.variant,
        ms(r.engine.median),
        ms(r.engine.min),
        ms(r.engine.max),
        rate,
        sim,
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
            Bound::TargetAtMost(max) => format!("goal at most {max}"),
            Bound::Info => String::new(),
        };
        say!(
            "    {:<30} {:>+.10e}  {against}  {verdict}",
            c.name,
            c.value
        );
    }
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    if let Some(Instrument::Scaling(mut evolve)) = args.instrument {
        evolve.schedule = true;
        return crate::evolve::run(evolve);
    }
    let names: Vec<String> = if args.workloads.is_empty() {
        WORKLOADS.iter().map(|s| s.to_string()).collect()
    } else {
        args.workloads.clone()
    };
    for n in &names {
        if !animats_bench::is_workload(n) {
            return Err(Failure::Input(format!(
                "unknown workload `{n}` (expected one of: {}; or on request: {})",
                WORKLOADS.join(", "),
                animats_bench::ON_REQUEST.join(", ")
            )));
        }
    }
    let opts = Options {
        quick: args.quick,
        runs: args.runs as usize,
    };
    let (machine, date) = (machine(), today());
    if !args.json {
        say!(
        "animats bench: f64, 1 thread unless noted; median [min–max] of {} runs after a warm-up{}; vectors: {}; built for: {}",
        opts.runs,
        if opts.quick { " (quick)" } else { "" },
        animats_engine::simd_summary(),
        built_for()
    );
    }
    let mut failed = 0;
    for n in &names {
        let rows = animats_bench::run(n, opts).map_err(Failure::Input)?;
        for r in &rows {
            if args.json {
                say!("{}", json_row(r, opts.quick, &machine, &date));
            } else {
                print_row(r);
            }
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
