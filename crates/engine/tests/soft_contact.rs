//! Penalty contact between spheres ([`SoftContact`]) against the physics of
//! a linear spring contact:
//!
//! - Without damping a head-on collision is elastic: two equal spheres
//!   exchange their velocities, momentum is kept to rounding (the forces
//!   are equal and opposite) and kinetic energy to the integrator's O(h)
//!   error; the contact lasts half a period of the pair's spring,
//!   `π √(μ / k)`, `μ` the reduced mass.
//! - With damping it loses energy and never pulls (the spheres part with
//!   a smaller, still separating, velocity).
//! - It does no work around a closed cycle: a muscle that presses two
//!   spheres together and lets them go, for many cycles, leaves the
//!   system's energy bounded (a whole evolved body that the sphere-contact
//!   event pumped to 28 m/s is `crates/scene/tests/pumping_body.toml`).
//! - Excluded pairs never touch.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_engine::{IntegratorKind, ParticleDef, SoftContact, World};
use glam::DVec3;

fn two(k: f64, c: f64, v: f64) -> (World, [animats_engine::ParticleId; 2]) {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    let a = w
        .add_particle(
            ParticleDef::new(0.1)
                .with_radius(0.05)
                .at(DVec3::new(-0.1, 0.0, 0.0))
                .with_velocity(DVec3::X * v),
        )
        .unwrap();
    let b = w
        .add_particle(
            ParticleDef::new(0.1)
                .with_radius(0.05)
                .at(DVec3::new(0.1, 0.0, 0.0))
                .with_velocity(-DVec3::X * v),
        )
        .unwrap();
    w.add_force(Box::new(SoftContact::new(k, c, &[a, b], &[]).unwrap()));
    (w, [a, b])
}

#[test]
fn without_damping_equal_spheres_exchange_velocities_elastically() {
    let (k, h) = (5000.0, 1e-5);
    let (mut w, [a, b]) = two(k, 0.0, 1.0);
    let mut touching = 0usize;
    for _ in 0..30_000 {
        w.step(h).unwrap();
        if (w.position(b) - w.position(a)).length() < 0.1 {
            touching += 1;
        }
        let p = w.velocity(a) * 0.1 + w.velocity(b) * 0.1;
        assert!(p.length() < 1e-15, "momentum {p}");
    }
    let (va, vb) = (w.velocity(a).x, w.velocity(b).x);
    // Symplectic Euler through a contact of ~1000 steps: O(h) error.
    assert!(
        (va + 1.0).abs() < 2e-3 && (vb - 1.0).abs() < 2e-3,
        "{va} {vb}"
    );
    let duration = touching as f64 * h;
    let expected = std::f64::consts::PI * (0.05f64 / k).sqrt();
    assert!(
        (duration - expected).abs() < 0.01 * expected,
        "contact lasted {duration} s, π√(μ/k) = {expected} s"
    );
}

#[test]
fn damping_takes_energy_and_never_pulls() {
    let (mut w, [a, b]) = two(5000.0, 2.0, 1.0);
    let mut least_gap_rate = f64::INFINITY;
    for _ in 0..30_000 {
        w.step(1e-5).unwrap();
        least_gap_rate = least_gap_rate.min(w.velocity(b).x - w.velocity(a).x);
    }
    let (va, vb) = (w.velocity(a).x, w.velocity(b).x);
    assert!(va < 0.0 && vb > 0.0, "they part: {va} {vb}");
    assert!(vb < 0.95, "energy was lost: {vb}");
    assert!((va + vb).abs() < 1e-12);
    assert!(least_gap_rate >= -2.0 - 1e-12);
}

#[test]
fn pressing_and_releasing_for_many_cycles_pumps_no_energy() {
    // Two spheres, held against each other by a force that switches on
    // and off (a muscle pressing them together), no gravity, no damping:
    // whatever the pushes put in they take out, so after whole cycles at
    // rest the spheres are as slow as they started.
    #[derive(Clone)]
    struct Press(animats_engine::ParticleId, animats_engine::ParticleId);
    impl animats_engine::Force for Press {
        fn apply(&mut self, ctx: &animats_engine::ForceContext, f: &mut [DVec3]) {
            let on = (ctx.t * 5.0).fract() < 0.5;
            if on {
                f[self.0.index()] += DVec3::X * 2.0;
                f[self.1.index()] -= DVec3::X * 2.0;
            }
        }
    }
    let (mut w, [a, b]) = two(5000.0, 0.0, 0.0);
    w.set_position(b, DVec3::new(0.0999, 0.0, 0.0)).unwrap();
    w.set_position(a, DVec3::new(0.0, 0.0, 0.0)).unwrap();
    w.add_force(Box::new(Press(a, b)));
    let mut most = 0.0f64;
    for _ in 0..200_000 {
        w.step(1e-5).unwrap();
        most = most.max(w.velocity(a).length());
    }
    // The push is 2 N: the spheres can never reach more than the speed a
    // 2 N push gives a 0.1 kg sphere over a few centimetres (√(2 F d / m)).
    assert!(
        most < (2.0f64 * 2.0 * 0.1 / 0.1).sqrt(),
        "fastest {most} m/s"
    );
}

#[test]
fn excluded_pairs_pass_through_each_other() {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    let a = w
        .add_particle(
            ParticleDef::new(0.1)
                .with_radius(0.05)
                .with_velocity(DVec3::X),
        )
        .unwrap();
    let b = w
        .add_particle(
            ParticleDef::new(0.1)
                .with_radius(0.05)
                .at(DVec3::new(0.2, 0.0, 0.0)),
        )
        .unwrap();
    let contact = SoftContact::new(5000.0, 0.0, &[a, b], &[(b, a)]).unwrap();
    assert_eq!(contact.pairs(), 0);
    w.add_force(Box::new(contact));
    for _ in 0..1000 {
        w.step(1e-3).unwrap();
    }
    assert_eq!(w.velocity(a), DVec3::X);
    assert!(SoftContact::new(-1.0, 0.0, &[a, b], &[]).is_err());
    assert!(SoftContact::new(1.0, f64::NAN, &[a, b], &[]).is_err());
}

/// How [`cloud`]'s spheres touch.
#[derive(Clone, Copy, PartialEq)]
enum Touch {
    Sweep,
    EveryPair,
    Not,
}

/// A cloud of `n` spheres on a jittered grid (many overlapping), moving
/// towards its centre, every fifth neighbour pair excluded; with the sweep
/// (from [`animats_engine::forces::soft_contact::SWEEP_FROM`] spheres),
/// testing every pair, or without contact. Returns the state's bits after
/// `steps` steps.
fn cloud(n: usize, touch: Touch, steps: usize) -> Vec<u64> {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    // A small linear congruential generator: the same cloud every time.
    let mut seed = 12345u64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let side = (n as f64).cbrt().ceil() as usize;
    let mut ids = Vec::new();
    for k in 0..n {
        let (i, j, l) = (k % side, (k / side) % side, k / (side * side));
        let at = DVec3::new(i as f64, j as f64, l as f64) * 0.06
            + DVec3::new(next(), next(), next()) * 0.02;
        let centre = DVec3::splat(0.03 * side as f64);
        ids.push(
            w.add_particle(
                ParticleDef::new(0.01 + 0.05 * next())
                    .with_radius(0.02 + 0.02 * next())
                    .at(at)
                    .with_velocity((centre - at) * 2.0),
            )
            .unwrap(),
        );
    }
    let excluded: Vec<_> = (0..n - 1)
        .step_by(5)
        .map(|k| (ids[k + 1], ids[k]))
        .collect();
    let contact = SoftContact::new(3000.0, 0.5, &ids, &excluded).unwrap();
    assert!(contact.sweeps(), "{n} spheres sweep");
    match touch {
        Touch::Sweep => {
            w.add_force(Box::new(contact));
        }
        Touch::EveryPair => {
            w.add_force(Box::new(contact.every_pair()));
        }
        Touch::Not => {}
    }
    for _ in 0..steps {
        w.step(1e-4).unwrap();
    }
    let s = w.state();
    s.pos
        .iter()
        .chain(&s.vel)
        .flat_map(|v| v.to_array())
        .map(f64::to_bits)
        .collect()
}

/// The sweep tests only the pairs whose boxes overlap, and in the order
/// every pair would be tested: the same bits as testing every pair, on a
/// cloud of 125 spheres squeezed together and bouncing apart for 2,000
/// steps (contacts made and broken, excluded pairs passing through).
#[test]
fn the_sweep_gives_the_bits_of_every_pair() {
    let swept = cloud(125, Touch::Sweep, 2000);
    let every = cloud(125, Touch::EveryPair, 2000);
    assert_eq!(swept, every);
    // And the spheres did touch: without contact every one ends elsewhere.
    let apart = cloud(125, Touch::Not, 2000);
    let moved = (0..125 * 3).filter(|&k| swept[k] != apart[k]).count();
    assert!(moved > 300, "{moved} of 375 coordinates differ");
}
