//! Terrain: spheres meet a slope, steps and a heightfield as they meet the
//! flat floor — the same located impacts, restitution, resting and
//! friction — along the surface's normal.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_engine::{
    FloorCollision, FloorDef, Heightfield, IntegratorKind, ParticleDef, ParticleId, Slope, Steps,
    Terrain, World,
};
use glam::{DVec2, DVec3};

const G: f64 = 9.8;

fn world_on(terrain: Terrain, kind: IntegratorKind) -> World {
    let mut w = World::new();
    w.set_gravity(DVec3::new(0.0, -G, 0.0));
    w.set_integrator(kind);
    w.add_floor(FloorDef {
        terrain,
        ..FloorDef::default()
    })
    .unwrap();
    w
}

fn slope(degrees: f64) -> Terrain {
    Terrain::Slope(Slope {
        angle: degrees.to_radians(),
        uphill: DVec3::new(0.6, 0.0, 0.8),
    })
}

/// The slope's outward normal and its steepest direction down.
fn frame(degrees: f64) -> (DVec3, DVec3) {
    let (sin, cos) = degrees.to_radians().sin_cos();
    let uphill = DVec3::new(0.6, 0.0, 0.8);
    let n = DVec3::Y * cos - uphill * sin;
    let down = -(uphill * cos + DVec3::Y * sin);
    (n, down)
}

/// A sphere resting on the slope at distance `along` down from the origin.
fn resting_ball(w: &mut World, degrees: f64, mu: (f64, f64), e: f64) -> ParticleId {
    let (n, down) = frame(degrees);
    let r = 0.05;
    w.add_particle(
        ParticleDef::new(0.2)
            .with_radius(r)
            .with_friction(mu.0, mu.1)
            .with_restitution(e)
            .at(down * 0.3 + n * r),
    )
    .unwrap()
}

#[test]
fn a_sphere_below_the_friction_angle_stays_put_for_a_minute() {
    // tan 20° = 0.364 < μs = 0.5: static friction holds it.
    for kind in [
        IntegratorKind::Rk4,
        IntegratorKind::Euler,
        IntegratorKind::Implicit,
    ] {
        let mut w = world_on(slope(20.0), kind);
        let p = resting_ball(&mut w, 20.0, (0.5, 0.3), 0.5);
        let start = w.position(p);
        for _ in 0..60_000 {
            w.step(1e-3).unwrap();
        }
        let drift = (w.position(p) - start).length();
        println!("{kind}: drift over 60 s {drift:.3e} m");
        assert!(drift < 1e-3, "{kind}: drifted {drift} m");
    }
}

#[test]
fn above_the_friction_angle_it_slides_at_g_sin_minus_mu_k_cos() {
    // tan 30° = 0.577 > μs = 0.5: it breaks away and slides with kinetic
    // friction μk N = μk m g cos θ against it.
    let (degrees, mu_k) = (30.0f64, 0.3);
    let (sin, cos) = degrees.to_radians().sin_cos();
    let expected = G * (sin - mu_k * cos);
    for kind in [
        IntegratorKind::Rk4,
        IntegratorKind::Euler,
        IntegratorKind::Midpoint,
    ] {
        let mut w = world_on(slope(degrees), kind);
        let p = resting_ball(&mut w, degrees, (0.5, mu_k), 0.5);
        let (n, down) = frame(degrees);
        let t = 1.0;
        for _ in 0..1000 {
            w.step(1e-3).unwrap();
        }
        let v = w.velocity(p);
        let a = v.dot(down) / t;
        println!("{kind}: a = {a:.12} vs g(sin θ − μk cos θ) = {expected:.12}");
        assert!(
            (a - expected).abs() < 1e-9 * expected,
            "{kind}: {a} vs {expected}"
        );
        // Along the slope, neither off it nor into it.
        assert!(v.dot(n).abs() < 1e-9 && (v - down * v.dot(down)).length() < 1e-9);
        let gap = w.clearance(p);
        assert!(gap.abs() < 1e-6, "{kind}: {gap} m off the slope");
    }
}

/// The normal-energy apexes after each bounce on the slope: the sphere's
/// normal motion is a bounce under gravity's normal part g cos θ.
#[test]
fn a_bounce_on_a_slope_keeps_e_squared_of_the_normal_energy() {
    let (degrees, e) = (25.0f64, 0.7);
    let (n, _) = frame(degrees);
    let gn = G * degrees.to_radians().cos();
    for kind in [IntegratorKind::Rk4, IntegratorKind::Midpoint] {
        let mut w = world_on(slope(degrees), kind);
        let r = 0.05;
        // Dropped along the normal from 0.5 m off the slope, frictionless.
        let p = w
            .add_particle(
                ParticleDef::new(0.2)
                    .with_radius(r)
                    .with_friction(0.0, 0.0)
                    .with_restitution(e)
                    .at(n * (0.5 + r)),
            )
            .unwrap();
        let mut apexes = Vec::new();
        for _ in 0..4000 {
            w.step(5e-4).unwrap();
            let bounced = !w.event::<FloorCollision>().unwrap().collisions().is_empty();
            if bounced {
                let vn = w.velocity(p).dot(n);
                apexes.push(w.clearance(p) + vn * vn / (2.0 * gn));
            }
        }
        println!("{kind}: apexes {apexes:?}");
        assert!(apexes.len() >= 4, "{kind}: {apexes:?}");
        let mut previous = 0.5;
        for &h in apexes.iter().take(4) {
            let ratio = h / previous;
            // Handled up to one envelope (1 cm at 9 m/s... here ≤ 3 mm of
            // travel in a step) below: a percent of these heights.
            assert!((ratio - e * e).abs() < 0.02, "{kind}: ratio {ratio}");
            previous = h;
        }
    }
}

fn rough(seed: u64, roughness: f64) -> Terrain {
    let (nx, nz) = (24, 24);
    let mut state = seed;
    let heights = (0..nx * nz)
        .map(|_| {
            // splitmix64
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            roughness * (2.0 * (z >> 11) as f64 / (1u64 << 53) as f64 - 1.0)
        })
        .collect();
    Terrain::Heightfield(Heightfield::new(
        DVec2::new(-1.2, -1.2),
        0.1,
        nx,
        nz,
        heights,
    ))
}

#[test]
fn no_impact_on_rough_ground_or_steps_adds_energy() {
    let steps = Terrain::Steps(Steps {
        direction: DVec3::X,
        start: -0.2,
        height: -0.04,
        depth: 0.15,
        count: 6,
    });
    for (label, terrain) in [("rough", rough(7, 0.03)), ("steps", steps)] {
        for e in [1.0, 0.6] {
            let mut w = world_on(terrain.clone(), IntegratorKind::Rk4);
            // Frictionless spheres thrown across: gravity is the only
            // force in flight, which RK4 integrates exactly, so the energy
            // can only fall at impacts.
            for k in 0..6 {
                let k = f64::from(k);
                w.add_particle(
                    ParticleDef::new(0.1)
                        .with_radius(0.02 + 0.01 * k)
                        .with_friction(0.0, 0.0)
                        .with_restitution(e)
                        .at(DVec3::new(-0.5 + 0.15 * k, 0.3 + 0.1 * k, 0.3 - 0.1 * k))
                        .with_velocity(DVec3::new(1.5 - 0.4 * k, -2.0, 0.7 * k - 1.0)),
                )
                .unwrap();
            }
            let start = w.energy().total();
            let own = |w: &World, i: usize| {
                let p = ParticleId::from_index(i);
                0.1 * (0.5 * w.velocity(p).length_squared() + G * w.position(p).y)
            };
            let (mut impacts, mut sliding) = (0, 0.0f64);
            for _ in 0..4000 {
                let before: Vec<f64> = (0..w.len()).map(|i| own(&w, i)).collect();
                w.step(5e-4).unwrap();
                let mut hit = vec![false; w.len()];
                for c in w.event::<FloorCollision>().unwrap().collisions() {
                    hit[c.particle.index()] = true;
                    impacts += 1;
                }
                for (i, &was) in before.iter().enumerate() {
                    let now = own(&w, i);
                    if hit[i] {
                        assert!(
                            now <= was + 1e-12 * was.abs(),
                            "{label}, e = {e}: an impact took sphere {i}'s energy {was} → {now} J at t = {}",
                            w.time()
                        );
                    } else {
                        // Sliding across the ground's facets, the contact
                        // force's normal turns within a step: record what
                        // that adds.
                        sliding = sliding.max(now - was);
                    }
                }
            }
            let energy = w.energy().total();
            println!("{label}, e = {e}: largest rise in a step without an impact {sliding:.2e} J");
            // Sliding from facet to facet, the contact force of the face
            // it leaves acts in some of RK4's stages and not in others: an
            // error of the order of a stage's impulse m g h / 6 along the
            // normal times the (mm/s) normal speeds there, far under 1 µJ.
            assert!(
                sliding < 1e-6,
                "{label}, e = {e}: sliding added {sliding} J"
            );
            assert!(
                energy <= start + 1e-12 * start,
                "{label}, e = {e}: {start} → {energy} J"
            );
            println!("{label}, e = {e}: {impacts} impacts, energy {start:.6} → {energy:.6} J");
            assert!(impacts >= 10, "{label}: only {impacts} impacts");
        }
    }
}

#[test]
fn no_sphere_tunnels_through_terrain_at_creature_speeds() {
    // Creatures reach a few m/s; fire spheres at up to 20 m/s into rough
    // ground, a riser and a steep slope, at a 2 ms step (20 m/s × 2 ms =
    // 4 cm of travel: four times the 1 cm envelope, so most impacts are
    // located by backtracking).
    let riser = Terrain::Steps(Steps {
        direction: DVec3::X,
        start: 0.5,
        height: 0.3,
        depth: 0.5,
        count: 2,
    });
    for (label, terrain) in [
        ("rough", rough(3, 0.05)),
        ("riser", riser),
        ("slope", slope(40.0)),
    ] {
        for speed in [2.0, 8.0, 20.0] {
            let mut w = world_on(terrain.clone(), IntegratorKind::Rk4);
            let mut ids = Vec::new();
            for k in 0..4 {
                let k = f64::from(k);
                let dir = DVec3::new(1.0, -0.5 - 0.3 * k, 0.2 * k - 0.3).normalize();
                ids.push(
                    w.add_particle(
                        ParticleDef::new(0.1)
                            .with_radius(0.03)
                            .with_restitution(0.5)
                            .at(DVec3::new(0.1 * k, 0.35 + 0.05 * k, 0.0))
                            .with_velocity(dir * speed),
                    )
                    .unwrap(),
                );
            }
            for _ in 0..500 {
                w.step(2e-3).unwrap();
                for &p in &ids {
                    let gap = w.clearance(p);
                    assert!(
                        gap >= -1e-9,
                        "{label} at {speed} m/s: sphere {} is {gap} m inside at t = {}",
                        p.index(),
                        w.time()
                    );
                }
            }
            // Nothing ended up under the ground's surface.
            for &p in &ids {
                let x = w.position(p);
                let ground = w.terrain().unwrap().height(x.x, x.z);
                assert!(x.y > ground, "{label} at {speed} m/s: {x} below {ground}");
            }
        }
    }
}

#[test]
fn a_sphere_rolling_into_a_riser_bounces_back_and_one_off_an_edge_falls_to_the_next_tread() {
    let stairs = |height: f64| {
        Terrain::Steps(Steps {
            direction: DVec3::X,
            start: 0.5,
            height,
            depth: 0.4,
            count: 3,
        })
    };
    // Up: a 10 cm riser stops a 3 cm sphere rolling at 1 m/s.
    let mut w = world_on(stairs(0.1), IntegratorKind::Rk4);
    let p = w
        .add_particle(
            ParticleDef::new(0.1)
                .with_radius(0.03)
                .with_friction(0.0, 0.0)
                .with_restitution(0.8)
                .at(DVec3::new(0.0, 0.03, 0.0))
                .with_velocity(DVec3::new(1.0, 0.0, 0.0)),
        )
        .unwrap();
    for _ in 0..2000 {
        w.step(5e-4).unwrap();
    }
    let (x, v) = (w.position(p), w.velocity(p));
    println!("riser: x = {x}, v = {v}");
    // 0.8 m/s back, less what lifting it back onto the tread costs (it
    // fell a fraction of a µm in the rest of the impact's step).
    assert!(x.x < 0.47 && (v.x + 0.8).abs() < 1e-5, "{x} {v}");
    // Down: slid off the first tread's edge at 1 m/s, it lands on a lower
    // tread where free fall from the edge puts it.
    let mut w = world_on(stairs(-0.1), IntegratorKind::Rk4);
    let p = w
        .add_particle(
            ParticleDef::new(0.1)
                .with_radius(0.03)
                .with_friction(0.0, 0.0)
                .with_restitution(0.0)
                .at(DVec3::new(0.4, 0.03, 0.0))
                .with_velocity(DVec3::new(1.0, 0.0, 0.0)),
        )
        .unwrap();
    let mut landed = None;
    for _ in 0..2000 {
        w.step(5e-4).unwrap();
        let c = w.event::<FloorCollision>().unwrap().collisions();
        if landed.is_none() && !c.is_empty() {
            landed = Some(w.position(p));
        }
    }
    let at = landed.expect("it lands");
    // It leaves the edge at x = 0.5 (its centre passes the edge; it rolls
    // round the corner only while its centre is within r of it, a few mm
    // of drop) and falls 0.1 m: √(2·0.1/g) = 0.143 s, 0.143 m on.
    let fall = (2.0 * 0.1 / G).sqrt();
    println!(
        "edge: landed at {at}, free fall predicts x ≈ {}",
        0.5 + fall
    );
    assert!((at.y - (-0.1 + 0.03)).abs() < 1e-6, "{at}");
    assert!((at.x - (0.5 + fall)).abs() < 0.02, "{at}");
}

#[test]
fn a_level_slope_is_the_flat_floor() {
    // The same bounces and slide on a 0° slope as on the plane y = 0.
    let run = |terrain: Terrain| {
        let mut w = world_on(terrain, IntegratorKind::Rk4);
        let p = w
            .add_particle(
                ParticleDef::new(0.1)
                    .with_radius(0.05)
                    .with_friction(0.6, 0.4)
                    .with_restitution(0.6)
                    .at(DVec3::new(0.0, 0.6, 0.0))
                    .with_velocity(DVec3::new(1.5, 0.0, -0.5)),
            )
            .unwrap();
        for _ in 0..3000 {
            w.step(1e-3).unwrap();
        }
        (w.position(p), w.velocity(p))
    };
    let (flat, level) = (run(Terrain::Flat), run(slope(0.0)));
    println!("flat {flat:?}\nlevel {level:?}");
    assert!((flat.0 - level.0).length() < 1e-9 && (flat.1 - level.1).length() < 1e-9);
    // It bounced, slid and stopped.
    assert!(flat.1.length() < 1e-12 && flat.0.x > 0.1);
}

/// The `feet` measure's count: the moving spheres within a tolerance of
/// the ground, on the flat floor (its own loop) and on a slope (each
/// particle's clearance), by the geometry. A fixed sphere on the ground
/// is no foot.
#[test]
fn the_spheres_on_the_ground_are_counted_by_their_clearance() {
    let r = 0.05;
    // Heights of the spheres' lowest points above the ground.
    let gaps = [-0.01, 0.0, 0.004, 0.0099, 0.0101, 0.02, 0.5];
    for (terrain, degrees) in [(Terrain::Flat, 0.0), (slope(20.0), 20.0)] {
        let mut w = world_on(terrain, IntegratorKind::Symplectic);
        let (n, _) = frame(degrees);
        for (k, &gap) in gaps.iter().enumerate() {
            // Along the normal from a point of the ground (the slope passes
            // through the origin), spread across it.
            let across = DVec3::new(0.3 * k as f64, 0.0, -0.2 * k as f64);
            let on = across - n * n.dot(across);
            let on = if degrees == 0.0 { across } else { on };
            w.add_particle(ParticleDef::new(0.1).with_radius(r).at(on + n * (r + gap)))
                .unwrap();
        }
        let fixed = w
            .add_particle(ParticleDef::new(0.1).with_radius(r).at(n * r).fixed())
            .unwrap();
        assert!(w.clearance(fixed).abs() < 1e-12);
        for (tolerance, want) in [(0.01, 4), (0.002, 2), (0.03, 6), (-0.02, 0)] {
            assert_eq!(
                w.count_on_ground(tolerance),
                want,
                "{degrees}°, tolerance {tolerance}"
            );
        }
    }
}

/// `touches_ground` gives `clearance(p) <= tolerance`'s answer on every
/// terrain, though off the flat floor it skips the search for spheres
/// certainly too far: spheres from inside the ground to 2 m above a
/// heightfield (gentle and steep), steps and a slope, each asked at its
/// own clearance and one and two ulps either side, and at tolerances from
/// 0 to 1 m; radii from 0 (a point) to 0.2 m.
#[test]
fn touching_the_ground_is_the_clearance_within_the_tolerance() {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let field = |relief: f64, uniform: &mut dyn FnMut() -> f64| {
        let heights = (0..12 * 9).map(|_| relief * (uniform() - 0.5)).collect();
        Terrain::Heightfield(Heightfield::new(
            DVec2::new(-0.6, -0.4),
            0.1,
            12,
            9,
            heights,
        ))
    };
    let steps = Terrain::Steps(Steps {
        direction: DVec3::X,
        start: 0.0,
        height: 0.05,
        depth: 0.2,
        count: 4,
    });
    let terrains = [
        field(0.03, &mut uniform),
        field(0.5, &mut uniform),
        steps,
        slope(25.0),
    ];
    let (mut asked, mut touching) = (0, 0);
    for terrain in terrains {
        let mut w = world_on(terrain.clone(), IntegratorKind::Symplectic);
        let ids: Vec<ParticleId> = (0..400)
            .map(|k| {
                let r = [0.0, 0.01, 0.05, 0.2][k % 4];
                let (x, z) = (1.6 * uniform() - 0.8, 1.2 * uniform() - 0.6);
                let y = terrain.height(x, z) + 2.0 * uniform() * uniform() - 0.05;
                w.add_particle(ParticleDef::new(0.1).with_radius(r).at(DVec3::new(x, y, z)))
                    .unwrap()
            })
            .collect();
        for &p in &ids {
            let c = w.clearance(p);
            let mut tolerances = vec![-0.01, 0.0, 1e-3, 0.01, 0.1, 1.0];
            if c.is_finite() && c > 0.0 {
                let (down, up) = (
                    f64::from_bits(c.to_bits() - 1),
                    f64::from_bits(c.to_bits() + 1),
                );
                tolerances.extend([c, down, up, f64::from_bits(down.to_bits() - 1)]);
            }
            for tolerance in tolerances {
                let touches = w.touches_ground(p, tolerance);
                assert_eq!(
                    touches,
                    c <= tolerance,
                    "particle {p:?} at {:?} r {}: {c} against {tolerance}, {terrain:?}",
                    w.position(p),
                    w.particles().radius[p.index()]
                );
                asked += 1;
                touching += usize::from(touches);
            }
        }
    }
    // Both answers were given often.
    assert!(
        touching > asked / 5 && touching < asked * 4 / 5,
        "{touching} of {asked}"
    );
}
