//! `cargo bench`: the standard workloads in quick mode, engine beside baseline.
//! (`animats bench` runs the full set; see docs/PERFORMANCE.md.)

fn main() {
    // `cargo bench -- NAME...` picks workloads; cargo's own flags are ignored.
    let mut names: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    if names.is_empty() {
        names = ["chain-64", "cloth-32", "nbody5", "allpairs-1000"]
            .map(String::from)
            .to_vec();
    }
    let opts = animats_bench::Options {
        quick: true,
        runs: 5,
    };
    for name in names {
        match animats_bench::run(&name, opts) {
            Ok(rows) => {
                for r in rows {
                    let ratio = r.ratio().map_or("-".into(), |x| format!("{x:.2}"));
                    let failed = r
                        .checks
                        .iter()
                        .filter(|c| c.passed() == Some(false))
                        .count();
                    println!(
                        "{:<14} {:<36} median {:>10.3} ms  [{:.3}–{:.3}]  vs baseline {ratio}  checks failed: {failed}",
                        r.workload,
                        r.variant,
                        r.engine.median * 1e3,
                        r.engine.min * 1e3,
                        r.engine.max * 1e3
                    );
                }
            }
            Err(e) => eprintln!("{e}"),
        }
    }
}
