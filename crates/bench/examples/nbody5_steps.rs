//! Steps the built-in nbody5 world N times, or with `reference` the
//! reference program's `advance`, and prints the energy: a workload for a
//! profiler (`valgrind --tool=callgrind target/release/examples/nbody5_steps
//! 200000 [reference]`; docs/PERFORMANCE.md).
//!
//!     cargo build --release -p animats-bench --example nbody5_steps
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    if std::env::args().nth(2).as_deref() == Some("reference") {
        let mut r = animats_bench::nbody5::Reference::new();
        for _ in 0..n {
            r.advance(animats_bench::nbody5::DT);
        }
        println!("{}", r.energy());
        return;
    }
    let mut w = animats_bench::nbody5::builtin_world();
    for _ in 0..n {
        w.step(animats_bench::nbody5::DT).expect("finite");
    }
    println!("{}", animats_bench::nbody5::world_energy(&w));
}
