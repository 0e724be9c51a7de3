//! Small worlds (under 16 particles) step particle by particle, larger ones
//! by flat loops over coordinates (docs/DESIGN.md, "Small worlds step
//! particle by particle"): both must give the same bits. A chain of 12
//! springs under gravity and drag is stepped alone, and again beside 40
//! free particles that touch nothing (which put it on the other path); its
//! trajectory must be identical, for every explicit integrator, and a blow-up must
//! be caught and named on both paths.

use animats_engine::{DVec3, IntegratorKind, ParticleDef, SimError, SpringDef, World};

fn chain(extra: usize, stiffness: f64) -> World {
    let mut w = World::new();
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let mut last = w
        .add_particle(ParticleDef::new(1.0).at(DVec3::new(0.0, 2.0, 0.0)).fixed())
        .unwrap();
    for k in 1..13 {
        let x = DVec3::new(0.1 * k as f64, 2.0 + 0.01 * (k % 3) as f64, 0.02 * k as f64);
        let p = w
            .add_particle(ParticleDef::new(0.1 + 0.01 * k as f64).at(x))
            .unwrap();
        w.add_spring(SpringDef::new(last, p, stiffness, 0.3))
            .unwrap();
        last = p;
    }
    for k in 0..extra {
        let x = DVec3::new(-5.0 - k as f64, 10.0, 3.0);
        w.add_particle(ParticleDef::new(1.0).at(x).with_velocity(DVec3::X))
            .unwrap();
    }
    w
}

#[test]
fn a_small_world_steps_the_same_bits_as_inside_a_large_one() {
    // The explicit integrators: the implicit one's conjugate gradients sum
    // over every particle, so the free ones change its iterations.
    for kind in IntegratorKind::ALL.into_iter().filter(|k| k.is_explicit()) {
        let (mut small, mut large) = (chain(0, 200.0), chain(40, 200.0));
        small.set_integrator(kind);
        large.set_integrator(kind);
        for step in 0..2000 {
            small.step(1e-3).unwrap();
            large.step(1e-3).unwrap();
            let n = small.len();
            assert_eq!(
                small.state().pos[..n],
                large.state().pos[..n],
                "{kind}, step {step}"
            );
            assert_eq!(small.state().vel[..n], large.state().vel[..n], "{kind}");
        }
    }
}

#[test]
fn a_blow_up_is_named_on_both_paths() {
    // Far too stiff for the step: the chain's explicit steps blow up.
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        let mut names = Vec::new();
        for extra in [0, 40] {
            let mut w = chain(extra, 1e12);
            w.set_integrator(kind);
            let error = (0..10_000).find_map(|_| w.step(1e-2).err());
            match error {
                Some(SimError::NonFinite { particle, .. }) => {
                    assert!(particle.index() < 13, "{kind}: blamed {particle:?}");
                    // The world stays at its last finite state.
                    assert!(w.state().pos.iter().all(|x| x.is_finite()));
                    names.push(particle);
                }
                other => panic!("{kind} with {extra} more: {other:?}"),
            }
        }
        assert_eq!(names[0], names[1], "{kind}");
    }
}
