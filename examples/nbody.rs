//! The thesis's tutorial (§4.1.2): a new force written outside the engine.
//!
//! `NBodyGravity` below is everything a user writes to add mutual gravitation:
//! a struct holding its bodies, and `Force::apply` adding Newton's attraction
//! between every pair to the force accumulators. The world then integrates it
//! like any built-in force. We run a small planetary system and print how far
//! its total energy drifts.
//!
//! Run with `cargo run --release --example nbody`.

use animats_engine::{Force, ForceContext, IntegratorKind, ParticleDef, ParticleId, World};
use glam::DVec3;

/// Mutual gravitation among a list of bodies.
struct NBodyGravity {
    /// Gravitational constant.
    g: f64,
    bodies: Vec<ParticleId>,
}

impl Force for NBodyGravity {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        for (k, &a) in self.bodies.iter().enumerate() {
            for &b in &self.bodies[k + 1..] {
                let (i, j) = (a.index(), b.index());
                let d = ctx.pos[j] - ctx.pos[i];
                let r2 = d.length_squared();
                // Newton: F = G mᵢ mⱼ / r², along d, equal and opposite.
                let f =
                    d * (self.g * ctx.particles.mass[i] * ctx.particles.mass[j] / (r2 * r2.sqrt()));
                forces[i] += f;
                forces[j] -= f;
            }
        }
    }

    fn potential_energy(&self, ctx: &ForceContext) -> f64 {
        let mut e = 0.0;
        for (k, &a) in self.bodies.iter().enumerate() {
            for &b in &self.bodies[k + 1..] {
                let r = (ctx.pos[b.index()] - ctx.pos[a.index()]).length();
                e -= self.g * ctx.particles.mass[a.index()] * ctx.particles.mass[b.index()] / r;
            }
        }
        e
    }

    fn is_conservative(&self) -> bool {
        true
    }

    fn name(&self) -> &str {
        "tutorial n-body gravity"
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Units: G = 1, a sun of mass 1 and three light planets on circular orbits
    // (v = sqrt(G M / r)), so one orbit at r = 1 takes 2π time units.
    let mut world = World::new();
    let sun = world.add_particle(ParticleDef::new(1.0))?;
    let mut bodies = vec![sun];
    for (r, m) in [(1.0, 1e-3), (1.6, 2e-4), (2.5, 5e-4)] {
        let v = (1.0f64 / r).sqrt();
        let planet = ParticleDef::new(m)
            .at(DVec3::new(r, 0.0, 0.0))
            .with_velocity(DVec3::new(0.0, 0.0, v));
        bodies.push(world.add_particle(planet)?);
    }
    world.add_force(Box::new(NBodyGravity { g: 1.0, bodies }));

    for kind in [
        IntegratorKind::Rk4,
        IntegratorKind::Symplectic,
        IntegratorKind::Euler,
    ] {
        let mut w = World::new();
        // Rebuild the same system for each integrator.
        for id in world.particle_ids() {
            let p = world.particles();
            let def = ParticleDef::new(p.mass[id.index()])
                .at(world.position(id))
                .with_velocity(world.velocity(id));
            w.add_particle(def)?;
        }
        w.add_force(Box::new(NBodyGravity {
            g: 1.0,
            bodies: w.particle_ids().collect(),
        }));
        w.set_integrator(kind);
        let e0 = w.energy().total();
        let (dt, orbits) = (1e-3, 10.0);
        let steps = (orbits * std::f64::consts::TAU / dt).round() as usize;
        for _ in 0..steps {
            w.step(dt)?;
        }
        let e1 = w.energy().total();
        println!(
            "{:<10} {steps} steps of {dt}: E0 = {e0:.12}, E = {e1:.12}, relative drift {:+.3e}",
            kind.name(),
            (e1 - e0) / e0.abs()
        );
    }
    Ok(())
}
