//! Whole evaluations, GPU against CPU (issue 42's checks 1 and 2): a
//! population of the soft walker (`scenes/walker.toml`, its own genome and
//! random oscillator genomes within its bounds) or of random evolved
//! bodies (`scenes/bodies_walk.toml`'s random starts, with the archive's
//! measures: feet on the floor, size), evaluated by the engine on every core (what
//! `animats evolve` does, strict), by the C on every core, and by the
//! GPU; every fitness, distance, time and end reason compared as bits;
//! evaluations and creature-steps per second of each.
//!
//! `neural`: the same bodies with neural brains reading touch sensors.
//! `quadruped`: the thesis's model 3 (`scenes/quadruped3_walk.toml`, 12
//! oscillating leg springs, in air, its steps at 0.5 ms), its evolved gait
//! and gaits around it, each gene moved by up to 5 % of its range (a late
//! population of `animats evolve`: most walk, some fall).
//!
//! `roobot`: the thesis's hopper (`scenes/hop_evolver.toml`, RK4 at 8 ms,
//! held in its plane, its hopping FSM) with the evolved parameters and
//! parameters around them, each moved by up to 2 % of its range.
//!
//! `raibert`: the same hopper under Raibert's controller (`brain =
//! "raibert"`), its hand-set gains and gains around them, each moved by up
//! to 5 % of its range.
//!
//! `jellyfish`: the thesis's jellyfish under its own pulses
//! (`scenes/jellyfish_swim.toml`, RK4 at 10 ms), its food put at random
//! within 3 m of it (so that it steers), its ceiling at random between
//! 0.5 and 5 m (so that it idles and hovers).
//!
//! `rough`: the walker on rough ground (`scenes/walker_rough.toml`: a
//! heightfield, the kernel compiled with terrain), its evolved gait and
//! random ones.
//!
//! `rocks`: the walker among rocks (`scenes/walker_rocks.toml`: sphere
//! contact, the event, in a kernel of its own), gaits about its own, each
//! gene moved by up to 5 % of its range.
//!
//!     cargo run --release -p animats-gpu --example gpu_evaluate -- [walker|bodies|neural|quadruped|roobot|raibert|jellyfish|rough|rocks] [COUNT] [SECONDS]
//!
//! `ANIMATS_CPU_FAST=1` times the C in fast mode on the CPU too;
//! `ANIMATS_SKIP_C=1` leaves the C on the CPU out, `ANIMATS_SKIP_FAST=1`
//! (either set and not empty)
//! the GPU's fast mode; `ANIMATS_GPU_SORT=1` puts the scenes in order of
//! size (`animats_gpu::order`) before anything runs; `ANIMATS_GPU_REGS`
//! and `ANIMATS_GPU_BLOCK` tune the kernel (`animats_gpu::Tuning`);
//! `ANIMATS_GPU_SPECIALISE=0` runs the whole kernel instead of one
//! specialised for the batch (`animats_gpu::Special`);
//! `ANIMATS_PREPARE_ONLY=1` only compiles and loads the batch's kernels.
//!
//! Exit 2 where no GPU can be used (after the CPU's comparison; the
//! message says why), 1 if any bit differs.

use animats_creatures::random::Random;
use animats_gpu::{Batch, Device, Layout, Mode, Schedule};
use animats_scene::evaluate::{evaluate, Evaluation, SceneProblem};
use animats_scene::morphology::MorphologyProblem;
use animats_scene::Scene;
use rayon::prelude::*;
use std::time::Instant;

const WALKER: &str = include_str!("../../../scenes/walker.toml");
const BODIES_WALK: &str = include_str!("../../../scenes/bodies_walk.toml");
const QUADRUPED_WALK: &str = include_str!("../../../scenes/quadruped3_walk.toml");
const HOP_EVOLVER: &str = include_str!("../../../scenes/hop_evolver.toml");
const WALKER_ROUGH: &str = include_str!("../../../scenes/walker_rough_evolved.toml");
const WALKER_ROCKS: &str = include_str!("../../../scenes/walker_rocks.toml");
const JELLYFISH_SWIM: &str = include_str!("../../../scenes/jellyfish_swim.toml");

fn fail(e: impl std::fmt::Display) -> ! {
    eprintln!("gpu_evaluate: {e}");
    std::process::exit(2)
}

/// Scene `k` of the population.
fn scene(kind: &str, seconds: f64, k: u64) -> Result<Scene, String> {
    let duration = |t: &str| t.replace("duration = 10.0", &format!("duration = {seconds}"));
    let mut rng = Random::for_entry(42, k);
    if kind == "walker" || kind == "rough" {
        let (text, file) = if kind == "walker" {
            (WALKER, "scenes/walker.toml")
        } else {
            (WALKER_ROUGH, "scenes/walker_rough_evolved.toml")
        };
        let problem = SceneProblem::parse(&duration(text), file).map_err(|e| e.to_string())?;
        if k == 0 {
            return problem.fresh();
        }
        let g: Vec<f64> = problem
            .bounds()
            .iter()
            .map(|&(lo, hi)| rng.between(lo, hi))
            .collect();
        problem.scene(&g)
    } else if kind == "jellyfish" {
        let text = JELLYFISH_SWIM
            .replace("duration = 20.0", &format!("duration = {seconds}"))
            .replace(
                "position = [0.0, 1000.0, 0.0]",
                &format!(
                    "position = [{}, {}, {}]",
                    rng.between(-3.0, 3.0),
                    rng.between(-3.0, 3.0),
                    rng.between(-3.0, 3.0)
                ),
            )
            .replace(
                "ceiling = 2000.0",
                &format!("ceiling = {}", rng.between(0.5, 5.0)),
            );
        animats_scene::parse(&text, "scenes/jellyfish_swim.toml").map_err(|e| e.to_string())
    } else if kind == "quadruped" || kind == "roobot" || kind == "raibert" || kind == "rocks" {
        let (text, file, spread) = if kind == "quadruped" {
            (
                QUADRUPED_WALK.to_string(),
                "scenes/quadruped3_walk.toml",
                0.05,
            )
        } else if kind == "rocks" {
            // Gaits about the walker's, which walk into the rocks.
            (duration(WALKER_ROCKS), "scenes/walker_rocks.toml", 0.05)
        } else if kind == "raibert" {
            let own = HOP_EVOLVER.replace("params = \"initial\"", "brain = \"raibert\"");
            (own, "scenes/hop_evolver.toml", 0.05)
        } else {
            let evolved = HOP_EVOLVER.replace("params = \"initial\"", "params = \"evolved\"");
            (evolved, "scenes/hop_evolver.toml", 0.02)
        };
        let text = text.replace("duration = 20.0", &format!("duration = {seconds}"));
        let problem = SceneProblem::parse(&text, file).map_err(|e| e.to_string())?;
        let g: Vec<f64> = problem
            .start()
            .iter()
            .zip(problem.bounds())
            .map(|(&x, &(lo, hi))| {
                let moved = x + (hi - lo) * rng.between(-spread, spread);
                if k == 0 {
                    x
                } else {
                    moved.clamp(lo, hi)
                }
            })
            .collect();
        problem.scene(&g)
    } else {
        let mut text = duration(BODIES_WALK);
        if kind == "neural" {
            text = text.replace("controller = \"oscillator\"", "controller = \"neural\"");
        }
        let problem = MorphologyProblem::parse(&text, "scenes/bodies_walk.toml")
            .map_err(|e| e.to_string())?;
        let genes = problem.random(&mut rng);
        let text = problem.develop(&genes, "")?;
        animats_scene::parse(&text, "body.toml").map_err(|e| e.to_string())
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map_or("walker", String::as_str);
    let count: u64 = args
        .get(2)
        .map_or(Ok(65_536), |a| a.parse())
        .unwrap_or_else(|_| fail("COUNT: a whole number"));
    let seconds: f64 = args
        .get(3)
        .map_or(Ok(10.0), |a| a.parse())
        .unwrap_or_else(|_| fail("SECONDS: a number"));
    if !matches!(
        kind,
        "walker"
            | "bodies"
            | "neural"
            | "quadruped"
            | "roobot"
            | "raibert"
            | "jellyfish"
            | "rough"
            | "rocks"
    ) || !(1..=10_000_000).contains(&count)
    {
        fail("usage: gpu_evaluate [walker|bodies|neural|quadruped|roobot|raibert|jellyfish|rough|rocks] [COUNT 1 to 10,000,000] [SECONDS]");
    }
    if !(seconds > 0.0 && seconds <= 1000.0) {
        fail("SECONDS: more than 0, at most 1000");
    }
    let build = || -> Vec<Scene> {
        (0..count)
            .into_par_iter()
            .map(|k| scene(kind, seconds, k).unwrap_or_else(|e| fail(e)))
            .collect()
    };
    let t = Instant::now();
    let mut scenes = build();
    let built = t.elapsed().as_secs_f64();
    // ANIMATS_GPU_SORT=1: the scenes in order of size (animats_gpu::order)
    // for the engine and the GPU alike, so that the bits still compare.
    let sorted = animats_gpu::order::sort_from_env().unwrap_or_else(|e| fail(e));
    if sorted {
        scenes.sort_by_key(animats_gpu::order::size);
    }
    let refs: Vec<&Scene> = scenes.iter().collect();
    let t = Instant::now();
    let packed = Batch::pack_scenes(&refs).unwrap_or_else(|e| fail(e));
    let pack = t.elapsed().as_secs_f64();
    let specialise = animats_gpu::cuda::specialise_from_env().unwrap_or_else(|e| fail(e));
    println!(
        "GPU kernel options: {} (bench/nvrtc.py OPTIONS compiles it)",
        animats_gpu::cuda::kernel_options(&packed, specialise).join(" ")
    );
    // `ANIMATS_PREPARE_ONLY=1`: the batch's kernels (strict, and fast
    // unless ANIMATS_SKIP_FAST) compiled into the disk's cache and loaded,
    // nothing run or timed: bench/gpu.sh compiles its runs' kernels side by
    // side so.
    if std::env::var_os("ANIMATS_PREPARE_ONLY").is_some_and(|v| !v.is_empty()) {
        let skip_fast = std::env::var_os("ANIMATS_SKIP_FAST").is_some_and(|v| !v.is_empty());
        let modes: &[Mode] = if skip_fast {
            &[Mode::Strict]
        } else {
            &[Mode::Strict, Mode::Fast]
        };
        for &mode in modes {
            if let Err(e) = Device::open_in(mode).and_then(|d| d.prepare(&packed)) {
                eprintln!("gpu_evaluate: {e}");
                std::process::exit(2);
            }
        }
        println!("kernels ready ({modes:?})");
        return;
    }
    let sizes: Vec<usize> = scenes.iter().map(|s| s.world.len()).collect();
    let particles: usize = sizes.iter().sum();
    let dt = scenes[0].dt;
    println!(
        "{count} {kind} evaluations of {seconds} s ({particles} particles, steps of {dt} s), {} CPU threads; scenes built in {built:.2} s, packed in {pack:.2} s{}",
        rayon::current_num_threads(),
        if sorted { "; in order of size (ANIMATS_GPU_SORT)" } else { "" }
    );

    let t = Instant::now();
    let engine: Vec<Evaluation> = scenes
        .into_par_iter()
        .map(|s| evaluate(s).unwrap_or_else(|e| fail(e)))
        .collect();
    let on_engine = t.elapsed().as_secs_f64();
    let steps: f64 = engine.iter().map(|e| (e.time / dt).round()).sum();
    let report = |what: &str, secs: f64| {
        println!(
            "{what:<28} {secs:8.3} s  {:10.1} evaluations/s  {:.3e} creature-steps/s",
            count as f64 / secs,
            steps / secs
        )
    };
    report("engine, every core:", on_engine);
    // A warp's 32 threads step until its longest evaluation ends: the share
    // of their steps that evaluate something (creatures in batch order).
    let lengths: Vec<usize> = engine
        .iter()
        .map(|e| (e.time / dt).round() as usize)
        .collect();
    let busy = animats_gpu::order::warp_busy(&lengths);
    println!(
        "warps of 32 busy {:.1} % of their steps (evaluations end at different times); {:.1} % of their lanes in loops over particles (sizes differ)",
        100.0 * busy,
        100.0 * animats_gpu::order::warp_busy(&sizes)
    );

    // `ANIMATS_SKIP_C=1` leaves the C on the CPU out (CI proves it the
    // engine's bits; bench/gpu.sh saves the device's time so).
    let skip_c = std::env::var_os("ANIMATS_SKIP_C").is_some_and(|v| !v.is_empty());
    let c_cpu = (!skip_c).then(|| {
        let mut cpu = packed.clone();
        let t = Instant::now();
        let c_cpu = cpu.evaluate_cpu().unwrap_or_else(|e| fail(e));
        report("C, every core:", t.elapsed().as_secs_f64());
        c_cpu
    });
    // The C in fast mode on the CPU, where asked (it costs a whole CPU
    // run more: bench/gpu.sh does not ask).
    if std::env::var_os("ANIMATS_CPU_FAST").is_some() && animats_gpu::cpu_has_fma() {
        let mut fast = packed.clone();
        let t = Instant::now();
        fast.evaluate_cpu_with(Mode::Fast)
            .unwrap_or_else(|e| fail(e));
        report("C in fast mode, every core:", t.elapsed().as_secs_f64());
    }
    let bits = |e: &Evaluation| {
        (
            [e.fitness, e.distance, e.time].map(f64::to_bits),
            e.measures.iter().map(|m| m.to_bits()).collect::<Vec<u64>>(),
            e.ended.clone(),
        )
    };
    let differ = |got: &[Evaluation]| {
        got.iter()
            .zip(&engine)
            .filter(|(a, b)| bits(a) != bits(b))
            .count()
    };
    let bad = c_cpu.as_deref().map_or(0, |c_cpu| {
        let bad = differ(c_cpu);
        println!("C on the CPU against the engine: {bad} of {count} evaluations differ");
        bad
    });
    let best = engine
        .iter()
        .map(|e| e.fitness)
        .fold(f64::NEG_INFINITY, f64::max);
    println!("best fitness {best}; the first: {:?}", engine[0]);

    let mut device = match Device::open() {
        Ok(d) => d,
        Err(e) => {
            eprintln!("gpu_evaluate: {e}");
            std::process::exit(if bad == 0 { 2 } else { 1 });
        }
    };
    println!(
        "GPU tuning: {:?}; {} threads a block for this batch",
        device.tuning(),
        device.threads_a_block(count as usize)
    );
    // The batch's kernel compiled, loaded and launched once before any
    // clock starts (the first launch pays for the loading).
    device.prepare(&packed).unwrap_or_else(|e| fail(e));
    println!(
        "GPU kernel: {}",
        device.kernel_report(&packed).unwrap_or_else(|e| fail(e))
    );
    // Each creature's state in the thread's local memory (the default),
    // then in the batch's arrays; one thread per evaluation (the default),
    // then threads taking evaluations from a queue.
    let mut bad_gpu = 0;
    for (layout, schedule) in [
        (Layout::Local, Schedule::Static),
        (Layout::Batch, Schedule::Static),
        (Layout::Local, Schedule::Queue),
    ] {
        let mut gpu = packed.clone();
        gpu.set_layout(layout);
        device.set_schedule(schedule);
        let t = Instant::now();
        let on_gpu = device.evaluate(&mut gpu).unwrap_or_else(|e| fail(e));
        let secs = t.elapsed().as_secs_f64();
        let how = format!("{layout:?}, {schedule:?}");
        report(
            &format!("GPU ({}), {how}, copies included:", device.name()),
            secs,
        );
        println!(
            "GPU, {how}: {:.1}x the engine on every core",
            on_engine / secs
        );
        let differ = differ(&on_gpu);
        println!("GPU, {how}, against the engine: {differ} of {count} evaluations differ");
        bad_gpu += differ;
    }
    // Fast mode (fused multiply-adds): its own kernel; not the engine's
    // bits, so its fitnesses' drift and the population's ranking.
    // (`ANIMATS_SKIP_FAST=1` leaves it out: bench/gpu.sh's sweep of the
    // tuning knobs.)
    let fast = if std::env::var_os("ANIMATS_SKIP_FAST").is_some_and(|v| !v.is_empty()) {
        Err("left out (ANIMATS_SKIP_FAST)".to_string())
    } else {
        Device::open_in(Mode::Fast)
    };
    match fast {
        Ok(fast) => {
            fast.prepare(&packed).unwrap_or_else(|e| fail(e));
            let mut gpu = packed.clone();
            let t = Instant::now();
            let on_gpu = fast.evaluate(&mut gpu).unwrap_or_else(|e| fail(e));
            let secs = t.elapsed().as_secs_f64();
            report("GPU, fast mode (FMA), copies included:", secs);
            println!(
                "GPU, fast mode: {:.1}x the engine on every core",
                on_engine / secs
            );
            let rel: Vec<f64> = on_gpu
                .iter()
                .zip(&engine)
                .map(|(a, b)| {
                    (a.fitness - b.fitness).abs() / a.fitness.abs().max(b.fitness.abs()).max(1e-300)
                })
                .collect();
            let mut sorted = rel.clone();
            sorted.sort_by(f64::total_cmp);
            let f = |v: &[Evaluation]| v.iter().map(|e| e.fitness).collect::<Vec<f64>>();
            println!(
                "GPU, fast mode, against the engine: {} of {count} differ; relative fitness difference median {:.2e}, max {:.2e}; rank correlation {:.4}",
                differ(&on_gpu),
                sorted[sorted.len() / 2],
                sorted.last().copied().unwrap_or(0.0),
                animats_gpu::rank_correlation(&f(&on_gpu), &f(&engine))
            );
        }
        Err(e) => println!("GPU, fast mode: {e}"),
    }
    if bad > 0 || bad_gpu > 0 {
        std::process::exit(1);
    }
}
