//! Forces against physics: orbits, conservation laws, fluids, nails.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_engine::{
    AngleJointDef, Current, FluidMedium, Force, ForceContext, IntegratorKind, NBodyGravity,
    ParticleDef, ParticleId, SpringDef, Targets, TorqueJointDef, World,
};
use glam::DVec3;
use std::f64::consts::{PI, TAU};

#[test]
fn two_body_circular_orbit_has_the_right_period_and_radius() {
    // Two bodies at separation r orbit their barycentre with
    // ω² = G (m1 + m2) / r³ (Kepler's third law for a circular orbit).
    let (g, m1, m2, r): (f64, f64, f64, f64) = (1.0, 1.0, 0.25, 1.5);
    let omega = (g * (m1 + m2) / (r * r * r)).sqrt();
    let period = TAU / omega;
    let mut w = World::new();
    // Positions relative to the barycentre, velocities ω × r.
    let (r1, r2) = (r * m2 / (m1 + m2), r * m1 / (m1 + m2));
    let a = w
        .add_particle(
            ParticleDef::new(m1)
                .at(DVec3::new(-r1, 0.0, 0.0))
                .with_velocity(DVec3::new(0.0, 0.0, -omega * r1)),
        )
        .unwrap();
    let b = w
        .add_particle(
            ParticleDef::new(m2)
                .at(DVec3::new(r2, 0.0, 0.0))
                .with_velocity(DVec3::new(0.0, 0.0, omega * r2)),
        )
        .unwrap();
    w.add_nbody(NBodyGravity::new(g, 0.0, Targets::All))
        .unwrap();
    let steps = 4000;
    let h = period / steps as f64;
    let mut worst_radius = 0.0f64;
    let mut quarter = DVec3::ZERO;
    for i in 0..steps {
        w.step(h).unwrap();
        let sep = (w.position(b) - w.position(a)).length();
        worst_radius = worst_radius.max((sep - r).abs() / r);
        if i + 1 == steps / 4 {
            quarter = w.position(b);
        }
    }
    // RK4 at 4000 steps per orbit: errors ~ (ωh)^4 ≈ 2e-12 per step.
    assert!(
        worst_radius < 1e-9,
        "separation drifted by {worst_radius} (relative)"
    );
    // A quarter period turns b through 90°: from +x to +z.
    assert!(
        (quarter - DVec3::new(0.0, 0.0, r2)).length() < 1e-8 * r,
        "quarter orbit at {quarter}"
    );
    // After one period both are back where they started.
    assert!((w.position(b) - DVec3::new(r2, 0.0, 0.0)).length() < 1e-8 * r);
    assert!((w.position(a) - DVec3::new(-r1, 0.0, 0.0)).length() < 1e-8 * r);
}

/// A free-floating chain of five masses with springs, angle joints and driven
/// torque joints, drifting and tumbling.
fn tumbling_chain(kind: IntegratorKind) -> World {
    let mut w = World::new();
    w.set_integrator(kind);
    let mut ids = Vec::new();
    for i in 0..5 {
        let x = DVec3::new(0.3 * i as f64, 0.05 * (i as f64).sin(), 0.02 * i as f64);
        let v = DVec3::new(0.1, -0.2 * i as f64, 0.3 * (i % 2) as f64);
        ids.push(
            w.add_particle(
                ParticleDef::new(0.2 + 0.1 * i as f64)
                    .at(x)
                    .with_velocity(v),
            )
            .unwrap(),
        );
    }
    for i in 0..4 {
        w.add_spring(SpringDef::new(ids[i], ids[i + 1], 40.0, 0.3).with_rest_length(0.25))
            .unwrap();
    }
    for i in 0..3 {
        w.add_angle_joint(
            AngleJointDef::new(ids[i], ids[i + 1], ids[i + 2], 2.0, 0.05).with_rest_angle(2.5),
        )
        .unwrap();
    }
    w.add_torque_joint(TorqueJointDef {
        end: ids[0],
        joint: ids[1],
        axis: DVec3::Z,
        torque: 0.3,
    })
    .unwrap();
    w.add_torque_joint(TorqueJointDef {
        end: ids[4],
        joint: ids[3],
        axis: DVec3::new(1.0, 1.0, 0.0),
        torque: -0.2,
    })
    .unwrap();
    w
}

#[test]
fn internal_forces_conserve_linear_momentum() {
    for kind in IntegratorKind::ALL {
        let mut w = tumbling_chain(kind);
        let p0 = w.momentum();
        let scale: f64 = w
            .particle_ids()
            .map(|p| w.particles().mass[p.index()] * w.velocity(p).length())
            .sum();
        let mut worst = 0.0f64;
        for _ in 0..5000 {
            w.step(1e-3).unwrap();
            worst = worst.max((w.momentum() - p0).length() / scale);
        }
        // Every internal force is applied with its exact reaction, so only
        // rounding (~1e-16 per operation) can change the momentum.
        assert!(
            worst < 1e-9,
            "{kind}: momentum changed by {worst} (relative)"
        );
    }
}

#[test]
fn torque_joint_applies_its_torque_about_the_joint() {
    let mut w = World::new();
    let j = w.add_particle(ParticleDef::new(1.0)).unwrap();
    let e = w
        .add_particle(ParticleDef::new(1.0).at(DVec3::new(0.5, 0.0, 0.3)))
        .unwrap();
    w.add_torque_joint(TorqueJointDef {
        end: e,
        joint: j,
        axis: DVec3::Z,
        torque: 2.0,
    })
    .unwrap();
    // One explicit Euler step from rest: Δv = F h / m, so F = Δv m / h.
    w.set_integrator(IntegratorKind::Euler);
    let h = 1e-6;
    w.step(h).unwrap();
    let f = w.velocity(e) / h;
    let moment = (DVec3::new(0.5, 0.0, 0.3) - DVec3::ZERO).cross(f);
    assert!(
        (moment.z - 2.0).abs() < 1e-9,
        "moment about the axis {moment}"
    );
    assert!(
        (w.velocity(j) + w.velocity(e)).length() < 1e-12,
        "reaction on the joint"
    );
}

#[test]
fn conservative_joints_and_springs_conserve_energy() {
    // Undamped springs and angle joints under gravity: RK4 keeps the total
    // energy to its truncation error, which shrinks as h⁴. The angle joint's
    // forces must be exactly the gradient of ½k(θ-θ₀)² for this to hold.
    let run = |h: f64| {
        let mut w = World::new();
        w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
        let a = w
            .add_particle(ParticleDef::new(0.3).at(DVec3::new(0.0, 1.0, 0.0)))
            .unwrap();
        let j = w
            .add_particle(ParticleDef::new(0.5).at(DVec3::new(0.2, 1.1, 0.0)))
            .unwrap();
        let b = w
            .add_particle(
                ParticleDef::new(0.4)
                    .at(DVec3::new(0.35, 0.9, 0.1))
                    .with_velocity(DVec3::new(0.0, 1.0, -1.0)),
            )
            .unwrap();
        w.add_spring(SpringDef::new(a, j, 50.0, 0.0)).unwrap();
        w.add_spring(SpringDef::new(j, b, 80.0, 0.0).with_rest_length(0.2))
            .unwrap();
        w.add_angle_joint(AngleJointDef::new(a, j, b, 3.0, 0.0).with_rest_angle(PI / 2.0))
            .unwrap();
        assert!(w.is_conservative());
        let e0 = w.energy().total();
        let steps = (1.0 / h).round() as usize;
        let mut worst = 0.0f64;
        for _ in 0..steps {
            w.step(h).unwrap();
            worst = worst.max((w.energy().total() - e0).abs());
        }
        worst
    };
    let (e1, e2) = (run(2e-3), run(1e-3));
    println!("energy error: {e1:e} at h = 2 ms, {e2:e} at h = 1 ms");
    assert!(e2 < 1e-6, "energy error {e2} J");
    // Fourth order: halving h cuts the error by about 16.
    assert!(e1 / e2 > 10.0, "energy error ratio {}", e1 / e2);
}

fn sphere_in_water(density: f64, radius: f64) -> (World, ParticleId) {
    let mut w = World::new();
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let volume = 4.0 / 3.0 * PI * radius.powi(3);
    let p = w
        .add_particle(
            ParticleDef::new(density * volume)
                .with_radius(radius)
                .at(DVec3::new(0.0, 10.0, 0.0)),
        )
        .unwrap();
    w.add_fluid(FluidMedium::water()).unwrap();
    (w, p)
}

#[test]
fn sinking_sphere_reaches_terminal_velocity() {
    // Terminal velocity: weight - buoyancy = drag,
    // (ρs - ρ) V g = ½ C ρ A v²  →  v = sqrt(2 (ρs - ρ) V g / (C ρ A)).
    let (rho_s, radius) = (2500.0, 0.01);
    let (mut w, p) = sphere_in_water(rho_s, radius);
    let v = 4.0 / 3.0 * PI * radius.powi(3);
    let a = PI * radius * radius;
    let terminal = (2.0 * (rho_s - 1000.0) * v * 9.8 / (0.47 * 1000.0 * a)).sqrt();
    for _ in 0..5000 {
        w.step(1e-3).unwrap(); // 5 s: dozens of time constants v_t/g'
    }
    let got = -w.velocity(p).y;
    assert!(
        (got - terminal).abs() / terminal < 0.01,
        "terminal velocity {got}, expected {terminal}"
    );
}

#[test]
fn light_sphere_rises_with_the_right_acceleration_and_neutral_one_stays() {
    // Initial acceleration from rest (no drag yet): a = g (ρ/ρs - 1).
    let (mut w, p) = sphere_in_water(200.0, 0.02);
    let h = 1e-4;
    w.step(h).unwrap();
    let a = w.velocity(p).y / h;
    let expected = 9.8 * (1000.0 / 200.0 - 1.0);
    assert!(
        (a - expected).abs() / expected < 1e-3,
        "initial acceleration {a}, expected {expected}"
    );
    for _ in 0..1000 {
        w.step(1e-3).unwrap();
    }
    assert!(w.position(p).y > 10.0 && w.velocity(p).y > 0.0);

    let (mut w, p) = sphere_in_water(1000.0, 0.02);
    for _ in 0..10_000 {
        w.step(1e-3).unwrap();
    }
    assert!(
        (w.position(p).y - 10.0).abs() < 1e-9,
        "neutral sphere moved to {}",
        w.position(p)
    );
}

#[test]
fn a_neutral_sphere_drifts_with_a_uniform_current() {
    let (mut w, p) = sphere_in_water(1000.0, 0.02);
    w.set_fluid_current(0, Current::Uniform(DVec3::new(0.2, 0.0, 0.0)))
        .unwrap();
    for _ in 0..20_000 {
        w.step(1e-3).unwrap();
    }
    // Quadratic drag relaxes the relative velocity as 1/(1 + t/τ); after 20 s
    // it is within a few per cent of the stream.
    let v = w.velocity(p).x;
    assert!(v > 0.19 && v <= 0.2 + 1e-12, "velocity {v}");
}

#[test]
fn a_nail_holds_a_hanging_bob_at_the_static_extension() {
    // A 0.2 kg bob on a damped spring (k = 50 N/m) from a nail that was
    // given a velocity (ignored): it settles m g / k = 3.92 cm below the
    // spring's rest length, and the nail takes the whole load unmoved.
    let (m, k, g) = (0.2, 50.0, 9.8);
    for kind in IntegratorKind::ALL {
        let mut w = World::new();
        w.set_integrator(kind);
        w.set_gravity(DVec3::new(0.0, -g, 0.0));
        let x = DVec3::new(0.1, 1.0, 0.3);
        let nail = w
            .add_particle(
                ParticleDef::new(1.0)
                    .at(x)
                    .with_velocity(DVec3::ONE)
                    .fixed(),
            )
            .unwrap();
        let bob = w
            .add_particle(ParticleDef::new(m).at(x - DVec3::new(0.0, 0.5, 0.0)))
            .unwrap();
        w.add_spring(SpringDef::new(nail, bob, k, 1.0)).unwrap();
        w.set_velocity(nail, DVec3::X).unwrap(); // ignored: it is nailed
        for _ in 0..20_000 {
            w.step(1e-3).unwrap();
        }
        let drop = x.y - w.position(bob).y;
        assert!(
            (drop - (0.5 + m * g / k)).abs() < 1e-6,
            "{kind}: the bob hangs {drop} m below the nail"
        );
        assert_eq!(w.position(nail), x, "{kind}");
    }
}

/// A user force added from outside the engine is evaluated at every RK4
/// trial state, like a built-in one: a tether pulling with `-k x` gives the
/// harmonic oscillator x = cos(ωt) to RK4 accuracy.
#[test]
fn user_forces_are_evaluated_at_every_trial_state() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Arc;
    #[derive(Clone)]
    struct Tether {
        p: ParticleId,
        k: f64,
        calls: Arc<AtomicUsize>,
    }
    impl Force for Tether {
        fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
            self.calls.fetch_add(1, Ordering::Relaxed);
            forces[self.p.index()] -= self.k * ctx.pos[self.p.index()];
        }
    }
    let calls = Arc::new(AtomicUsize::new(0));
    let mut w = World::new();
    let p = w.add_particle(ParticleDef::new(1.0).at(DVec3::X)).unwrap();
    w.add_force(Box::new(Tether {
        p,
        k: 9.0,
        calls: calls.clone(),
    }));
    for _ in 0..1000 {
        w.step(1e-3).unwrap();
    }
    assert_eq!(
        calls.load(Ordering::Relaxed),
        4000,
        "RK4 evaluates forces four times per step"
    );
    assert!((w.position(p).x - 3.0f64.cos()).abs() < 1e-10);
}

#[test]
fn a_blow_up_is_an_error_and_the_world_keeps_its_last_finite_state() {
    // ωh ≈ 300 under explicit Euler: the oscillation grows ~300× per step.
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Euler);
    let anchor = w.add_particle(ParticleDef::new(1.0).fixed()).unwrap();
    let bob = w
        .add_particle(ParticleDef::new(1e-3).at(DVec3::new(1.1, 0.0, 0.0)))
        .unwrap();
    w.add_spring(SpringDef::new(anchor, bob, 1e6, 0.0).with_rest_length(1.0))
        .unwrap();
    let mut steps = 0;
    let err = loop {
        match w.step(0.01) {
            Ok(_) => steps += 1,
            Err(e) => break e,
        }
        assert!(steps < 1000, "never blew up");
    };
    match err {
        animats_engine::SimError::NonFinite { particle, time } => {
            assert_eq!(particle, bob, "the moving particle is blamed, not the nail");
            assert!((time - 0.01 * (steps + 1) as f64).abs() < 1e-9);
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(w.position(bob).is_finite() && w.velocity(bob).is_finite());
    assert!(
        (w.time() - 0.01 * steps as f64).abs() < 1e-9,
        "the clock did not advance past the last good step"
    );
    assert_eq!(w.step(-1.0), Err(animats_engine::SimError::BadStep(-1.0)));
}

#[test]
fn a_plane_constraint_keeps_a_body_in_a_tilted_plane() {
    use animats_engine::PlaneConstraint;
    // A pendulum swinging in a vertical plane at 37° from the x axis. Its
    // forces lie in the plane only up to rounding; the constraint keeps it in.
    let a = 37f64.to_radians();
    let along = DVec3::new(a.cos(), 0.0, -a.sin());
    let normal = along.cross(DVec3::Y);
    let mut w = World::new();
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let pivot = w
        .add_particle(ParticleDef::new(1.0).at(DVec3::new(0.3, 2.0, 0.7)).fixed())
        .unwrap();
    let bob = w
        .add_particle(
            ParticleDef::new(0.2)
                .at(DVec3::new(0.3, 2.0, 0.7) + along * 0.5)
                .with_velocity(normal * 0.01),
        )
        .unwrap();
    w.add_spring(SpringDef::new(pivot, bob, 500.0, 0.0))
        .unwrap();
    w.add_event(Box::new(PlaneConstraint::new(
        DVec3::new(0.3, 2.0, 0.7),
        normal,
        vec![pivot, bob],
    )));
    let mut lowest = f64::INFINITY;
    for _ in 0..5000 {
        w.step(1e-3).unwrap();
        lowest = lowest.min(w.position(bob).y);
        let off = (w.position(bob) - DVec3::new(0.3, 2.0, 0.7)).dot(normal);
        assert!(off.abs() < 1e-15, "left the plane by {off}");
        assert!(w.velocity(bob).dot(normal).abs() < 1e-15);
    }
    // It did swing, down through the bottom of its arc.
    assert!(lowest < 2.0 - 0.45, "lowest point {lowest}");
}
