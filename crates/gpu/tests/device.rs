//! The GPU against the C on the CPU, bit for bit (300 random bodies of
//! mixed sizes dropped onto the floor, for 1 s), where a GPU is found;
//! elsewhere (CI has none) the test says what is missing and passes.

use animats_engine::{FluidMedium, IntegratorKind, World};
use animats_gpu::{Batch, Device};

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
        let mut gpu = cpu.clone();
        cpu.run_cpu(1000);
        device.run(&mut gpu, 1000).unwrap();
        for (c, w) in worlds.iter().enumerate() {
            for i in 0..w.len() {
                let (a, b) = (cpu.state(c, i).unwrap(), gpu.state(c, i).unwrap());
                let bits = |v: animats_engine::DVec3| v.to_array().map(f64::to_bits);
                assert!(
                    bits(a.0) == bits(b.0) && bits(a.1) == bits(b.1),
                    "{} ({kind:?}): creature {c}, particle {i}: CPU {a:?}, GPU {b:?}",
                    device.name()
                );
            }
        }
    }
}
