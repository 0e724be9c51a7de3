//! CMA-ES's own cost as its genome grows: the decomposition of a dense
//! covariance by Jacobi rotations and by Householder and QL (medians), and
//! a generation's ask and tell on an ellipsoid of condition 1e2 (60
//! generations from the start, the eigendecomposition refreshed as CMA-ES
//! refreshes it); one thread (docs/PERFORMANCE.md).
//!
//!     cargo run --release -p animats-bench --example cma_es_genes
// std's powf: a benchmark's objective, not the step path
#![allow(clippy::disallowed_methods)]

use animats_evolve::optimiser::eigen::{householder_ql_eigen, jacobi_eigen};
use animats_evolve::optimiser::{AnyOptimiser, Optimiser, OptimiserKind, Random, Setup};
use std::time::Instant;

/// The median of `runs` timings of `f`, s.
fn median_of(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn main() -> Result<(), String> {
    let mut rng = Random::for_entry(7, 0);
    println!("genes | Jacobi | Householder-QL | a generation (ask + tell)");
    for n in [20usize, 100, 300, 1000] {
        // B Bᵀ + I for B uniform in [−½, ½): dense, well conditioned.
        let b: Vec<f64> = (0..n * n).map(|_| rng.uniform() - 0.5).collect();
        let mut c = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let dot: f64 = (0..n).map(|k| b[i * n + k] * b[j * n + k]).sum();
                c[i * n + j] = dot + if i == j { 1.0 } else { 0.0 };
            }
        }
        let runs = if n >= 1000 { 3 } else { 11 };
        let ql = median_of(runs, || {
            std::hint::black_box(householder_ql_eigen(&c, n));
        });
        // Jacobi on 1,000 rows takes minutes.
        let jacobi = (n <= 300).then(|| {
            median_of(runs, || {
                std::hint::black_box(jacobi_eigen(&c, n));
            })
        });
        let setup = Setup {
            kind: OptimiserKind::CmaEs,
            start: vec![1.0; n],
            bounds: None,
            population: None,
            seed: 1,
            lane: 0,
            sigma: Some(0.5),
            restarts: 0,
        };
        let mut o = AnyOptimiser::new(&setup)?;
        let generations = 60;
        let start = Instant::now();
        for _ in 0..generations {
            let pop = o.ask();
            let fitness: Vec<f64> = pop
                .iter()
                .map(|x| {
                    -x.iter()
                        .enumerate()
                        .map(|(i, v)| 100f64.powf(i as f64 / (n - 1) as f64) * v * v)
                        .sum::<f64>()
                })
                .collect();
            o.tell(&fitness)?;
        }
        let generation = start.elapsed().as_secs_f64() / generations as f64;
        let ms = |s: f64| format!("{:.3} ms", s * 1e3);
        println!(
            "{n} | {} | {} | {}",
            jacobi.map_or("—".into(), ms),
            ms(ql),
            ms(generation)
        );
    }
    Ok(())
}
