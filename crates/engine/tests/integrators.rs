//! Every integrator against closed-form solutions.
//!
//! - Free fall and projectile motion under constant gravity: midpoint and RK4
//!   are exact for constant acceleration (to rounding); explicit and
//!   symplectic (and implicit) Euler have a known, exact discretisation error of ∓ g t h / 2
//!   in position, which we assert to rounding.
//! - The harmonic oscillator, undamped and damped, against x(t) in closed
//!   form; the order of convergence measured from three step sizes.
//! - Symplectic Euler's energy error stays bounded over 1000 periods.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_engine::{IntegratorKind, ParticleDef, SpringDef, World};
use glam::DVec3;
use std::f64::consts::TAU;

const G: DVec3 = DVec3::new(0.0, -9.8, 0.0);

fn projectile(kind: IntegratorKind, x0: DVec3, v0: DVec3, h: f64, steps: usize) -> (DVec3, DVec3) {
    let mut w = World::new();
    w.set_gravity(G);
    w.set_integrator(kind);
    let p = w
        .add_particle(ParticleDef::new(2.0).at(x0).with_velocity(v0))
        .unwrap();
    for _ in 0..steps {
        w.step(h).unwrap();
    }
    (w.position(p), w.velocity(p))
}

#[test]
fn free_fall_and_projectile_match_closed_form_for_every_integrator() {
    let (h, steps) = (0.01, 150);
    let t = h * steps as f64;
    for (x0, v0) in [
        (DVec3::new(0.0, 20.0, 0.0), DVec3::ZERO), // free fall
        (DVec3::new(1.0, 2.0, -1.0), DVec3::new(3.0, 12.0, -2.0)), // projectile
    ] {
        let exact_x = x0 + v0 * t + 0.5 * G * t * t;
        let exact_v = v0 + G * t;
        for kind in IntegratorKind::ALL {
            let (x, v) = projectile(kind, x0, v0, h, steps);
            // Velocity is linear in t: every method gets it exactly.
            assert!(
                (v - exact_v).length() < 1e-10,
                "{kind}: v = {v}, expected {exact_v}"
            );
            // Position: explicit Euler lags by g t h / 2, symplectic Euler leads by it.
            let expected = match kind {
                IntegratorKind::Euler => exact_x - 0.5 * G * t * h,
                IntegratorKind::Symplectic | IntegratorKind::Implicit => exact_x + 0.5 * G * t * h,
                IntegratorKind::Midpoint | IntegratorKind::Rk4 => exact_x,
            };
            assert!(
                (x - expected).length() < 1e-10,
                "{kind}: x = {x}, expected {expected}"
            );
        }
    }
}

/// A mass `m` on a spring of stiffness `k` and damping `c` to a fixed anchor,
/// released from rest `a` beyond the rest length. Returns (x - rest, v) at `t_end`.
fn oscillator(kind: IntegratorKind, k: f64, c: f64, h: f64, t_end: f64) -> (f64, f64) {
    let (m, rest, a) = (0.5, 1.0, 0.1);
    let mut w = World::new();
    w.set_integrator(kind);
    let anchor = w.add_particle(ParticleDef::new(1.0).fixed()).unwrap();
    let bob = w
        .add_particle(ParticleDef::new(m).at(DVec3::new(rest + a, 0.0, 0.0)))
        .unwrap();
    w.add_spring(SpringDef::new(anchor, bob, k, c).with_rest_length(rest))
        .unwrap();
    let steps = (t_end / h).round() as usize;
    for _ in 0..steps {
        w.step(h).unwrap();
    }
    (w.position(bob).x - rest, w.velocity(bob).x)
}

/// Closed form (x, v) of the (under)damped oscillator released from rest at `a`.
fn oscillator_exact(k: f64, c: f64, t: f64) -> (f64, f64) {
    let (m, a) = (0.5, 0.1);
    let w0 = (k / m).sqrt();
    let gamma = c / (2.0 * m);
    let wd = (w0 * w0 - gamma * gamma).sqrt();
    let (s, co) = (wd * t).sin_cos();
    let x = (-gamma * t).exp() * a * (co + gamma / wd * s);
    let v = -(-gamma * t).exp() * a * (w0 * w0 / wd) * s;
    (x, v)
}

/// Phase-space distance scaled to metres: unlike the position error alone it
/// cannot pass through zero when the numerical solution crosses the exact one.
fn phase_error(k: f64, got: (f64, f64), exact: (f64, f64)) -> f64 {
    let w0 = (k / 0.5f64).sqrt();
    ((got.0 - exact.0).powi(2) + ((got.1 - exact.1) / w0).powi(2)).sqrt()
}

#[test]
fn undamped_and_damped_oscillators_match_closed_form() {
    // k/m = (2π)²: period 1 s. Damping ratio 0.1 for the damped case.
    let k = 0.5 * TAU * TAU;
    for c in [0.0, 0.2 * (k * 0.5f64).sqrt()] {
        let t = 2.37;
        let exact = oscillator_exact(k, c, t);
        // RK4 at h = 1 ms: local error ~ (ωh)^5/120 per step → ~1e-11 m here.
        let (x, v) = oscillator(IntegratorKind::Rk4, k, c, 1e-3, t);
        assert!((x - exact.0).abs() < 1e-9, "rk4, c = {c}: {x} vs {exact:?}");
        assert!(
            (v - exact.1).abs() < 1e-8,
            "rk4, c = {c}: v = {v} vs {exact:?}"
        );
        // Midpoint (2nd order): global error ~ (ωh)² ω t a / 6 ≈ 6e-6 m.
        let (x, _) = oscillator(IntegratorKind::Midpoint, k, c, 1e-3, t);
        assert!(
            (x - exact.0).abs() < 2e-5,
            "midpoint, c = {c}: {x} vs {exact:?}"
        );
        // First-order methods: error ~ ω h ω t a / 2 ≈ 5e-3·a. Use h = 1e-5.
        for kind in [IntegratorKind::Euler, IntegratorKind::Symplectic] {
            let (x, _) = oscillator(kind, k, c, 1e-5, t);
            assert!(
                (x - exact.0).abs() < 1e-4,
                "{kind}, c = {c}: {x} vs {exact:?}"
            );
        }
    }
}

#[test]
fn convergence_orders_euler_1_midpoint_2_rk4_4() {
    let k = 0.5 * TAU * TAU;
    let c = 0.1 * (k * 0.5f64).sqrt();
    let t = 1.0;
    let exact = oscillator_exact(k, c, t);
    // Step sizes in each method's asymptotic range (ωh ≤ 0.03 for RK4), with
    // errors far above rounding.
    for (kind, h0, expected) in [
        (IntegratorKind::Euler, 1e-3, 1.0),
        (IntegratorKind::Symplectic, 1e-3, 1.0),
        (IntegratorKind::Midpoint, 4e-3, 2.0),
        (IntegratorKind::Rk4, 5e-3, 4.0),
    ] {
        let errors: Vec<f64> = [h0, h0 / 2.0, h0 / 4.0]
            .iter()
            .map(|&h| phase_error(k, oscillator(kind, k, c, h, t), exact))
            .collect();
        let p1 = (errors[0] / errors[1]).log2();
        let p2 = (errors[1] / errors[2]).log2();
        println!("{kind}: errors {errors:?}, orders {p1:.3} {p2:.3}");
        for p in [p1, p2] {
            assert!(
                (p - expected).abs() <= 0.2,
                "{kind}: measured order {p}, expected {expected}"
            );
        }
    }
}

#[test]
fn symplectic_euler_energy_error_stays_bounded_over_1000_periods() {
    let (m, k) = (0.5, 0.5 * TAU * TAU); // period 1 s
    let h = 0.01;
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    let anchor = w.add_particle(ParticleDef::new(1.0).fixed()).unwrap();
    let bob = w
        .add_particle(ParticleDef::new(m).at(DVec3::new(1.1, 0.0, 0.0)))
        .unwrap();
    w.add_spring(SpringDef::new(anchor, bob, k, 0.0).with_rest_length(1.0))
        .unwrap();
    assert!(w.is_conservative());
    let e0 = w.energy().total();
    let steps_per_period = 100;
    let mut worst_first = 0.0f64;
    let mut worst_last = 0.0f64;
    for period in 0..1000 {
        for _ in 0..steps_per_period {
            w.step(h).unwrap();
            let err = ((w.energy().total() - e0) / e0).abs();
            if period < 100 {
                worst_first = worst_first.max(err);
            } else if period >= 900 {
                worst_last = worst_last.max(err);
            }
        }
    }
    // The modified energy of symplectic Euler differs from E by O(ωh) ≈ 6%:
    // the error oscillates within that band and does not grow.
    println!("symplectic: worst relative energy error {worst_first:.4} (first 100 periods), {worst_last:.4} (last 100)");
    assert!(
        worst_first < TAU * h,
        "energy error {worst_first} larger than ωh"
    );
    assert!(
        worst_last <= worst_first * 1.05,
        "energy error grew: {worst_first} → {worst_last}"
    );

    // Explicit Euler on the same problem gains energy every period.
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Euler);
    let anchor = w.add_particle(ParticleDef::new(1.0).fixed()).unwrap();
    w.add_particle(ParticleDef::new(m).at(DVec3::new(1.1, 0.0, 0.0)))
        .unwrap();
    let bob = animats_engine::ParticleId::from_index(1);
    w.add_spring(SpringDef::new(anchor, bob, k, 0.0).with_rest_length(1.0))
        .unwrap();
    for _ in 0..10 * steps_per_period {
        w.step(h).unwrap();
    }
    assert!(
        w.energy().total() > 2.0 * e0,
        "explicit Euler should blow up the energy"
    );
}
