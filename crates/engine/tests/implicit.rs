//! Implicit (backward) Euler against what backward Euler must do.
//!
//! - On a harmonic oscillator every step multiplies the amplitude
//!   √(x² + (v/ω)²) by exactly 1/√(1 + ω²h²), at small and at huge steps.
//! - First order, measured from three step sizes on a nonlinear system
//!   (springs, an angle joint, damping, gravity) against RK4 at a tiny step.
//! - Internal forces (springs, angle joints) conserve linear momentum, to
//!   the linear solver's tolerance.
//! - A user force without a Jacobian still acts (explicitly).
//! - Linear drag: `v` falls by exactly `1/(1 + h b/m)` a step (RK4: by its
//!   stability polynomial).
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_engine::{
    AngleJointDef, Force, ForceContext, IntegratorKind, LinearDrag, ParticleDef, Solver, SpringDef,
    Targets, World,
};
use glam::DVec3;

/// A mass `m` on a spring `k` of rest length 1 to a nail at the origin,
/// stretched by `x0` along x.
fn oscillator(m: f64, k: f64, x0: f64) -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Implicit);
    let nail = w.add_particle(ParticleDef::new(1.0).fixed()).unwrap();
    let bob = w
        .add_particle(ParticleDef::new(m).at(DVec3::new(1.0 + x0, 0.0, 0.0)))
        .unwrap();
    w.add_spring(SpringDef::new(nail, bob, k, 0.0).with_rest_length(1.0))
        .unwrap();
    w
}

#[test]
fn oscillator_amplitude_decays_by_backward_eulers_factor_every_step() {
    let (m, k) = (0.5f64, 200.0f64);
    let omega = (k / m).sqrt();
    for omega_h in [0.05f64, 0.5, 5.0, 50.0] {
        let h = omega_h / omega;
        let mut w = oscillator(m, k, 0.3);
        let amplitude = |w: &World| {
            let (x, v) = (w.state().pos[1].x - 1.0, w.state().vel[1].x);
            (x * x + (v / omega) * (v / omega)).sqrt()
        };
        let factor = 1.0 / (1.0 + omega_h * omega_h).sqrt();
        let mut a = amplitude(&w);
        let a0 = a;
        for step in 0..200 {
            w.step(h).unwrap();
            let next = amplitude(&w);
            if next < 1e-6 * a0 {
                // Rounding in x − 1 (1e-16) is now 1e-10 of the amplitude.
                break;
            }
            let ratio = next / a;
            assert!(
                (ratio - factor).abs() < 1e-9,
                "ωh = {omega_h}, step {step}: ratio {ratio}, expected {factor}"
            );
            // It stays on the spring's axis.
            assert_eq!(w.state().pos[1].y, 0.0);
            a = next;
        }
    }
}

/// Three particles in a vertical plane: a nail, two masses on stiff damped
/// springs, an angle joint at the middle one, gravity; swung sideways.
fn nonlinear(kind: IntegratorKind) -> World {
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let a = w
        .add_particle(ParticleDef::new(1.0).at(DVec3::new(0.0, 1.0, 0.0)).fixed())
        .unwrap();
    let b = w
        .add_particle(
            ParticleDef::new(0.3)
                .at(DVec3::new(0.4, 0.9, 0.0))
                .with_velocity(DVec3::new(0.0, 0.5, 0.2)),
        )
        .unwrap();
    let c = w
        .add_particle(ParticleDef::new(0.2).at(DVec3::new(0.7, 0.5, 0.1)))
        .unwrap();
    w.add_spring(SpringDef::new(a, b, 300.0, 0.5)).unwrap();
    w.add_spring(SpringDef::new(b, c, 200.0, 0.3).with_rest_length(0.45))
        .unwrap();
    w.add_angle_joint(AngleJointDef::new(a, b, c, 2.0, 0.05).with_rest_angle(2.5))
        .unwrap();
    w
}

fn end_state(kind: IntegratorKind, h: f64, t: f64) -> Vec<DVec3> {
    let mut w = nonlinear(kind);
    let n = (t / h).round() as usize;
    for _ in 0..n {
        w.step(h).unwrap();
    }
    w.state().pos.clone()
}

#[test]
fn implicit_euler_converges_at_first_order() {
    let t = 0.5;
    let exact = end_state(IntegratorKind::Rk4, 1e-5, t);
    let error = |h: f64| {
        let got = end_state(IntegratorKind::Implicit, h, t);
        got.iter()
            .zip(&exact)
            .map(|(g, e)| (*g - *e).length())
            .fold(0.0, f64::max)
    };
    let e: Vec<f64> = [2e-3, 1e-3, 5e-4].iter().map(|&h| error(h)).collect();
    let (p1, p2) = ((e[0] / e[1]).log2(), (e[1] / e[2]).log2());
    println!("errors {e:?}, orders {p1:.3} {p2:.3}");
    for p in [p1, p2] {
        assert!((p - 1.0).abs() <= 0.1, "measured order {p}");
    }
}

/// No gravity, no nails: springs (some compressed, some stretched, with
/// damping) and angle joints only, at a step far past explicit stability;
/// returns the drift of momentum over 400 steps as a fraction of Σ m|v|.
fn momentum_drift(tolerance: f64) -> f64 {
    let mut w = World::new();
    w.set_solver(Solver {
        tolerance,
        ..Solver::default()
    })
    .unwrap();
    w.set_integrator(IntegratorKind::Implicit);
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    let mut u = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let ids: Vec<_> = (0..8)
        .map(|i| {
            let x = DVec3::new(i as f64 * 0.3 + 0.1 * u(), u(), 0.3 * u());
            let v = DVec3::new(u(), u(), u()) * 2.0;
            w.add_particle(ParticleDef::new(0.2 + u().abs()).at(x).with_velocity(v))
                .unwrap()
        })
        .collect();
    for i in 0..8 {
        for j in [i + 1, i + 2] {
            if j < 8 {
                let rest = 0.3 * (1.0 + u());
                w.add_spring(SpringDef::new(ids[i], ids[j], 500.0, 0.2).with_rest_length(rest))
                    .unwrap();
            }
        }
        if i + 2 < 8 {
            w.add_angle_joint(AngleJointDef::new(ids[i], ids[i + 1], ids[i + 2], 3.0, 0.1))
                .unwrap();
        }
    }
    let p0 = w.momentum();
    let scale: f64 = (0..8)
        .map(|i| w.particles().mass[i] * w.state().vel[i].length())
        .sum();
    let h = 0.05; // ω h ≈ 3 for the stiffest spring
    for _ in 0..400 {
        w.step(h).unwrap();
    }
    assert!(w.state().vel.iter().all(|v| v.is_finite()));
    (w.momentum() - p0).length() / scale
}

/// The forces' sum is zero, so the momentum changes only by the linear
/// solve's residual: it is conserved to the solver's tolerance (within 10×
/// it over 400 steps, at every tolerance: the drift scales with it).
#[test]
fn internal_forces_conserve_momentum_to_the_solver_tolerance() {
    for tolerance in [1e-6, 1e-9, 1e-12] {
        let drift = momentum_drift(tolerance);
        println!("tolerance {tolerance:e}: momentum drift {drift:e} of Σ m|v|");
        assert!(
            drift < 10.0 * tolerance,
            "tolerance {tolerance:e}: drift {drift:e}"
        );
    }
}

/// A constant push written as a user force, without a Jacobian.
#[derive(Clone)]
struct Push(DVec3);

impl Force for Push {
    fn apply(&mut self, _ctx: &ForceContext, forces: &mut [DVec3]) {
        for f in forces {
            *f += self.0;
        }
    }
}

#[test]
fn a_user_force_without_a_jacobian_acts_explicitly() {
    // Free flight under a constant user push: the step is symplectic
    // Euler's to rounding, as for gravity.
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Implicit);
    let p = w.add_particle(ParticleDef::new(2.0)).unwrap();
    w.add_force(Box::new(Push(DVec3::new(4.0, 0.0, -2.0))));
    let (h, n) = (0.01, 100);
    for _ in 0..n {
        w.step(h).unwrap();
    }
    let (a, t) = (DVec3::new(2.0, 0.0, -1.0), h * n as f64);
    let expected = 0.5 * a * t * t + 0.5 * a * t * h;
    assert!((w.position(p) - expected).length() < 1e-12);
    assert!((w.velocity(p) - a * t).length() < 1e-12);
}

#[test]
fn linear_drag_slows_by_backward_eulers_factor_and_rk4s_polynomial() {
    let (m, b, h) = (0.4, 2.0, 0.05);
    let v0 = DVec3::new(3.0, -1.0, 0.5);
    for kind in [IntegratorKind::Implicit, IntegratorKind::Rk4] {
        let mut w = World::new();
        w.set_integrator(kind);
        let p = w
            .add_particle(ParticleDef::new(m).with_velocity(v0))
            .unwrap();
        w.add_linear_drag(LinearDrag {
            coefficient: b,
            targets: Targets::All,
        })
        .unwrap();
        for n in 1..=40 {
            w.step(h).unwrap();
            let expected = match kind {
                // b h / m = 0.25: far past where explicit Euler oscillates.
                IntegratorKind::Implicit => v0 / (1.0 + h * b / m).powi(n),
                // RK4 on v' = −(b/m) v multiplies by its stability
                // polynomial R(z) = 1 + z + z²/2 + z³/6 + z⁴/24, z = −bh/m.
                _ => {
                    let z = -h * b / m;
                    v0 * (1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0).powi(n)
                }
            };
            assert!(
                (w.velocity(p) - expected).length() < 1e-14 * v0.length(),
                "{kind}, step {n}: {} vs {expected}",
                w.velocity(p)
            );
        }
    }
    let mut w = World::new();
    assert!(w
        .add_linear_drag(LinearDrag {
            coefficient: -1.0,
            targets: Targets::All
        })
        .is_err());
}
