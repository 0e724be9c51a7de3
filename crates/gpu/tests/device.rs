//! The GPU against the C on the CPU, bit for bit (300 random bodies of
//! mixed sizes dropped onto the floor, for 1 s), where a GPU is found;
//! elsewhere (CI has none) the test says what is missing and passes.

use animats_engine::{FluidMedium, IntegratorKind, World};
use animats_gpu::{Batch, Device, Layout, Schedule};

use animats_creatures::random::Random;
use animats_gpu::bodies::random_body;

#[test]
fn the_gpu_steps_every_creature_as_the_cpu_does_or_says_what_is_missing() {
    let device = match Device::open() {
        Ok(d) => d,
        Err(why) => {
            eprintln!("skipped, no GPU to test: {why}");
            assert!(
                why.contains("driver") || why.contains("device") || why.contains("NVRTC"),
                "{why}"
            );
            return;
        }
    };
    let mut rng = Random::for_entry(7, 0);
    for kind in [IntegratorKind::Rk4, IntegratorKind::Symplectic] {
        let worlds: Vec<World> = (0..300)
            .map(|k| {
                let n = 2 + (rng.uniform() * 39.0) as usize;
                let mut w = random_body(&mut rng, n, true, k % 2 == 0, kind).unwrap();
                if k % 3 == 0 {
                    w.add_fluid(FluidMedium::air()).unwrap();
                }
                for p in w.particle_ids().collect::<Vec<_>>() {
                    let x = w.position(p) + animats_engine::DVec3::new(0.0, 1.2, 0.0);
                    w.set_position(p, x).unwrap();
                }
                w.add_floor(animats_engine::FloorDef::default()).unwrap();
                w
            })
            .collect();
        let refs: Vec<&World> = worlds.iter().collect();
        let mut cpu = Batch::pack(&refs, 1e-3).unwrap();
        let packed = cpu.clone();
        cpu.run_cpu(1000);
        for layout in [Layout::Local, Layout::Batch] {
            let mut gpu = packed.clone();
            gpu.set_layout(layout);
            device.run(&mut gpu, 1000).unwrap();
            for (c, w) in worlds.iter().enumerate() {
                for i in 0..w.len() {
                    let (a, b) = (cpu.state(c, i).unwrap(), gpu.state(c, i).unwrap());
                    let bits = |v: animats_engine::DVec3| v.to_array().map(f64::to_bits);
                    assert!(
                        bits(a.0) == bits(b.0) && bits(a.1) == bits(b.1),
                        "{} ({kind:?}, {layout:?}): creature {c}, particle {i}: CPU {a:?}, GPU {b:?}",
                        device.name()
                    );
                }
            }
        }
    }
}

/// Whole evaluations (the soft walker under 200 random oscillator genomes,
/// 2 s each): the GPU's against the C's on the CPU, bit for bit.
#[test]
fn the_gpu_evaluates_every_scene_as_the_cpu_does_or_says_what_is_missing() {
    let device = match Device::open() {
        Ok(d) => d,
        Err(why) => {
            eprintln!("skipped, no GPU to test: {why}");
            return;
        }
    };
    let text =
        include_str!("../../../scenes/walker.toml").replace("duration = 10.0", "duration = 2.0");
    let problem = animats_scene::evaluate::SceneProblem::parse(&text, "walker.toml").unwrap();
    let mut rng = Random::for_entry(3, 0);
    let scenes: Vec<animats_scene::Scene> = (0..200)
        .map(|_| {
            let g: Vec<f64> = problem
                .bounds()
                .iter()
                .map(|&(lo, hi)| rng.between(lo, hi))
                .collect();
            problem.scene(&g).unwrap()
        })
        .collect();
    let refs: Vec<&animats_scene::Scene> = scenes.iter().collect();
    let mut cpu = Batch::pack_scenes(&refs).unwrap();
    let want = cpu.evaluate_cpu().unwrap();
    // Every layout of the state and every schedule of the threads.
    let mut device = device;
    for layout in [Layout::Local, Layout::Batch] {
        for schedule in [Schedule::Static, Schedule::Queue] {
            let mut gpu = Batch::pack_scenes(&refs).unwrap();
            gpu.set_layout(layout);
            device.set_schedule(schedule);
            let got = device.evaluate(&mut gpu).unwrap();
            for (c, (a, b)) in want.iter().zip(&got).enumerate() {
                let bits = |e: &animats_scene::evaluate::Evaluation| {
                    [e.fitness, e.distance, e.time].map(f64::to_bits)
                };
                assert!(
                    bits(a) == bits(b) && a.ended == b.ended,
                    "{}, {layout:?}, {schedule:?}: walker {c}: CPU {a:?}, GPU {b:?}",
                    device.name()
                );
            }
        }
    }
}
