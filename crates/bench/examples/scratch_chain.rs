use animats_bench::mass_spring::*;
use animats_engine::IntegratorKind;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let kind = if a[1] == "rk4" {
        IntegratorKind::Rk4
    } else {
        IntegratorKind::Symplectic
    };
    let spec = if a[2] == "chain" {
        chain64()
    } else {
        cloth(a[2].parse().unwrap())
    };
    let reps: usize = a[3].parse().unwrap();
    let threads: usize = a[4].parse().unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut best = f64::MAX;
        let mut h = 0u64;
        for _ in 0..reps {
            let mut w = engine_world(&spec, kind);
            let t = std::time::Instant::now();
            for _ in 0..STEPS {
                w.step(DT).unwrap();
            }
            best = best.min(t.elapsed().as_secs_f64());
            h = w
                .state()
                .pos
                .iter()
                .chain(&w.state().vel)
                .fold(0u64, |h, p| {
                    (h ^ p.x.to_bits()
                        ^ p.y.to_bits().rotate_left(1)
                        ^ p.z.to_bits().rotate_left(2))
                    .wrapping_mul(0x100000001b3)
                });
        }
        println!("best {:.3} ms hash {h:016x}", best * 1e3);
    });
}
