//! `World::recommended_dt`: the largest step an explicit integrator can take
//! with a world's springs. For two equal masses on one spring the bound is
//! exact (the relative motion's ω² = 2k/m is what the bound gives), so the
//! oscillation must stay bounded just below it and grow just above it; for
//! unequal masses it is conservative.

use animats_engine::{DVec3, IntegratorKind, ParticleDef, SpringDef, World};

/// Two masses on one undamped spring, stretched 10 % from rest, no gravity.
fn pair(m1: f64, m2: f64, k: f64) -> World {
    let mut w = World::new();
    let a = w.add_particle(ParticleDef::new(m1)).unwrap();
    let b = w
        .add_particle(ParticleDef::new(m2).at(DVec3::new(1.1, 0.0, 0.0)))
        .unwrap();
    w.add_spring(SpringDef::new(a, b, k, 0.0).with_rest_length(1.0))
        .unwrap();
    w
}

/// The largest |extension| over `steps` steps of `h`, or infinity if the
/// world blew up.
fn largest_extension(mut w: World, kind: IntegratorKind, h: f64, steps: usize) -> f64 {
    w.set_integrator(kind);
    let mut most: f64 = 0.0;
    for _ in 0..steps {
        if w.step(h).is_err() {
            return f64::INFINITY;
        }
        let s = w.state();
        most = most.max(((s.pos[1] - s.pos[0]).length() - 1.0).abs());
    }
    most
}

#[test]
fn two_equal_masses_are_stable_just_below_the_bound_and_grow_just_above() {
    let (m, k) = (0.5, 200.0);
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        let limit = pair(m, m, k).step_limit(kind).unwrap();
        let omega = (2.0 * k / m).sqrt();
        assert!((limit.omega - omega).abs() < 1e-12 * omega, "{kind}: ω");
        assert_eq!(limit.dt, kind.stable_omega_h() / omega);
        let below = largest_extension(pair(m, m, k), kind, 0.98 * limit.dt, 20_000);
        let above = largest_extension(pair(m, m, k), kind, 1.02 * limit.dt, 20_000);
        // The start is 0.1 m. Just below the bound symplectic Euler's orbit
        // is a stretched ellipse (at most 1/√(1 − (ωh/2)²) = 5.03 times the
        // start) and RK4's decays (|R(iωh)| < 1); just above, RK4 grows by
        // 15 % a step until the ends pass through each other (the spring
        // then turns round and the motion stops being linear), symplectic
        // Euler without bound.
        let (most_below, least_above) = match kind {
            IntegratorKind::Rk4 => (0.1, 1.0),
            _ => (0.1 * 5.1, 1e3),
        };
        assert!(below <= most_below, "{kind} at 0.98 of the bound: {below}");
        assert!(above > least_above, "{kind} at 1.02 of the bound: {above}");
    }
}

#[test]
fn unequal_masses_get_a_conservative_step() {
    // ω² = k (1/m₁ + 1/m₂) = 11 k, the bound says 20 k: √(20/11) = 1.35
    // times the true limit's ω, so the recommended step is stable.
    let (k, kind) = (50.0, IntegratorKind::Symplectic);
    let w = pair(1.0, 0.1, k);
    let limit = w.step_limit(kind).unwrap();
    let true_dt = 2.0 / (11.0 * k).sqrt();
    assert!(limit.dt < true_dt && limit.dt > 0.7 * true_dt);
    assert_eq!(limit.particle.index(), 1, "the light end");
    let most = largest_extension(w, kind, limit.dt, 20_000);
    assert!(most < 0.2, "stable at the recommended step: {most}");
}

#[test]
fn the_limit_names_the_particle_and_its_stiffest_spring() {
    // A chain nailed at one end: the soft links are 10 N/m, one link 1000 N/m.
    let mut w = World::new();
    let ids: Vec<_> = (0..5)
        .map(|i| {
            let mut p = ParticleDef::new(0.2).at(DVec3::new(i as f64 * 0.1, 1.0, 0.0));
            p.fixed = i == 0;
            w.add_particle(p).unwrap()
        })
        .collect();
    for (i, k) in [10.0, 10.0, 1000.0, 10.0].into_iter().enumerate() {
        w.add_spring(SpringDef::new(ids[i], ids[i + 1], k, 0.1))
            .unwrap();
    }
    let limit = w.step_limit(IntegratorKind::Rk4).unwrap();
    assert_eq!(limit.spring.index(), 2);
    assert!([2, 3].contains(&limit.particle.index()));
    let omega = (2.0 * 1010.0 / 0.2f64).sqrt();
    assert!((limit.omega - omega).abs() < 1e-12 * omega);
    assert_eq!(
        w.recommended_dt(IntegratorKind::Rk4),
        Some(2.0 * std::f64::consts::SQRT_2 / omega)
    );
}

#[test]
fn without_springs_between_moving_particles_there_is_no_limit() {
    let mut w = World::new();
    let a = w.add_particle(ParticleDef::new(1.0).fixed()).unwrap();
    let b = w
        .add_particle(ParticleDef::new(1.0).at(DVec3::X).fixed())
        .unwrap();
    assert_eq!(w.recommended_dt(IntegratorKind::Symplectic), None);
    w.add_spring(SpringDef::new(a, b, 100.0, 0.0)).unwrap();
    assert_eq!(
        w.recommended_dt(IntegratorKind::Symplectic),
        None,
        "two nails"
    );
}
