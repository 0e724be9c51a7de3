//! Where cloth-128's second thread goes: the median wall time of 1,000
//! symplectic steps of the workload (`mass_spring::engine_world`), of the
//! same without its floor rule (no event to check), and of 1,000 force
//! evaluations alone at its starting state, on a pool of one thread and of
//! two, for `--runs` runs each (default 7); then the force evaluations on
//! one thread alone and with a second, independent copy running on the
//! other core at the same time (what the hardware shares).
//!
//! `cargo run --release -p animats-bench --example cloth_threads`

use animats_bench::mass_spring::{cloth, engine_world, spring_world, DAMPING, STIFFNESS};
use animats_engine::{DVec3, IntegratorKind};
use std::time::Instant;

fn median(mut t: Vec<f64>) -> f64 {
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn main() {
    let mut runs = 7usize;
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        match (flag.as_str(), args.next().and_then(|v| v.parse().ok())) {
            ("--runs", Some(v)) if v >= 1 => runs = v,
            _ => {
                eprintln!("cloth_threads: expected --runs N (>= 1), got {flag:?}");
                std::process::exit(2);
            }
        }
    }
    let spec = cloth(128);
    println!("cloth-128, symplectic Euler, 1,000 steps; medians of {runs} runs");
    for threads in [1, 2] {
        let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(threads).build() else {
            eprintln!("cloth_threads: cannot start {threads} threads");
            std::process::exit(1);
        };
        let time_steps = |floor: bool| -> Vec<f64> {
            (0..runs)
                .map(|_| {
                    let mut w = if floor {
                        engine_world(&spec, IntegratorKind::Symplectic)
                    } else {
                        spring_world(&spec, STIFFNESS, DAMPING, IntegratorKind::Symplectic)
                    };
                    pool.install(|| {
                        let t = Instant::now();
                        for _ in 0..1000 {
                            if let Err(e) = w.step(1e-3) {
                                eprintln!("cloth_threads: {e}");
                                std::process::exit(1);
                            }
                        }
                        t.elapsed().as_secs_f64()
                    })
                })
                .collect()
        };
        let (steps, bare) = (time_steps(true), time_steps(false));
        let w = engine_world(&spec, IntegratorKind::Symplectic);
        let (state, particles) = (w.state().clone(), w.particles().clone());
        let mut forces = w.forces().clone();
        drop(w);
        let mut out = vec![DVec3::ZERO; state.pos.len()];
        let evaluations = (0..runs)
            .map(|_| {
                pool.install(|| {
                    let t = Instant::now();
                    for _ in 0..1000 {
                        forces.evaluate(0.0, 1e-3, &state.pos, &state.vel, &particles, &mut out);
                    }
                    t.elapsed().as_secs_f64()
                })
            })
            .collect();
        let (s, b, e) = (median(steps), median(bare), median(evaluations));
        println!(
            "{threads} thread(s): steps {:.1} ms, without the floor rule {:.1} ms, force evaluations alone {:.1} ms, the rest of the step {:.1} ms",
            s * 1e3,
            b * 1e3,
            e * 1e3,
            (s - e) * 1e3
        );
    }
    // The machine's share: two copies of the whole evaluation, one per
    // core, at once, each on its own world (nothing shared but the
    // hardware), against one copy alone.
    let evaluate_alone = || -> f64 {
        let w = engine_world(&spec, IntegratorKind::Symplectic);
        let (state, particles) = (w.state().clone(), w.particles().clone());
        let mut forces = w.forces().clone();
        let mut out = vec![DVec3::ZERO; state.pos.len()];
        let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(1).build() else {
            eprintln!("cloth_threads: cannot start a thread");
            std::process::exit(1);
        };
        median(
            (0..runs)
                .map(|_| {
                    pool.install(|| {
                        let t = Instant::now();
                        for _ in 0..1000 {
                            forces
                                .evaluate(0.0, 1e-3, &state.pos, &state.vel, &particles, &mut out);
                        }
                        t.elapsed().as_secs_f64()
                    })
                })
                .collect(),
        )
    };
    let alone = evaluate_alone();
    let both: Vec<f64> = std::thread::scope(|s| {
        let copies: Vec<_> = (0..2).map(|_| s.spawn(evaluate_alone)).collect();
        copies.into_iter().filter_map(|c| c.join().ok()).collect()
    });
    if let [a, b] = both[..] {
        println!(
            "1,000 force evaluations on one thread: {:.1} ms alone, {:.1} / {:.1} ms with a second copy on the other core",
            alone * 1e3,
            a * 1e3,
            b * 1e3
        );
    }
}
