//! What a large world's step costs when it is called from outside any rayon
//! pool (as `animats simulate`, the Python bindings and most users' loops
//! call it) against inside the global pool (as `animats bench` times it):
//! the median time per step of 300 steps of cloth-128
//! (`mass_spring::engine_world`, 16,384 particles), symplectic Euler and
//! RK4, for `--runs` runs each (default 5), the two ways alternated. First,
//! what one empty split into two pieces costs (median of 300) from this
//! thread and from a pool thread, right after another and after 3 ms of
//! work (time enough for the pool's idle threads to fall asleep).
//!
//! `cargo run --release -p animats-bench --example outside_pool`

use animats_bench::mass_spring::{cloth, engine_world};
use animats_engine::{IntegratorKind, World};
use rayon::prelude::*;
use std::time::{Duration, Instant};

fn median(mut t: Vec<f64>) -> f64 {
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

/// Milliseconds per step over 300 steps.
fn per_step(w: &mut World) -> f64 {
    let t = Instant::now();
    for _ in 0..300 {
        if let Err(e) = w.step(1e-3) {
            eprintln!("outside_pool: {e}");
            std::process::exit(1);
        }
    }
    t.elapsed().as_secs_f64() * 1e3 / 300.0
}

/// Median microseconds of an empty split into two pieces, each after
/// `gap` of busy work on this thread.
fn split_cost(gap: Duration) -> f64 {
    let times = (0..300)
        .map(|_| {
            let t = Instant::now();
            while t.elapsed() < gap {}
            let t = Instant::now();
            (0..2usize).into_par_iter().for_each(|i| {
                std::hint::black_box(i);
            });
            t.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    median(times)
}

fn main() {
    let mut runs = 5usize;
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        match (flag.as_str(), args.next().and_then(|v| v.parse().ok())) {
            ("--runs", Some(v)) if v >= 1 => runs = v,
            _ => {
                eprintln!("outside_pool: expected --runs N (>= 1), got {flag:?}");
                std::process::exit(2);
            }
        }
    }
    for (gap, when) in [(0, "right after another"), (3000, "after 3 ms of work")] {
        let gap = Duration::from_micros(gap);
        let outside = split_cost(gap);
        let inside = rayon::scope(|_| split_cost(gap));
        println!(
            "an empty split {when}: {outside:.1} us from this thread, {inside:.2} us from a pool thread"
        );
    }
    let spec = cloth(128);
    println!(
        "cloth-128, 300 steps, global pool of {} threads; medians of {runs} runs",
        rayon::current_num_threads()
    );
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        let (mut outside, mut inside) = (Vec::new(), Vec::new());
        for _ in 0..runs {
            outside.push(per_step(&mut engine_world(&spec, kind)));
            let mut w = engine_world(&spec, kind);
            inside.push(rayon::scope(|_| per_step(&mut w)));
        }
        println!(
            "{}: {:.3} ms a step called from this thread, {:.3} ms from inside the pool",
            kind.name(),
            median(outside),
            median(inside)
        );
    }
}
