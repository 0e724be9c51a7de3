//! Drag across springs as rods (`RodDrag`) against its analytic forms: a
//! rod moving without turning feels `−½ C ρ D L |v_n| v_n` and nothing
//! along itself; its two-point quadrature's torque on a turning rod; its
//! power is never positive in still water; a rod coasting across still
//! water slows as `v₀ / (1 + k v₀ t)`; a current pushes a rod at rest.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_engine::{Current, Force, ForceContext, ParticleDef, ParticleId, RodDrag, World};
use glam::DVec3;

const RHO: f64 = 1000.0;
const C: f64 = 1.2;
const D: f64 = 0.02;

/// A world of two particles (0.1 kg each) at `a` and `b` moving with `va`
/// and `vb`.
fn rod(a: DVec3, b: DVec3, va: DVec3, vb: DVec3) -> (World, [ParticleId; 2]) {
    let mut w = World::new();
    let p = w
        .add_particle(ParticleDef::new(0.1).at(a).with_velocity(va))
        .unwrap();
    let q = w
        .add_particle(ParticleDef::new(0.1).at(b).with_velocity(vb))
        .unwrap();
    (w, [p, q])
}

/// The drag's force on each particle of `w` at its state.
fn forces(w: &World, drag: &mut RodDrag) -> Vec<DVec3> {
    let ctx = ForceContext {
        t: 0.0,
        dt: 1e-3,
        pos: &w.state().pos,
        vel: &w.state().vel,
        particles: w.particles(),
        gravity: DVec3::ZERO,
    };
    let mut f = vec![DVec3::ZERO; w.state().len()];
    drag.apply(&ctx, &mut f);
    f
}

fn water(ends: [ParticleId; 2], current: Current) -> RodDrag {
    RodDrag::new(RHO, C, D, current, &[(ends[0], ends[1])]).unwrap()
}

fn close(got: DVec3, want: DVec3, what: &str) {
    let tol = 1e-12 * want.length().max(1e-12);
    assert!(
        (got - want).length() <= tol,
        "{what}: got {got}, expected {want}"
    );
}

#[test]
fn a_rod_moving_without_turning_feels_the_cylinders_drag_across_it_and_none_along_it() {
    let l = 0.3;
    let (a, b) = (DVec3::new(0.1, 0.2, -0.3), DVec3::new(0.1 + l, 0.2, -0.3));
    for deg in [0.0f64, 20.0, 45.0, 70.0, 90.0, 135.0] {
        let th = deg.to_radians();
        let v = DVec3::new(th.cos(), th.sin(), 0.0) * 0.7;
        let (w, ends) = rod(a, b, v, v);
        let f = forces(&w, &mut water(ends, Current::Still));
        // Across the rod: v sin θ along +y; ½ C ρ D L (v sin θ)².
        let vn = v.y;
        let want = DVec3::new(0.0, -0.5 * C * RHO * D * l * vn.abs() * vn, 0.0);
        close(f[0] + f[1], want, &format!("total at {deg}°"));
        close(f[0], want * 0.5, &format!("end a at {deg}°"));
        close(f[1], want * 0.5, &format!("end b at {deg}°"));
        if deg == 0.0 {
            assert_eq!(f[0] + f[1], DVec3::ZERO, "along the rod: nothing");
        }
    }
}

#[test]
fn a_rod_turning_about_its_middle_feels_no_force_and_the_quadratures_torque() {
    // ω about z, the rod along x: a point at s from the middle moves at
    // ω s along y. The integral's torque is c ω² L⁴ / 32 (c = ½ C ρ D);
    // the two Gauss points at ±L/(2√3), each carrying L/2, give
    // c ω² L⁴ / (24 √3), 0.770 of it; the net force is zero either way.
    let (l, omega) = (0.4, 3.0);
    let (a, b) = (
        DVec3::new(-l / 2.0, 0.0, 0.0),
        DVec3::new(l / 2.0, 0.0, 0.0),
    );
    let (w, ends) = rod(
        a,
        b,
        DVec3::new(0.0, -omega * l / 2.0, 0.0),
        DVec3::new(0.0, omega * l / 2.0, 0.0),
    );
    let f = forces(&w, &mut water(ends, Current::Still));
    // Zero to rounding of the end forces (0.29 N each).
    assert!(
        (f[0] + f[1]).length() <= 1e-12 * f[0].length(),
        "net force {}",
        f[0] + f[1]
    );
    let torque = a.cross(f[0]) + b.cross(f[1]);
    let c = 0.5 * C * RHO * D;
    let quadrature = c * omega * omega * l.powi(4) / (24.0 * 3f64.sqrt());
    let integral = c * omega * omega * l.powi(4) / 32.0;
    close(torque, DVec3::new(0.0, 0.0, -quadrature), "torque");
    assert!((quadrature / integral - 0.7698).abs() < 1e-4);
}

#[test]
fn in_still_water_the_drag_never_adds_energy() {
    // Power F·v summed over the ends is −Σ c (L/2) |v_n|³ ≤ 0 at any state,
    // springs stretched, turning, or not.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut worst = f64::NEG_INFINITY;
    for _ in 0..10_000 {
        let mut v = || DVec3::new(next(), next(), next());
        let (a, b, va, vb) = (v(), v(), v() * 3.0, v() * 3.0);
        let (w, ends) = rod(a, b, va, vb);
        let f = forces(&w, &mut water(ends, Current::Still));
        worst = worst.max(f[0].dot(va) + f[1].dot(vb));
    }
    assert!(worst <= 0.0, "drag did work {worst} W");
}

#[test]
fn a_rod_coasting_across_still_water_slows_as_the_analytic_solution() {
    // m dv/dt = −c L v² (c = ½ C ρ D, both ends 0.1 kg) → v = v₀ / (1 + k v₀ t),
    // k = c L / m; the rod keeps its direction (no torque by symmetry).
    let (l, v0, m) = (0.3, 2.0, 0.2);
    let v = DVec3::new(0.0, 0.0, v0);
    let (mut w, ends) = rod(DVec3::ZERO, DVec3::new(l, 0.0, 0.0), v, v);
    w.add_force(Box::new(water(ends, Current::Still)));
    let k = 0.5 * C * RHO * D * l / m;
    let h = 1e-4; // RK4: k v₀ h = 0.0036, its error far below the tolerance
    for _ in 0..20_000 {
        w.step(h).unwrap(); // 2 s: 72 times 1/(k v₀)
    }
    let want = v0 / (1.0 + k * v0 * 2.0);
    for p in ends {
        let got = w.velocity(p);
        assert!(
            (got.z - want).abs() < 1e-9 && got.x.abs() < 1e-12 && got.y.abs() < 1e-12,
            "{got} against ({want} along z)"
        );
    }
    // Along its length it coasts on forever.
    let v = DVec3::new(v0, 0.0, 0.0);
    let (mut w, ends) = rod(DVec3::ZERO, DVec3::new(l, 0.0, 0.0), v, v);
    w.add_force(Box::new(water(ends, Current::Still)));
    for _ in 0..100 {
        w.step(h).unwrap();
    }
    assert_eq!(w.velocity(ends[0]), v);
}

#[test]
fn a_current_pushes_a_rod_at_rest_as_the_rod_moving_through_still_water_is_pushed_back() {
    let u = DVec3::new(0.0, 0.5, 0.25);
    let (a, b) = (DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.0, 2.0, 3.5));
    let (w, ends) = rod(a, b, DVec3::ZERO, DVec3::ZERO);
    let pushed = forces(&w, &mut water(ends, Current::Uniform(u)));
    let (w, ends) = rod(a, b, -u, -u);
    let dragged = forces(&w, &mut water(ends, Current::Still));
    close(pushed[0], dragged[0], "end a");
    close(pushed[1], dragged[1], "end b");
    // Only the current's part across the rod (along y) acts.
    assert!(pushed[0].z == 0.0 && pushed[0].y > 0.0);
}

#[test]
fn bad_parameters_are_refused_by_name() {
    let (_, [p, q]) = rod(DVec3::ZERO, DVec3::X, DVec3::ZERO, DVec3::ZERO);
    let err = |r: Result<RodDrag, animats_engine::ModelError>| r.unwrap_err().to_string();
    assert!(err(RodDrag::new(RHO, C, 0.0, Current::Still, &[(p, q)])).contains("diameter"));
    assert!(
        err(RodDrag::new(RHO, f64::NAN, D, Current::Still, &[(p, q)])).contains("drag_coefficient")
    );
    assert!(err(RodDrag::new(-1.0, C, D, Current::Still, &[(p, q)])).contains("density"));
    assert!(err(RodDrag::new(RHO, C, D, Current::Still, &[(p, p)])).contains("itself"));
}
