//! The thesis's tutorial (§4.1.2): the n-body gravitational simulator, with
//! its force written outside the engine (`gravity.rs`, a few dozen lines).
//!
//! A sun and three planets on circular orbits, integrated for ten orbits of
//! the inner planet with each integrator; we print how far the total energy
//! drifts. Run with `cargo run --release --example nbody`.

mod gravity;

use animats_engine::{DVec3, IntegratorKind, ParticleDef, World};
use gravity::NBodyGravity;

/// A sun of mass 1 and three light planets, in units where G = 1, so the
/// planet at r = 1 goes round once every 2π.
fn solar_system(kind: IntegratorKind) -> Result<World, Box<dyn std::error::Error>> {
    let mut world = World::new();
    world.set_integrator(kind);
    world.add_particle(ParticleDef::new(1.0))?;
    for (r, m) in [(1.0, 1e-3), (1.6, 2e-4), (2.5, 5e-4)] {
        let v: f64 = (1.0f64 / r).sqrt(); // circular orbit: v² = G M / r
        world.add_particle(
            ParticleDef::new(m)
                .at(DVec3::new(r, 0.0, 0.0))
                .with_velocity(DVec3::new(0.0, 0.0, v)),
        )?;
    }
    let bodies: Vec<_> = world.particle_ids().collect();
    world.add_force(Box::new(NBodyGravity::new(1.0, &bodies)));
    Ok(world)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (dt, orbits) = (1e-3, 10.0);
    let steps = (orbits * std::f64::consts::TAU / dt).round() as usize;
    println!("sun + 3 planets, {orbits} orbits, {steps} steps of {dt}");
    for kind in [
        IntegratorKind::Rk4,
        IntegratorKind::Midpoint,
        IntegratorKind::Symplectic,
        IntegratorKind::Euler,
    ] {
        let mut world = solar_system(kind)?;
        let e0 = world.energy().total();
        for _ in 0..steps {
            world.step(dt)?;
        }
        let e1 = world.energy().total();
        println!(
            "{:<10} E0 = {e0:.12}  E = {e1:.12}  relative drift {:+.3e}",
            kind.name(),
            (e1 - e0) / e0.abs()
        );
    }
    Ok(())
}
