//! Random bodies of springs, angle joints and torque joints: what the
//! parity tests step on both sides, and what the GPU benchmark
//! (`examples/gpu_check.rs`) evaluates by the thousand.

use animats_creatures::random::Random;
use animats_engine::{
    AngleJointDef, DVec3, IntegratorKind, ModelError, ParticleDef, SpringDef, TorqueJointDef, World,
};

/// Each coordinate uniform in [-scale/2, scale/2).
pub fn random_vec(rng: &mut Random, scale: f64) -> DVec3 {
    DVec3::new(
        rng.uniform() - 0.5,
        rng.uniform() - 0.5,
        rng.uniform() - 0.5,
    ) * scale
}

/// A random body of `n` particles: a ring of springs through them all,
/// then as many again between random pairs, each of its own stiffness,
/// damping and rest length; with `joints`, an angle joint (at rest at its
/// first angle) and a torque joint (a random axis and torque) for every
/// third particle; random masses, radii, positions and velocities.
pub fn random_body(
    rng: &mut Random,
    n: usize,
    gravity: bool,
    joints: bool,
    kind: IntegratorKind,
) -> Result<World, ModelError> {
    let mut w = World::new();
    if gravity {
        w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    }
    w.set_integrator(kind);
    let ids: Vec<_> = (0..n)
        .map(|_| {
            let def = ParticleDef::new(rng.between(0.1, 3.0))
                .with_radius(rng.between(0.02, 0.2))
                .at(random_vec(rng, 2.0))
                .with_velocity(random_vec(rng, 1.0));
            w.add_particle(def)
        })
        .collect::<Result<_, _>>()?;
    for i in 0..2 * n {
        let (a, b) = if i < n {
            (i, (i + 1) % n)
        } else {
            let a = (rng.uniform() * n as f64) as usize;
            (a, (a + 1 + (rng.uniform() * (n - 1) as f64) as usize) % n)
        };
        if a == b {
            continue;
        }
        let def = SpringDef::new(
            ids[a],
            ids[b],
            rng.between(10.0, 400.0),
            rng.between(0.0, 2.0),
        )
        .with_rest_length(rng.between(0.2, 1.5));
        w.add_spring(def)?;
    }
    if joints && n >= 3 {
        for j in (0..n).step_by(3) {
            let (a, b) = ((j + 1) % n, (j + 2) % n);
            let def = AngleJointDef::new(
                ids[a],
                ids[j],
                ids[b],
                rng.between(0.5, 20.0),
                rng.between(0.0, 0.5),
            );
            w.add_angle_joint(def)?;
            let motor = TorqueJointDef {
                end: ids[a],
                joint: ids[j],
                axis: random_vec(rng, 1.0) + DVec3::Y,
                torque: rng.between(-3.0, 3.0),
            };
            w.add_torque_joint(motor)?;
        }
    }
    Ok(w)
}
