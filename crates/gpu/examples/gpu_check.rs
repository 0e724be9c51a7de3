//! The GPU against the CPU (issue 42's checks 1 and 2, for the bodies the
//! C steps today): a batch of random bodies of springs and joints dropped
//! onto the floor, stepped by the engine on every core (what `animats`
//! does, strict), by the C on every core, and by the GPU; every coordinate
//! compared as bits; throughput of each.
//!
//!     cargo run --release -p animats-gpu --example gpu_check -- [CREATURES] [STEPS] [PARTICLES] [INTEGRATOR]
//!
//! PARTICLES 0 (the default) mixes sizes of 2 to 40. INTEGRATOR as a
//! scene's `integrator` (default `rk4`; `implicit` runs implicit Euler's
//! kernels). Exit 2 where no GPU
//! can be used (the message says why), 1 if any bit differs.
//! `ANIMATS_SKIP_C=1` leaves the C on the CPU out (the GPU compared with
//! the engine); `ANIMATS_GPU_SORT=1` puts the creatures in order of size
//! (`animats_gpu::order`) before anything runs; `ANIMATS_GPU_REGS` and `ANIMATS_GPU_BLOCK` tune the kernel
//! (`animats_gpu::Tuning`), `ANIMATS_GPU_SPECIALISE=0` runs the whole kernel
//! instead of one specialised for the batch (`animats_gpu::Special`);
//! `ANIMATS_PREPARE_ONLY=1` only compiles and loads the batch's kernel.

use animats_creatures::random::Random;
use animats_engine::{FloorDef, IntegratorKind, World};
use animats_gpu::bodies::random_body;
use animats_gpu::{Batch, Device, Layout};
use rayon::prelude::*;
use std::time::Instant;

fn main() {
    let arg = |k: usize, default: u64| -> u64 {
        std::env::args()
            .nth(k)
            .map_or(Ok(default), |a| a.parse())
            .unwrap_or_else(|_| {
                eprintln!("usage: gpu_check [CREATURES] [STEPS] [PARTICLES]: whole numbers");
                std::process::exit(2)
            })
    };
    let (creatures, steps, particles) = (arg(1, 65_536), arg(2, 1000), arg(3, 20));
    let kind: IntegratorKind = match std::env::args()
        .nth(4)
        .map_or(Ok(IntegratorKind::Rk4), |a| a.parse())
    {
        Ok(kind) => kind,
        Err(e) => {
            eprintln!("gpu_check: INTEGRATOR: {e}");
            std::process::exit(2)
        }
    };
    if creatures == 0 || creatures > 10_000_000 || particles == 1 || particles > 1000 {
        eprintln!("gpu_check: 1 to 10,000,000 creatures of 2 to 1000 particles (0: mixed)");
        std::process::exit(2);
    }
    let dt = 1e-3;
    let mut rng = Random::for_entry(42, 0);
    let worlds: Vec<World> = (0..creatures)
        .map(|k| {
            let n = if particles == 0 {
                2 + (rng.uniform() * 39.0) as usize
            } else {
                particles as usize
            };
            let mut w = match random_body(&mut rng, n, true, k % 2 == 0, kind) {
                Ok(w) => w,
                Err(e) => {
                    eprintln!("gpu_check: {e}");
                    std::process::exit(2);
                }
            };
            // Dropped onto the floor: bounces, backtracking, resting.
            for p in w.particle_ids().collect::<Vec<_>>() {
                let x = w.position(p) + animats_engine::DVec3::new(0.0, 1.2, 0.0);
                if let Err(e) = w.set_position(p, x) {
                    eprintln!("gpu_check: {e}");
                    std::process::exit(2);
                }
            }
            if let Err(e) = w.add_floor(FloorDef::default()) {
                eprintln!("gpu_check: {e}");
                std::process::exit(2);
            }
            w
        })
        .collect();
    // ANIMATS_GPU_SORT=1: the creatures in order of size (animats_gpu::order),
    // for the engine and the GPU alike, so that the bits still compare.
    let sorted = match animats_gpu::order::sort_from_env() {
        Ok(sort) => sort,
        Err(e) => {
            eprintln!("gpu_check: {e}");
            std::process::exit(2);
        }
    };
    let mut worlds = worlds;
    if sorted {
        worlds.sort_by_key(animats_gpu::order::world_size);
    }
    let total_particles: usize = worlds.iter().map(World::len).sum();
    let refs: Vec<&World> = worlds.iter().collect();
    let packed = match Batch::pack(&refs, dt) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("gpu_check: {e}");
            std::process::exit(2);
        }
    };
    // `ANIMATS_PREPARE_ONLY=1`: the batch's kernel compiled (into the
    // disk's cache) and loaded, nothing run or timed: bench/gpu.sh compiles
    // its runs' kernels side by side so.
    if std::env::var_os("ANIMATS_PREPARE_ONLY").is_some_and(|v| !v.is_empty()) {
        let ready = Device::open().and_then(|d| {
            let mut warm = packed.clone();
            d.run(&mut warm, 1).map(|()| d.kernel_options(&packed))
        });
        match ready {
            Ok(options) => println!("kernel ready: {}", options.join(" ")),
            Err(e) => {
                eprintln!("gpu_check: {e}");
                std::process::exit(2);
            }
        }
        return;
    }
    println!(
        "{creatures} creatures ({total_particles} particles; {}) dropped onto the floor, {steps} {} steps of {dt} s, {} CPU threads{}",
        if particles == 0 { "2 to 40 particles each".to_string() } else { format!("{particles} particles each") },
        kind.name(),
        rayon::current_num_threads(),
        if sorted { "; in order of size (ANIMATS_GPU_SORT)" } else { "" }
    );
    println!(
        "warps of 32: {:.1} % of their lanes busy in loops over particles (sizes differ)",
        100.0 * animats_gpu::order::warp_busy(&worlds.iter().map(World::len).collect::<Vec<_>>())
    );
    let rate = |secs: f64| (creatures * steps) as f64 / secs;

    let t = Instant::now();
    worlds.par_iter_mut().for_each(|w| {
        for _ in 0..steps {
            if w.step(dt).is_err() {
                break;
            }
        }
    });
    let engine = t.elapsed().as_secs_f64();
    println!(
        "engine, every core:  {engine:8.3} s  {:.3e} creature-steps/s",
        rate(engine)
    );

    // `ANIMATS_SKIP_C=1` leaves the C on the CPU out (CI proves it the
    // engine's bits; bench/gpu.sh saves the device's time so): the GPU is
    // then compared with the engine.
    let skip_c = std::env::var_os("ANIMATS_SKIP_C").is_some_and(|v| !v.is_empty());
    let cpu = (!skip_c).then(|| {
        let mut cpu = packed.clone();
        let t = Instant::now();
        cpu.run_cpu(steps);
        let c_cpu = t.elapsed().as_secs_f64();
        println!(
            "C, every core:       {c_cpu:8.3} s  {:.3e} creature-steps/s",
            rate(c_cpu)
        );
        cpu
    });
    // Every creature's particles, the engine's, as bits.
    let sizes: Vec<usize> = worlds.iter().map(World::len).collect();
    let bits = |v: animats_engine::DVec3| v.to_array().map(f64::to_bits);
    let engine_bits: Vec<Vec<[[u64; 3]; 2]>> = worlds
        .iter()
        .map(|w| {
            (0..w.len())
                .map(|i| [bits(w.state().pos[i]), bits(w.state().vel[i])])
                .collect()
        })
        .collect();
    // Creatures of `b` whose bits differ from `reference(c, i)`'s.
    let differ = |b: &Batch, reference: &dyn Fn(usize, usize) -> [[u64; 3]; 2]| -> usize {
        (0..creatures as usize)
            .filter(|&c| {
                (0..sizes[c]).any(|i| {
                    let (x, v) = b.state(c, i).unwrap_or_default();
                    [bits(x), bits(v)] != reference(c, i)
                })
            })
            .count()
    };
    let bad = cpu.as_ref().map_or(0, |cpu| {
        let bad = differ(cpu, &|c, i| engine_bits[c][i]);
        println!("C on the CPU against the engine: {bad} of {creatures} creatures differ");
        bad
    });

    let device = match Device::open() {
        Ok(d) => d,
        Err(e) => {
            eprintln!("gpu_check: {e}");
            std::process::exit(if bad == 0 { 2 } else { 1 });
        }
    };
    println!(
        "GPU tuning: {:?}; {} threads a block for this batch; kernel options: {}",
        device.tuning(),
        device.threads_a_block(creatures as usize),
        device.kernel_options(&packed).join(" ")
    );
    // Once to warm (the module is loaded; the first launch pays for it).
    let mut warm = packed.clone();
    if let Err(e) = device.run(&mut warm, 1) {
        eprintln!("gpu_check: {e}");
        std::process::exit(2);
    }
    match device.kernel_report(&packed) {
        Ok(report) => println!("GPU kernel: {report}"),
        Err(e) => {
            eprintln!("gpu_check: {e}");
            std::process::exit(2);
        }
    }
    // Each creature's state in the thread's local memory (the default),
    // then in the batch's arrays.
    let mut bad_gpu = 0;
    for layout in [Layout::Local, Layout::Batch] {
        let mut gpu = packed.clone();
        gpu.set_layout(layout);
        let t = Instant::now();
        if let Err(e) = device.run(&mut gpu, steps) {
            eprintln!("gpu_check: {e}");
            std::process::exit(2);
        }
        let on_gpu = t.elapsed().as_secs_f64();
        println!(
            "GPU ({}), {layout:?}, copies included: {on_gpu:8.3} s  {:.3e} creature-steps/s: {:.1}x the engine on every core",
            device.name(),
            rate(on_gpu),
            engine / on_gpu
        );
        let (differ, against) = match &cpu {
            Some(cpu) => (
                differ(&gpu, &|c, i| {
                    let (x, v) = cpu.state(c, i).unwrap_or_default();
                    [bits(x), bits(v)]
                }),
                "C on the CPU",
            ),
            None => (differ(&gpu, &|c, i| engine_bits[c][i]), "engine"),
        };
        println!(
            "GPU, {layout:?}, against the {against}: {differ} of {creatures} creatures differ"
        );
        bad_gpu += differ;
    }
    if bad > 0 || bad_gpu > 0 {
        std::process::exit(1);
    }
}
