//! Sphere–sphere contact against the physics of impacts.
//!
//! - A head-on collision of unequal masses conserves momentum exactly and
//!   keeps e² of the relative kinetic energy (the relative velocity is
//!   reversed and scaled by e).
//! - A glancing collision conserves momentum in both directions; without
//!   friction the tangential relative velocity is untouched.
//! - Newton's cradle of 5 balls with e = 1 passes the impulse to the last.
//! - A sphere thrown at a nailed one with v·h just under the radius bounces
//!   back instead of tunnelling (the missed overlap is backtracked).
//! - Joined pairs never collide.
//! - A sphere dropped on one resting on the floor comes to rest on it, with
//!   the pair's overlap under a micrometre; one set in the pocket of three
//!   rests at the height of the tetrahedron, the base held by friction; a
//!   square pyramid of 30 comes to rest and stays; so does a column of 12,
//!   taller than the handling's passes.
//! - Spheres flung far away neither break the grid nor hide a collision;
//!   spheres millions of cells apart are never a pair (not even a sphere
//!   with itself), and a pair that touches out there is found once.
//!
//! The pile of a thousand spheres is in `crates/bench/tests/pile.rs`.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_engine::{
    FloorDef, IntegratorKind, ParticleDef, SphereContact, SphereContactDef, SpringDef, World,
};
use glam::DVec3;

fn ball(m: f64, r: f64, x: DVec3, v: DVec3) -> ParticleDef {
    ParticleDef::new(m).with_radius(r).at(x).with_velocity(v)
}

#[test]
fn head_on_unequal_masses_conserve_momentum_and_keep_e_squared() {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    let a = w
        .add_particle(ball(2.0, 0.1, DVec3::ZERO, DVec3::X).with_restitution(0.8))
        .unwrap();
    let b = w
        .add_particle(
            ball(0.5, 0.1, DVec3::new(0.5, 0.0, 0.0), -2.0 * DVec3::X).with_restitution(0.5),
        )
        .unwrap();
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    let p0 = w.momentum();
    let u0 = w.velocity(b) - w.velocity(a);
    let mut hits = 0;
    for _ in 0..300 {
        w.step(1e-3).unwrap();
        hits += w.event::<SphereContact>().unwrap().impacts().len();
    }
    assert_eq!(hits, 1);
    let p1 = w.momentum();
    assert!((p1 - p0).length() < 1e-14, "momentum {p0} -> {p1}");
    // e = 0.8 × 0.5: the relative velocity reverses, scaled by 0.4, so the
    // relative kinetic energy ½ μ u² keeps 0.16 of itself.
    let u1 = w.velocity(b) - w.velocity(a);
    assert!((u1 - (-0.4 * u0)).length() < 1e-14, "u {u0} -> {u1}");
    let ratio = u1.length_squared() / u0.length_squared();
    assert!(
        (ratio - 0.16).abs() < 1e-14,
        "kept {ratio} of the relative energy"
    );
}

fn glancing(mu: f64) -> (World, DVec3, DVec3) {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Rk4);
    w.add_particle(
        ball(1.5, 0.1, DVec3::ZERO, DVec3::new(2.0, 0.0, 0.3))
            .with_friction(mu, mu)
            .with_restitution(0.9),
    )
    .unwrap();
    w.add_particle(
        ball(
            0.7,
            0.1,
            DVec3::new(0.6, 0.12, 0.0),
            DVec3::new(-1.0, 0.2, 0.0),
        )
        .with_friction(mu, mu)
        .with_restitution(0.9),
    )
    .unwrap();
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    let p0 = w.momentum();
    let u0 = w.state().vel[1] - w.state().vel[0];
    (w, p0, u0)
}

#[test]
fn a_glancing_collision_conserves_momentum_in_both_directions() {
    for mu in [0.0, 0.6] {
        let (mut w, p0, u0) = glancing(mu);
        let mut normal = None;
        for _ in 0..400 {
            w.step(1e-3).unwrap();
            if normal.is_none() && !w.event::<SphereContact>().unwrap().impacts().is_empty() {
                let s = w.state();
                normal = Some((s.pos[1] - s.pos[0]).normalize());
            }
        }
        let n = normal.expect("they collided");
        let p1 = w.momentum();
        assert!((p1 - p0).length() < 1e-14, "μ {mu}: momentum {p0} -> {p1}");
        let u1 = w.state().vel[1] - w.state().vel[0];
        // Along the normal: reversed and scaled by e = 0.81.
        assert!((u1.dot(n) + 0.81 * u0.dot(n)).abs() < 1e-12, "μ {mu}");
        let (t0, t1) = (u0 - n * u0.dot(n), u1 - n * u1.dot(n));
        if mu == 0.0 {
            assert!((t1 - t0).length() < 1e-12, "frictionless: {t0} -> {t1}");
        } else {
            // Friction slows the sliding, never reverses it.
            assert!(
                t1.length() < t0.length() && t1.dot(t0) >= 0.0,
                "{t0} -> {t1}"
            );
        }
    }
}

#[test]
fn newtons_cradle_passes_the_impulse_to_the_last_ball() {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    let r = 0.05;
    let mut balls = vec![w
        .add_particle(ball(1.0, r, DVec3::new(-0.3, 0.0, 0.0), DVec3::X).with_restitution(1.0))
        .unwrap()];
    for k in 1..5 {
        // Hanging in a row, 0.1 mm apart.
        let x = DVec3::new(k as f64 * (2.0 * r + 1e-4), 0.0, 0.0);
        balls.push(
            w.add_particle(ball(1.0, r, x, DVec3::ZERO).with_restitution(1.0))
                .unwrap(),
        );
    }
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    for _ in 0..500 {
        w.step(1e-3).unwrap();
    }
    for (k, &b) in balls.iter().enumerate() {
        let v = w.velocity(b);
        let expected = if k == 4 { DVec3::X } else { DVec3::ZERO };
        assert!((v - expected).length() < 1e-12, "ball {k}: {v}");
    }
}

#[test]
fn no_tunnelling_when_a_step_moves_less_than_the_radius() {
    let r = 0.05;
    for fraction in [0.5, 0.9, 0.99] {
        let h = 1e-3;
        let v = fraction * r / h;
        let mut w = World::new();
        w.set_integrator(IntegratorKind::Symplectic);
        w.add_particle(ParticleDef::new(1.0).with_radius(r).fixed())
            .unwrap();
        let b = w
            .add_particle(
                ball(1.0, r, DVec3::new(-0.5, 0.0, 0.0), DVec3::new(v, 0.0, 0.0))
                    .with_restitution(1.0),
            )
            .unwrap();
        w.add_sphere_contact(SphereContactDef {
            restitution: Some(1.0),
            ..SphereContactDef::default()
        })
        .unwrap();
        for _ in 0..(1.0 / v / h) as usize + 10 {
            w.step(h).unwrap();
            assert!(
                w.position(b).x <= -2.0 * r + 0.01 + 1e-12,
                "v h = {fraction} r: it got through"
            );
        }
        assert!(
            (w.velocity(b).x + v).abs() < 1e-9 * v,
            "v h = {fraction} r: {}",
            w.velocity(b)
        );
    }
}

#[test]
fn no_tunnelling_when_a_step_moves_several_diameters() {
    // A swept test: a step that carries a sphere right through another
    // (nothing overlaps at either end) is missed and retaken in pieces.
    let r = 0.05;
    let h = 1e-3;
    for per_step in [3.0, 10.0, 40.0] {
        for phase in 0..8 {
            let v = per_step * r / h;
            let start = -0.5 - per_step * r * phase as f64 / 8.0;
            let mut w = World::new();
            w.set_integrator(IntegratorKind::Symplectic);
            w.add_particle(ParticleDef::new(1.0).with_radius(r).fixed())
                .unwrap();
            let b = w
                .add_particle(ball(
                    1.0,
                    r,
                    DVec3::new(start, 0.0, 0.0),
                    DVec3::new(v, 0.0, 0.0),
                ))
                .unwrap();
            w.add_sphere_contact(SphereContactDef {
                restitution: Some(1.0),
                ..SphereContactDef::default()
            })
            .unwrap();
            for _ in 0..20 {
                w.step(h).unwrap();
                assert!(
                    w.position(b).x < 0.0,
                    "{per_step} r a step, from {start}: through to {}",
                    w.position(b)
                );
            }
            assert!(
                w.velocity(b).x < 0.0,
                "{per_step} r, from {start}: did not bounce"
            );
        }
    }
    // Two free spheres crossing head on, each 4 r a step, and one
    // overtaking another in the same direction.
    for (va, vb) in [(4.0, -4.0), (12.0, 2.0)] {
        let mut w = World::new();
        w.set_integrator(IntegratorKind::Symplectic);
        let a = w
            .add_particle(ball(
                1.0,
                r,
                DVec3::new(-0.47, 0.0, 0.0),
                DVec3::X * (va * r / h),
            ))
            .unwrap();
        let b = w
            .add_particle(ball(
                1.0,
                r,
                DVec3::new(0.33, 0.0, 0.0),
                DVec3::X * (vb * r / h),
            ))
            .unwrap();
        w.add_sphere_contact(SphereContactDef::default()).unwrap();
        let p0 = w.momentum();
        for _ in 0..40 {
            w.step(h).unwrap();
            assert!(
                w.position(a).x < w.position(b).x,
                "{va}, {vb}: they passed through"
            );
        }
        assert!((w.momentum() - p0).length() < 1e-12 * p0.length().max(1.0));
    }
}

#[test]
fn joined_pairs_never_collide() {
    let mut w = World::new();
    let a = w
        .add_particle(ball(1.0, 0.1, DVec3::ZERO, DVec3::ZERO))
        .unwrap();
    let b = w
        .add_particle(ball(1.0, 0.1, DVec3::new(0.15, 0.0, 0.0), DVec3::ZERO))
        .unwrap();
    w.add_spring(SpringDef::new(a, b, 10.0, 0.0)).unwrap();
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    for _ in 0..10 {
        w.step(1e-3).unwrap();
        assert!(w.event::<SphereContact>().unwrap().impacts().is_empty());
    }
    assert_eq!(w.position(b), DVec3::new(0.15, 0.0, 0.0));
}

#[test]
fn a_sphere_dropped_on_another_comes_to_rest_on_it() {
    let r = 0.02;
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let low = w
        .add_particle(
            ParticleDef::new(0.05)
                .with_radius(r)
                .at(DVec3::new(0.0, r, 0.0)),
        )
        .unwrap();
    let high = w
        .add_particle(
            ParticleDef::new(0.05)
                .with_radius(r)
                .at(DVec3::new(0.0, 0.2, 0.0))
                .with_restitution(0.5),
        )
        .unwrap();
    // The floor first: the contacts then know to leave it holding `low`.
    w.add_floor(FloorDef::default()).unwrap();
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    let mut bounces = 0;
    for _ in 0..3000 {
        w.step(1e-3).unwrap();
        bounces += w.event::<SphereContact>().unwrap().impacts().len();
    }
    let gap = (w.position(high) - w.position(low)).length() - 2.0 * r;
    println!(
        "{bounces} impacts, gap {gap:e} m, speeds {} {}",
        w.velocity(low),
        w.velocity(high)
    );
    assert!(bounces > 1, "it bounced (e = 0.25 at the first impact)");
    assert!(gap.abs() < 1e-6, "gap {gap}");
    assert!(w.velocity(high).length() < 1e-9 && w.velocity(low).length() < 1e-9);
    assert!((w.position(low).y - r).abs() < 1e-9);
}

#[test]
fn spheres_far_beyond_the_grid_neither_panic_nor_hide_a_collision() {
    // Spheres 1e200 m away make the grid sparse (a hash map of occupied
    // cells instead of a dense array): the two near the origin still meet,
    // once, and the far ones never.
    let mut w = World::new();
    w.add_particle(ball(1.0, 0.1, DVec3::ZERO, DVec3::X))
        .unwrap();
    w.add_particle(ball(1.0, 0.1, DVec3::new(0.25, 0.0, 0.0), DVec3::ZERO))
        .unwrap();
    for x in [1e200, -1e200, 1e200 + 1e190] {
        w.add_particle(ball(1.0, 0.1, DVec3::new(x, 0.0, 0.0), DVec3::ZERO))
            .unwrap();
    }
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    let mut impacts = Vec::new();
    for _ in 0..200 {
        w.step(1e-3).unwrap();
        let c = w.event::<SphereContact>().unwrap();
        impacts.extend(
            c.impacts()
                .iter()
                .map(|i| (i.spheres.0.index(), i.spheres.1.index())),
        );
    }
    assert_eq!(impacts, vec![(0, 1)]);
}

#[test]
fn spheres_apart_a_million_cells_and_more_are_never_a_pair() {
    // Cells twice the largest radius, 6 cm here: spheres 100 km from the
    // origin are 1.7 million cells out, and a sparse grid's neighbouring
    // cells there must stay distinct cells, or a sphere is tested against
    // itself (an overlap of 2r at distance 0: every step backtracked).
    // Apart: no pair, no overlap. Two overlapping by 1 mm out there: one
    // pair, 1 mm deep. Spread over more cells than a 64-bit key holds
    // (10¹² cells apart in x, 10⁹ in y and z): the same.
    let r = 0.03;
    for (spread, far) in [
        (DVec3::new(7e3, 0.0, 0.0), 1e5),
        (DVec3::new(7e3, 0.0, 0.0), -1e5),
        (DVec3::new(6e10, 6e7, 6e7), 0.0),
        (DVec3::new(1e300, 0.0, 0.0), 0.0),
    ] {
        for touching in [false, true] {
            let mut w = World::new();
            w.set_integrator(IntegratorKind::Symplectic);
            let mut at = Vec::new();
            for i in 0..12 {
                at.push(DVec3::new(far, 0.0, 0.0) + spread * (i as f64 - 5.5));
            }
            if touching {
                at.push(at[3] + DVec3::new(0.0, 2.0 * r - 1e-3, 0.0));
            }
            for &x in &at {
                w.add_particle(ball(1.0, r, x, DVec3::ZERO)).unwrap();
            }
            w.add_sphere_contact(SphereContactDef::default()).unwrap();
            let mut probe = SphereContact::new(SphereContactDef::default()).unwrap();
            let deepest = probe.deepest_overlap(&w.state().pos, w.particles());
            let want = if touching { 1e-3 } else { 0.0 };
            // The pair lies along y: its gap is rounded where its y is.
            let tol = 4.0 * f64::EPSILON * (at[3].y.abs() + 2.0 * r);
            assert!(
                (deepest - want).abs() <= tol,
                "spread {spread}, far {far}, touching {touching}: deepest overlap {deepest}"
            );
            let steps = w.step(1e-3).unwrap();
            assert_eq!(
                w.event::<SphereContact>().unwrap().touching(),
                usize::from(touching),
                "spread {spread}, far {far}, touching {touching}"
            );
            assert_eq!(steps.backtracks, 0, "spread {spread}, far {far}");
        }
    }
}

#[test]
fn a_sphere_rests_in_the_pocket_of_three_at_the_height_of_a_tetrahedron() {
    // Three touching spheres on the floor, a fourth set down 1 mm above the
    // pocket between them: it settles at r + √(4r² − d²) (d: the base's
    // circumradius), and friction keeps the base from spreading.
    let r = 0.02;
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let d = 2.0 * r / 3f64.sqrt();
    let sphere = |x: DVec3| {
        ParticleDef::new(0.05)
            .with_radius(r)
            .at(x)
            .with_restitution(0.3)
            .with_friction(0.6, 0.4)
    };
    for k in 0..3 {
        let a = std::f64::consts::TAU * k as f64 / 3.0;
        w.add_particle(sphere(DVec3::new(d * a.cos(), r, d * a.sin())))
            .unwrap();
    }
    let height = r + (4.0 * r * r - d * d).sqrt();
    let top = w
        .add_particle(sphere(DVec3::new(0.0, height + 0.001, 0.0)))
        .unwrap();
    w.add_floor(FloorDef::default()).unwrap();
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    for _ in 0..3000 {
        w.step(1e-3).unwrap();
    }
    let s = w.state();
    // Within what one step of gravity moves it, g h² ≈ 1e-5 m.
    assert!(
        (w.position(top).y - height).abs() < 9.8e-6,
        "top at {}, expected {height}",
        w.position(top).y
    );
    for k in 0..3 {
        let side = (s.pos[k] - s.pos[(k + 1) % 3]).length();
        assert!(
            (side - 2.0 * r).abs() < 1e-9,
            "the base spread: side {side}"
        );
    }
    // What is left of the velocity is less than one step of gravity.
    assert!(s.vel.iter().all(|v| v.length() < 9.8e-3));
}

/// A square pyramid of 30 spheres (4×4, 3×3, 2×2 and one on top), each
/// layer set in the pockets of the one below, touching, on the floor.
fn pyramid(r: f64) -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    // Over a square of four touching spheres the one above sits √2 r
    // higher (its centre √2 r from each of theirs horizontally, 2r apart).
    let rise = 2f64.sqrt() * r;
    for (layer, side) in [4usize, 3, 2, 1].into_iter().enumerate() {
        let first = -(side as f64 - 1.0) * r;
        for i in 0..side {
            for j in 0..side {
                let x = DVec3::new(
                    first + 2.0 * r * i as f64,
                    r + rise * layer as f64,
                    first + 2.0 * r * j as f64,
                );
                w.add_particle(
                    ParticleDef::new(0.05)
                        .with_radius(r)
                        .at(x)
                        .with_restitution(0.3)
                        .with_friction(0.6, 0.4),
                )
                .unwrap();
            }
        }
    }
    w.add_floor(FloorDef::default()).unwrap();
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    w
}

#[test]
fn a_pyramid_of_spheres_comes_to_rest_and_stays() {
    // Resting contact between spheres settles as the floor's does: within
    // a few steps the pyramid reaches a state it returns to after every
    // step, having sunk by at most one step of gravity per layer (g h²,
    // the overlap a step's fall makes before the contact removes it).
    let (r, h) = (0.02, 1e-3);
    let mut w = pyramid(r);
    let start = w.state().pos.clone();
    for _ in 0..1000 {
        w.step(h).unwrap();
    }
    let settled = w.state().clone();
    for _ in 0..4000 {
        w.step(h).unwrap();
    }
    let drift = w
        .state()
        .pos
        .iter()
        .zip(&settled.pos)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max);
    let sag = w
        .state()
        .pos
        .iter()
        .zip(&start)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max);
    let speed = w.state().vel.iter().map(|v| v.length()).fold(0.0, f64::max);
    println!("drift over 4 s {drift:e} m, sag {sag:e} m, fastest {speed:e} m/s");
    assert!(drift < 1e-12, "still moving: {drift} m in 4 s");
    assert!(sag < 4.0 * 9.8 * h * h, "sank {sag} m");
    // What a step's end still carries of that step's gravity (the passes
    // stop before every contact has taken it back), never more.
    assert!(speed <= 9.8 * h, "fastest {speed} m/s");
}

#[test]
fn a_column_taller_than_the_passes_rests_on_the_floor() {
    // Twelve spheres stacked on the floor, more than the handling's passes:
    // each rests on the one below although the two merely touch when a
    // step ends (both fell by the same g h²), so the push of the spheres
    // above must reach the floor through contacts that do not overlap.
    // The column comes to rest and stays there, each contact overlapping
    // by less than a slow approach closes in a step (`rest_speed · h`).
    // (The passes do not take back all of a step's gravity in so tall a
    // column: its lower spheres end a step with a few g h of it, which
    // the next step's contacts take back; positions repeat exactly.)
    let (r, h, n) = (0.02, 1e-3, 12);
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    for k in 0..n {
        let x = DVec3::new(0.0, r + 2.0 * r * k as f64, 0.0);
        w.add_particle(ball(0.05, r, x, DVec3::ZERO).with_restitution(0.3))
            .unwrap();
    }
    w.add_floor(FloorDef::default()).unwrap();
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    let start = w.state().pos.clone();
    for _ in 0..1000 {
        w.step(h).unwrap();
    }
    let settled = w.state().pos.clone();
    let mut travelled = 0.0;
    for _ in 0..1000 {
        let before = w.state().pos.clone();
        w.step(h).unwrap();
        travelled += (w.state().pos[n - 1] - before[n - 1]).length();
    }
    let top = w.state().pos[n - 1];
    let sag = start[n - 1].y - top.y;
    let drift = (top - settled[n - 1]).length();
    let speed = w.state().vel.iter().map(|v| v.length()).fold(0.0, f64::max);
    println!("top: sag {sag:e} m, drift {drift:e} m, travelled {travelled:e} m in a second; fastest {speed:e} m/s");
    let rest_speed = SphereContactDef::default().rest_speed;
    assert!(
        sag > 0.0 && sag < (n - 1) as f64 * rest_speed * h,
        "the top sank {sag} m"
    );
    assert!(drift < 1e-12, "the top moved {drift} m in a second at rest");
    assert!(
        travelled < 1e-9,
        "the top travelled {travelled} m step by step in a second"
    );
}
