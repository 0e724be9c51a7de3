//! The C step (kernel/step.h, compiled for this CPU) against the engine,
//! bit for bit: every particle's position and velocity after every step
//! count checked, for each integrator the C covers, on a hanging chain and
//! on batches of random bodies of mixed sizes (2 to 40 particles: both of
//! the engine's paths, below and above its 16-particle "small world"
//! loop) of springs, angle joints and torque joints, with and without
//! gravity, in water and air or not, on the floor, pushed, and touching
//! each other through soft contact; and pulled together by n-body gravity.

use animats_engine::{DVec3, FloorDef, FluidMedium, IntegratorKind, ParticleDef, SpringDef, World};
use animats_gpu::{Batch, Layout};

use animats_creatures::random::Random;
use animats_gpu::bodies::{random_body, random_vec};

const INTEGRATORS: [IntegratorKind; 4] = [
    IntegratorKind::Euler,
    IntegratorKind::Midpoint,
    IntegratorKind::Rk4,
    IntegratorKind::Symplectic,
];

/// Steps `worlds` with the engine and a batch of them with the C, `steps`
/// at a time, `rounds` times, and asserts every coordinate equal.
fn assert_same(worlds: &mut [World], dt: f64, steps: u64, rounds: usize, what: &str) {
    let refs: Vec<&World> = worlds.iter().collect();
    let mut batch = Batch::pack(&refs, dt).unwrap();
    // The same creatures with their state kept in the batch's arrays
    // rather than in each thread's own (Layout::Local, the default, for
    // creatures of at most 32 particles): the same bits.
    let mut in_batch = batch.clone();
    in_batch.set_layout(Layout::Batch);
    // A world whose state stops being finite stays at its last finite
    // state; the C must stop its creature at the same step, in the same
    // state.
    let mut failed: Vec<Option<u64>> = vec![None; worlds.len()];
    for round in 1..=rounds {
        for (w, failed) in worlds.iter_mut().zip(&mut failed) {
            for s in 0..steps {
                if failed.is_some() {
                    break;
                }
                if w.step(dt).is_err() {
                    *failed = Some((round as u64 - 1) * steps + s + 1);
                }
            }
        }
        batch.run_cpu(steps);
        in_batch.run_cpu(steps);
        if round == rounds && failed.iter().any(Option::is_some) {
            eprintln!(
                "{what}: blew up at steps {:?}",
                failed.iter().flatten().collect::<Vec<_>>()
            );
        }
        for (c, w) in worlds.iter().enumerate() {
            assert_eq!(batch.failed(c), failed[c], "{what}: creature {c}'s blow-up");
            assert_eq!(
                in_batch.failed(c),
                failed[c],
                "{what}: creature {c}'s blow-up"
            );
            for i in 0..w.len() {
                let as_bits = |s: Option<(DVec3, DVec3)>| {
                    s.map(|(x, v)| [x, v].map(|a| a.to_array().map(f64::to_bits)))
                };
                assert_eq!(
                    as_bits(batch.state(c, i)),
                    as_bits(in_batch.state(c, i)),
                    "{what}: creature {c}, particle {i}: the layouts differ"
                );
                let (x, v) = batch.state(c, i).unwrap();
                let (ex, ev) = (w.state().pos[i], w.state().vel[i]);
                let bits = |a: DVec3| a.to_array().map(f64::to_bits);
                assert!(
                    bits(x) == bits(ex) && bits(v) == bits(ev),
                    "{what}: creature {c}, particle {i}, after {} steps: C x = {x}, v = {v}; engine x = {ex}, v = {ev}",
                    round as u64 * steps
                );
            }
        }
    }
}

/// Penalty contact between every pair of `w`'s spheres that no spring
/// joins (k = 5000 N/m, c = 2 N s/m).
fn soft_contact(w: &World) -> Box<animats_engine::SoftContact> {
    let ids: Vec<_> = w.particle_ids().collect();
    Box::new(animats_engine::SoftContact::new(5000.0, 2.0, &ids, &w.joined_pairs()).unwrap())
}

/// Steps each of `plain` (the same bodies as `worlds` without a force)
/// 1200 steps of 0.5 ms, as far as it stays finite, and counts the bodies
/// that end elsewhere than their twins in `worlds`.
fn ending_elsewhere(worlds: &[World], plain: &mut [World]) -> usize {
    for w in plain.iter_mut() {
        for _ in 0..1200 {
            if w.step(5e-4).is_err() {
                break;
            }
        }
    }
    worlds
        .iter()
        .zip(plain.iter())
        .filter(|(a, b)| a.state().pos != b.state().pos)
        .count()
}

#[test]
fn a_hanging_chain_is_the_engine_s_to_the_bit_under_every_integrator() {
    for kind in INTEGRATORS {
        let mut w = World::new();
        w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
        w.set_integrator(kind);
        let ids: Vec<_> = (0..8)
            .map(|i| {
                w.add_particle(ParticleDef::new(0.5).at(DVec3::new(0.3 * i as f64, 2.0, 0.0)))
                    .unwrap()
            })
            .collect();
        for pair in ids.windows(2) {
            w.add_spring(SpringDef::new(pair[0], pair[1], 200.0, 0.5).with_rest_length(0.3))
                .unwrap();
        }
        assert_same(&mut [w], 1e-3, 500, 4, &format!("chain, {kind:?}"));
    }
}

#[test]
fn a_body_with_more_springs_than_a_thread_holds_is_the_engine_s_to_the_bit() {
    // 20 particles, every pair joined: 190 springs, more than the 128 a
    // thread holds in arrays of its own (it works in the batch's), beside
    // the same body with 120 of them (held).
    let body = |springs: usize| {
        let mut w = World::new();
        w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
        w.set_integrator(IntegratorKind::Rk4);
        let ids: Vec<_> = (0..20)
            .map(|i| {
                let at = DVec3::new(
                    0.1 * (i % 5) as f64,
                    1.0 + 0.1 * (i / 5) as f64,
                    0.01 * i as f64,
                );
                w.add_particle(ParticleDef::new(0.1).at(at)).unwrap()
            })
            .collect();
        let pairs = (0..20).flat_map(|i| (i + 1..20).map(move |j| (i, j)));
        for (i, j) in pairs.take(springs) {
            w.add_spring(SpringDef::new(ids[i], ids[j], 50.0, 0.1))
                .unwrap();
        }
        w.add_floor(FloorDef::default()).unwrap();
        w
    };
    assert_same(&mut [body(190), body(120)], 1e-3, 300, 2, "dense bodies");
}

#[test]
fn batches_of_random_bodies_of_mixed_sizes_are_the_engine_s_to_the_bit() {
    let mut rng = Random::for_entry(42, 0);
    for kind in INTEGRATORS {
        for (gravity, joints, water) in [
            (true, true, true),
            (true, true, false),
            (false, true, false),
            (true, false, false),
        ] {
            let mut worlds: Vec<World> = (0..24)
                .map(|_| {
                    let n = 2 + (rng.uniform() * 39.0) as usize;
                    let mut w = random_body(&mut rng, n, gravity, joints, kind).unwrap();
                    if water {
                        w.add_fluid(FluidMedium::water()).unwrap();
                        w.add_fluid(FluidMedium::air()).unwrap();
                    }
                    w
                })
                .collect();
            let sizes: Vec<usize> = worlds.iter().map(World::len).collect();
            assert!(sizes.iter().any(|&n| n < 16) && sizes.iter().any(|&n| n >= 16));
            assert_same(
                &mut worlds,
                5e-4,
                400,
                3,
                &format!("random bodies {sizes:?}, {kind:?}, gravity {gravity}, joints {joints}, water {water}"),
            );
        }
    }
}

/// Bodies dropped onto the floor from up to 2.2 m, pushed by constant
/// forces: bounces (located by backtracking when a sphere passes the
/// envelope inside a step), rest, the contact force's reaction and
/// friction.
#[test]
fn bodies_falling_onto_the_floor_are_the_engine_s_to_the_bit() {
    let mut rng = Random::for_entry(9, 0);
    for kind in INTEGRATORS {
        for (contact, air) in [(true, false), (true, true), (false, false)] {
            let mut worlds: Vec<World> = (0..24)
                .map(|k| {
                    let n = 2 + (rng.uniform() * 39.0) as usize;
                    let mut w = random_body(&mut rng, n, true, k % 2 == 0, kind).unwrap();
                    for p in w.particle_ids().collect::<Vec<_>>() {
                        let x = w.position(p) + DVec3::new(0.0, 1.2, 0.0);
                        w.set_position(p, x).unwrap();
                    }
                    let floor = FloorDef {
                        contact,
                        ..FloorDef::default()
                    };
                    w.add_floor(floor).unwrap();
                    if air {
                        w.add_fluid(FluidMedium::air()).unwrap();
                    }
                    // A wind on every other particle, and a second push on
                    // the first (the same particle twice, in order).
                    let ids: Vec<_> = w.particle_ids().collect();
                    let some: Vec<_> = ids.iter().copied().step_by(2).collect();
                    w.add_constant_force(some, random_vec(&mut rng, 3.0))
                        .unwrap();
                    w.add_constant_force(vec![ids[0]], random_vec(&mut rng, 5.0))
                        .unwrap();
                    w
                })
                .collect();
            assert_same(
                &mut worlds,
                1e-3,
                500,
                4,
                &format!("bodies on the floor, {kind:?}, contact {contact}, air {air}"),
            );
            let backtracked: u64 = worlds.iter().map(|w| w.stats().backtracks).sum();
            let down = worlds
                .iter()
                .filter(|w| w.state().pos.iter().any(|x| x.y < 0.21))
                .count();
            eprintln!("{kind:?}, contact {contact}, air {air}: {backtracked} backtracks; {down} of 24 bodies down");
            assert!(down > 12, "{kind:?}: only {down} bodies reached the floor");
        }
    }
}

/// Bodies dropped onto terrain (terrain.rs): a slope rising along a random
/// heading, a flight of steps up (and, for half the batches, down) along
/// another, and a heightfield of random heights whose edge the bodies
/// cross (where its heights go on), with and without the floor's contact
/// force; each batch shares one ground, as a batch shares one floor. The
/// same bodies on the flat floor end elsewhere: the ground's shape is
/// felt.
#[test]
fn bodies_falling_onto_terrain_are_the_engine_s_to_the_bit() {
    use animats_engine::{Heightfield, Slope, Steps, Terrain};
    let mut rng = Random::for_entry(17, 0);
    let heading = |rng: &mut Random| {
        let a = rng.between(0.0, std::f64::consts::TAU);
        DVec3::new(
            animats_engine::math::cos(a),
            0.0,
            animats_engine::math::sin(a),
        )
    };
    for (b, kind) in INTEGRATORS.into_iter().enumerate() {
        let terrains = [
            Terrain::Slope(Slope {
                angle: rng.between(0.1, 0.5),
                uphill: heading(&mut rng),
            }),
            Terrain::Steps(Steps {
                direction: heading(&mut rng),
                start: rng.between(-0.8, 0.0),
                height: if b % 2 == 0 { 0.08 } else { -0.08 },
                depth: rng.between(0.1, 0.3),
                count: 8,
            }),
            Terrain::Heightfield(Heightfield::new(
                animats_engine::DVec2::new(-1.5, -1.5),
                0.1,
                21,
                23,
                (0..21 * 23).map(|_| rng.between(-0.15, 0.15)).collect(),
            )),
        ];
        for (t, (ground, terrain)) in ["slope", "steps", "heightfield"]
            .into_iter()
            .zip(terrains)
            .enumerate()
        {
            // Each ground with and without the contact force, each under two
            // integrators (CI's time: the flat floor's test has every pair).
            {
                let contact = (b + t) % 2 == 0;
                let floor = FloorDef {
                    contact,
                    terrain: terrain.clone(),
                    ..FloorDef::default()
                };
                let mut flat = Vec::new();
                let mut worlds: Vec<World> = (0..8)
                    .map(|k| {
                        let n = 2 + (rng.uniform() * 30.0) as usize;
                        let mut w = random_body(&mut rng, n, true, k % 2 == 0, kind).unwrap();
                        for p in w.particle_ids().collect::<Vec<_>>() {
                            let x = w.position(p) + DVec3::new(0.0, 2.0, 0.0);
                            w.set_position(p, x).unwrap();
                        }
                        let mut on_flat = w.clone();
                        on_flat.add_floor(FloorDef::default()).unwrap();
                        flat.push(on_flat);
                        w.add_floor(floor.clone()).unwrap();
                        w
                    })
                    .collect();
                let what = format!("bodies on a {ground}, {kind:?}, contact {contact}");
                assert_same(&mut worlds, 1e-3, 400, 4, &what);
                let backtracked: u64 = worlds.iter().map(|w| w.stats().backtracks).sum();
                let touching = worlds
                    .iter()
                    .filter(|w| w.particle_ids().any(|p| w.clearance(p) < 0.05))
                    .count();
                for w in flat.iter_mut() {
                    for _ in 0..1600 {
                        if w.step(1e-3).is_err() {
                            break;
                        }
                    }
                }
                let elsewhere = worlds
                    .iter()
                    .zip(&flat)
                    .filter(|(a, b)| a.state().pos != b.state().pos)
                    .count();
                eprintln!("{what}: {backtracked} backtracks, {touching} of 8 within 5 cm of the ground, {elsewhere} of 8 elsewhere on the flat floor");
                assert!(
                    touching >= 4,
                    "{what}: only {touching} bodies near the ground"
                );
                assert!(
                    elsewhere == 8,
                    "{what}: {elsewhere} of 8 bodies felt the terrain"
                );
                assert!(backtracked > 0, "{what}: no collision was located");
            }
        }
    }
}

/// Particles that start in the ground or exactly on it, where the
/// terrain's nearest point (`Terrain::probe`, `an_probe`) takes the paths
/// a body dropped from above never takes: inside a flight of steps (up
/// and down) or under a heightfield, the normal turned to face out from
/// below; exactly on a riser's face (no distance: the riser's own
/// normal); exactly on a heightfield's vertex (the face's normal). Random
/// bodies centred on the surface (about half their particles in the
/// ground), and bodies of two particles put on a riser's face and on a
/// vertex, with and without the contact force, under symplectic Euler
/// and RK4.
#[test]
fn particles_starting_in_or_on_the_terrain_are_the_engine_s_to_the_bit() {
    use animats_engine::{Heightfield, Steps, Terrain};
    let mut rng = Random::for_entry(23, 0);
    let steps = |height: f64| {
        Terrain::Steps(Steps {
            direction: DVec3::X,
            start: -0.25,
            height,
            depth: 0.125,
            count: 8,
        })
    };
    let field = Terrain::Heightfield(Heightfield::new(
        animats_engine::DVec2::new(-1.5, -1.5),
        0.125,
        25,
        25,
        (0..25 * 25).map(|_| rng.between(-0.15, 0.15)).collect(),
    ));
    for (t, (ground, terrain)) in [
        ("steps up", steps(0.08)),
        ("steps down", steps(-0.08)),
        ("heightfield", field),
    ]
    .into_iter()
    .enumerate()
    {
        for (b, kind) in [IntegratorKind::Symplectic, IntegratorKind::Rk4]
            .into_iter()
            .enumerate()
        {
            let contact = (b + t) % 2 == 0;
            let floor = FloorDef {
                contact,
                terrain: terrain.clone(),
                ..FloorDef::default()
            };
            let mut worlds: Vec<World> = (0..6)
                .map(|k| {
                    let n = 2 + (rng.uniform() * 20.0) as usize;
                    let mut w = random_body(&mut rng, n, true, k % 2 == 0, kind).unwrap();
                    let ids: Vec<_> = w.particle_ids().collect();
                    let centre = ids.iter().map(|&p| w.position(p)).sum::<DVec3>() / n as f64;
                    let at = DVec3::new(rng.between(-0.2, 0.6), 0.0, rng.between(-0.5, 0.5));
                    let lift = terrain.height(at.x, at.z) - centre.y;
                    for &p in &ids {
                        let x = w.position(p) - DVec3::new(centre.x, 0.0, centre.z) + at;
                        w.set_position(p, x + DVec3::new(0.0, lift, 0.0)).unwrap();
                    }
                    w.add_floor(floor.clone()).unwrap();
                    w
                })
                .collect();
            // Two particles joined by a spring, the first exactly on the
            // third riser's face (halfway up it) or on a vertex.
            let mut pair = World::new();
            pair.set_gravity(DVec3::new(0.0, -9.8, 0.0));
            pair.set_integrator(kind);
            let on = match &terrain {
                Terrain::Steps(s) => DVec3::new(s.start + 2.0 * s.depth, 2.5 * s.height, 0.0),
                _ => DVec3::new(-0.25, terrain.height(-0.25, 0.5), 0.5),
            };
            let p0 = pair
                .add_particle(ParticleDef::new(0.2).at(on).with_radius(0.02))
                .unwrap();
            let p1 = pair
                .add_particle(ParticleDef::new(0.3).at(on + DVec3::new(0.05, 0.3, 0.02)))
                .unwrap();
            pair.add_spring(SpringDef::new(p0, p1, 400.0, 2.0)).unwrap();
            pair.add_floor(floor.clone()).unwrap();
            let (off, _) = terrain.probe(on, 1.0).unwrap();
            assert!(off.abs() < 1e-12, "{ground}: the particle is {off} m off");
            worlds.push(pair);
            // A particle far past the field's edge, falling onto its flat
            // extension: at 10¹⁸ m its cell's index lies past 2⁶² cells,
            // held there (it saturated, and the next cell's overflowed).
            let mut far = World::new();
            far.set_gravity(DVec3::new(0.0, -9.8, 0.0));
            far.set_integrator(kind);
            let x = 1e18;
            far.add_particle(
                ParticleDef::new(0.2)
                    .at(DVec3::new(x, terrain.height(x, 0.5) + 0.05, 0.5))
                    .with_radius(0.02),
            )
            .unwrap();
            far.add_floor(floor.clone()).unwrap();
            worlds.push(far);
            let inside = worlds
                .iter()
                .filter(|w| w.particle_ids().any(|p| w.clearance(p) < -0.01))
                .count();
            assert!(
                inside >= 4,
                "{ground}: only {inside} of 8 start in the ground"
            );
            let what = format!("particles in and on {ground}, {kind:?}, contact {contact}");
            assert_same(&mut worlds, 1e-3, 200, 2, &what);
        }
    }
}

/// A fixed particle (no inverse mass) in the ground, a body tethered to
/// it by springs falling around it: the floor's check, handling and
/// contact force leave the fixed one alone, on the flat floor and on
/// terrain (`an_floor_check`, `an_terrain_check`, `an_terrain_handle`,
/// `an_terrain_contact`, each `w == 0`), with and without the contact
/// force, and with gravity off (the bodies thrown at the ground), which
/// the terrain's handling reads; on the flat floor every other body held
/// in a vertical plane checked before the floor (`an_floor_note`).
#[test]
fn fixed_particles_in_the_ground_are_left_there_as_the_engine_leaves_them() {
    use animats_engine::{Heightfield, Steps, Terrain};
    let mut rng = Random::for_entry(29, 0);
    let grounds = [
        ("flat floor", Terrain::Flat),
        (
            "steps",
            Terrain::Steps(Steps {
                direction: DVec3::new(0.6, 0.0, 0.8),
                start: -0.3,
                height: 0.07,
                depth: 0.2,
                count: 6,
            }),
        ),
        (
            "heightfield",
            Terrain::Heightfield(Heightfield::new(
                animats_engine::DVec2::new(-2.0, -2.0),
                0.2,
                21,
                21,
                (0..21 * 21).map(|_| rng.between(-0.1, 0.1)).collect(),
            )),
        ),
    ];
    for (t, (ground, terrain)) in grounds.into_iter().enumerate() {
        for (b, kind) in [IntegratorKind::Symplectic, IntegratorKind::Rk4]
            .into_iter()
            .enumerate()
        {
            for gravity in [true, false] {
                let contact = (b + t + usize::from(gravity)) % 2 == 0;
                let floor = FloorDef {
                    contact,
                    terrain: terrain.clone(),
                    ..FloorDef::default()
                };
                let mut worlds: Vec<World> = (0..6)
                    .map(|k| {
                        let mut w = World::new();
                        if gravity {
                            w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
                        }
                        w.set_integrator(kind);
                        let (x, z) = (rng.between(-0.5, 0.8), rng.between(-0.5, 0.5));
                        let r0 = rng.between(0.03, 0.1);
                        let at = DVec3::new(x, terrain.height(x, z) - 0.5 * r0, z);
                        let anchor = w
                            .add_particle(ParticleDef::new(1.0).with_radius(r0).at(at).fixed())
                            .unwrap();
                        let n = 2 + (rng.uniform() * 6.0) as usize;
                        let ids: Vec<_> = (0..n)
                            .map(|_| {
                                let up = DVec3::new(0.0, rng.between(0.1, 0.5), 0.0);
                                let def = ParticleDef::new(rng.between(0.1, 1.0))
                                    .with_radius(rng.between(0.02, 0.08))
                                    .at(at + up + random_vec(&mut rng, 0.4))
                                    .with_velocity(random_vec(&mut rng, 1.0) - DVec3::Y);
                                w.add_particle(def).unwrap()
                            })
                            .collect();
                        for (k, &p) in ids.iter().enumerate() {
                            for q in [anchor, ids[(k + 1) % n]] {
                                let def = SpringDef::new(
                                    p,
                                    q,
                                    rng.between(50.0, 300.0),
                                    rng.between(0.0, 1.0),
                                )
                                .with_rest_length(rng.between(0.2, 0.6));
                                w.add_spring(def).unwrap();
                            }
                        }
                        if terrain.is_flat() && k % 2 == 1 {
                            // Held in a vertical plane, checked before the
                            // floor: the floor handles what its check found.
                            let a = rng.between(0.0, std::f64::consts::TAU);
                            let normal = DVec3::new(
                                animats_engine::math::sin(a),
                                0.0,
                                animats_engine::math::cos(a),
                            );
                            w.add_event(Box::new(animats_engine::PlaneConstraint::new(
                                at,
                                normal,
                                ids.clone(),
                            )));
                        }
                        w.add_floor(floor.clone()).unwrap();
                        assert!(w.clearance(anchor) < 0.0, "{ground}: the anchor is not in");
                        w
                    })
                    .collect();
                let what = format!(
                    "tethered on the {ground}, {kind:?}, contact {contact}, gravity {gravity}"
                );
                assert_same(&mut worlds, 1e-3, 300, 4, &what);
                // Each body met the ground: a collision located, or resting
                // on it at the end.
                let met = worlds
                    .iter()
                    .filter(|w| {
                        w.stats().backtracks > 0
                            || w.particle_ids().skip(1).any(|p| w.clearance(p) < 0.01)
                    })
                    .count();
                // (Without gravity, thrown, most bounce off the contact
                // force's cushion or the ground and fly on.)
                let least = if gravity { 4 } else { 1 };
                assert!(
                    met >= least,
                    "{what}: only {met} of 6 bodies met the ground"
                );
            }
        }
    }
}

/// A creature that blows up in one launch stays where it stopped in the
/// next ones (`an_step_creature` returns at once), as the engine's world
/// stays at its last finite state, while the rest of its batch goes on:
/// two particles on a spring of 10 MN/m under explicit Euler at 1 ms (it
/// blows up within the first of four launches of 100 steps) beside the
/// same on a spring of 10 N/m.
#[test]
fn a_creature_that_blew_up_stays_stopped_in_later_launches() {
    let pair = |stiffness: f64| {
        let mut w = World::new();
        w.set_integrator(IntegratorKind::Euler);
        let a = w.add_particle(ParticleDef::new(0.01)).unwrap();
        let b = w
            .add_particle(ParticleDef::new(0.01).at(DVec3::new(0.12, 0.0, 0.0)))
            .unwrap();
        w.add_spring(SpringDef::new(a, b, stiffness, 0.0).with_rest_length(0.1))
            .unwrap();
        w
    };
    let mut worlds = vec![pair(1e7), pair(10.0)];
    assert_same(&mut worlds, 1e-3, 100, 4, "a blow-up, then more launches");
    let mut again = [pair(1e7), pair(10.0)];
    let first = (1..=100).find(|_| again[0].step(1e-3).is_err());
    assert!(first.is_some(), "no blow-up in the first launch");
    assert!((0..400).all(|_| again[1].step(1e-3).is_ok()));
}

/// Bodies held in planes (events/plane_constraint.rs, the roobot's planar
/// motion) falling onto the floor: half in a vertical plane at a random
/// heading (the roobot's), half in a plane slanted at random, which the
/// floor's handling and the plane's projection both move (their order, the
/// world's order of events, matters: half the worlds add the plane before
/// the floor), each holding every other particle of its body, and every
/// third world a second plane holding its first particle. Every step
/// leaves a plane by rounding, so every step projects.
#[test]
fn bodies_held_in_planes_are_the_engine_s_to_the_bit() {
    // Body k of a batch, held in its planes or (`held` false) free.
    let body = |kind, k: u64, held: bool| {
        let mut rng = Random::for_entry(13, k);
        let n = 2 + (rng.uniform() * 39.0) as usize;
        let mut w = random_body(&mut rng, n, true, k.is_multiple_of(2), kind).unwrap();
        let ids: Vec<_> = w.particle_ids().collect();
        for &p in &ids {
            let x = w.position(p) + DVec3::new(0.0, 1.2, 0.0);
            w.set_position(p, x).unwrap();
        }
        let normal = if k % 4 < 2 {
            let h = rng.between(0.0, std::f64::consts::TAU);
            DVec3::new(
                animats_engine::math::sin(h),
                0.0,
                animats_engine::math::cos(h),
            )
        } else {
            random_vec(&mut rng, 1.0)
        };
        let second = random_vec(&mut rng, 1.0);
        let floor_first = k.is_multiple_of(2);
        if floor_first {
            w.add_floor(FloorDef::default()).unwrap();
        }
        if held {
            w.add_event(Box::new(animats_engine::PlaneConstraint::new(
                w.position(ids[0]),
                normal,
                ids.iter().copied().step_by(2).collect(),
            )));
        }
        if !floor_first {
            w.add_floor(FloorDef::default()).unwrap();
        }
        if held && k.is_multiple_of(3) {
            w.add_event(Box::new(animats_engine::PlaneConstraint::new(
                DVec3::ZERO,
                second,
                vec![ids[0]],
            )));
        }
        w.add_fluid(FluidMedium::air()).unwrap();
        w
    };
    for kind in INTEGRATORS {
        let mut worlds: Vec<World> = (0..24).map(|k| body(kind, k, true)).collect();
        assert_same(&mut worlds, 1e-3, 500, 4, &format!("planes, {kind:?}"));
        // The planes matter: free, the same bodies end elsewhere.
        let elsewhere = (0..24)
            .filter(|&k| {
                let mut free = body(kind, k, false);
                for _ in 0..2000 {
                    if free.step(1e-3).is_err() {
                        break;
                    }
                }
                free.state().pos != worlds[k as usize].state().pos
            })
            .count();
        let backtracked: u64 = worlds.iter().map(|w| w.stats().backtracks).sum();
        eprintln!(
            "planes, {kind:?}: {backtracked} backtracks; {elsewhere} of 24 end elsewhere free"
        );
        assert_eq!(elsewhere, 24, "{kind:?}");
        assert!(backtracked > 0, "{kind:?}: no collision was located");
    }
}

/// Bodies whose spheres collide with each other through soft (penalty)
/// contact, every pair but those a spring joins, as an evolved body's
/// `[contacts] model = "penalty"` builds it, dropped onto the floor: the
/// C's contact forces are the engine's, pair by pair in its order.
#[test]
fn bodies_whose_spheres_touch_each_other_are_the_engine_s_to_the_bit() {
    let mut rng = Random::for_entry(17, 0);
    for kind in INTEGRATORS {
        let make = |rng: &mut Random, contact: bool| -> Vec<World> {
            (0..16)
                .map(|k| {
                    // Up to 40 spheres: the engine sweeps from 32 on.
                    let n = 2 + (rng.uniform() * 39.0) as usize;
                    let mut w = random_body(rng, n, true, k % 2 == 0, kind).unwrap();
                    w.add_floor(FloorDef::default()).unwrap();
                    if contact {
                        let soft = soft_contact(&w);
                        w.add_force(soft);
                    }
                    w
                })
                .collect()
        };
        let mut again = rng.clone();
        let mut worlds = make(&mut rng, true);
        let mut plain = make(&mut again, false);
        // The contacts matter: without them the bodies end elsewhere.
        let before: Vec<usize> = worlds.iter().map(World::len).collect();
        assert_same(
            &mut worlds,
            5e-4,
            400,
            3,
            &format!("touching bodies {before:?}, {kind:?}"),
        );
        let moved = ending_elsewhere(&worlds, &mut plain);
        eprintln!("{kind:?}: {moved} of 16 bodies end elsewhere without their contacts");
        assert!(
            moved >= 8,
            "{kind:?}: the contacts changed only {moved} bodies"
        );
    }
}

/// Spheres that collide with each other as the discrete event
/// (events/sphere_contact: `[contacts]`, the walker among its rocks): free
/// spheres of mixed sizes, masses, restitutions and frictions thrown at
/// each other above the floor, some fast enough to pass deeper than the
/// envelope inside a step (backtracked) or through another (the swept
/// test), some joined by springs (never colliding), some fixed, some with
/// one restitution for every contact, with a floor and without; and random
/// bodies among rocks. The C's pairs, passes and floor that holds spheres
/// up are the engine's, to the bit.
#[test]
fn spheres_colliding_as_events_are_the_engine_s_to_the_bit() {
    let mut rng = Random::for_entry(23, 0);
    for (kind, floor) in INTEGRATORS
        .into_iter()
        .flat_map(|k| [(k, true), (k, false)])
    {
        let make = |rng: &mut Random, contact: bool| -> Vec<World> {
            (0..24)
                .map(|k| {
                    let mut w = if k % 3 == 2 {
                        // A body among rocks, as walker_rocks.toml.
                        let n = 2 + (rng.uniform() * 14.0) as usize;
                        let mut w = random_body(rng, n, true, k % 2 == 0, kind).unwrap();
                        for p in w.particle_ids().collect::<Vec<_>>() {
                            let x = w.position(p) + DVec3::new(0.0, 2.2, 0.0);
                            w.set_position(p, x).unwrap();
                        }
                        for _ in 0..1 + (rng.uniform() * 12.0) as usize {
                            let at = DVec3::new(
                                rng.between(-2.0, 2.0),
                                rng.between(0.05, 0.3),
                                rng.between(-2.0, 2.0),
                            );
                            w.add_particle(
                                ParticleDef::new(rng.between(0.2, 5.0))
                                    .with_radius(rng.between(0.05, 0.3))
                                    .at(at),
                            )
                            .unwrap();
                        }
                        w
                    } else {
                        let mut w = World::new();
                        w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
                        w.set_integrator(kind);
                        let n = 2 + (rng.uniform() * 29.0) as usize;
                        let ids: Vec<_> = (0..n)
                            .map(|i| {
                                // Some small and fast at the middle of the
                                // heap: 6 to 12 cm a step, more than their
                                // radius (the swept test's).
                                let fast = rng.uniform() < 0.15;
                                let at = random_vec(rng, 0.6) + DVec3::new(0.0, 0.8, 0.0);
                                let v = if fast {
                                    (DVec3::new(0.0, 0.8, 0.0) - at).normalize_or_zero()
                                        * rng.between(60.0, 120.0)
                                } else {
                                    random_vec(rng, 2.0)
                                };
                                let r = if fast { 0.03 } else { rng.between(0.03, 0.15) };
                                let mut def = ParticleDef::new(rng.between(0.1, 3.0))
                                    .with_radius(r)
                                    .at(at)
                                    .with_velocity(v);
                                def.restitution = rng.between(0.0, 0.95);
                                def.mu_s = rng.between(0.0, 1.0);
                                def.mu_k = def.mu_s * rng.between(0.3, 1.0);
                                def.fixed = i == 0 && k % 4 == 1;
                                w.add_particle(def).unwrap()
                            })
                            .collect();
                        for _ in 0..n / 4 {
                            let a = (rng.uniform() * n as f64) as usize;
                            let b = (a + 1 + (rng.uniform() * (n - 1) as f64) as usize) % n;
                            if a != b {
                                let rest = (w.position(ids[a]) - w.position(ids[b])).length();
                                w.add_spring(SpringDef::new(ids[a], ids[b], 200.0, rest))
                                    .unwrap();
                            }
                        }
                        w
                    };
                    if floor {
                        w.add_floor(FloorDef::default()).unwrap();
                    }
                    if contact {
                        let def = animats_engine::SphereContactDef {
                            restitution: (k % 4 == 3).then_some(0.3),
                            ..Default::default()
                        };
                        w.add_sphere_contact(def).unwrap();
                    }
                    w
                })
                .collect()
        };
        let mut again = rng.clone();
        let mut worlds = make(&mut rng, true);
        let mut plain = make(&mut again, false);
        let what = format!("spheres colliding, {kind:?}, floor {floor}");
        assert_same(&mut worlds, 1e-3, 400, 3, &what);
        let backtracked: u64 = worlds.iter().map(|w| w.stats().backtracks).sum();
        let moved = ending_elsewhere(&worlds, &mut plain);
        eprintln!("{what}: {backtracked} backtracks; {moved} of 24 worlds end elsewhere without their contacts");
        assert!(
            moved >= 16,
            "{what}: the contacts changed only {moved} worlds"
        );
        assert!(
            backtracked > 0,
            "{what}: no contact was located by backtracking"
        );
    }
}

/// Sphere contact's corner cases, each a world of its own in one batch
/// with the floor: two fixed spheres sunk into each other and into the
/// floor, a free one dropped onto them (a fixed pair is never handled;
/// the floor holds no fixed sphere up); two spheres meeting head on along
/// a line (no sliding: no friction's impulse); two at one place (no
/// normal: left alone); two small fast ones flying side by side at one
/// velocity, 1 cm apart (the swept test with no relative motion); points
/// (no radius) among spheres; a world of points only (no sphere at all);
/// spheres on a sparse grid, and spread over more cells than its keys hold.
#[test]
fn sphere_contact_s_corner_cases_are_the_engine_s_to_the_bit() {
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        let world = |spheres: &[(f64, f64, DVec3, DVec3, bool)]| {
            let mut w = World::new();
            w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
            w.set_integrator(kind);
            for &(mass, radius, at, v, fixed) in spheres {
                let mut def = ParticleDef::new(mass)
                    .with_radius(radius)
                    .at(at)
                    .with_velocity(v);
                def.fixed = fixed;
                def.restitution = 0.6;
                def.mu_s = 0.5;
                def.mu_k = 0.3;
                w.add_particle(def).unwrap();
            }
            w.add_floor(FloorDef::default()).unwrap();
            w.add_sphere_contact(animats_engine::SphereContactDef::default())
                .unwrap();
            w
        };
        let z = DVec3::ZERO;
        let xyz = DVec3::new;
        let mut worlds = vec![
            world(&[
                (1.0, 0.2, xyz(0.0, 0.1, 0.0), z, true),
                (1.0, 0.2, xyz(0.3, 0.15, 0.0), z, true),
                (0.5, 0.1, xyz(0.12, 0.8, 0.03), z, false),
            ]),
            world(&[
                (1.0, 0.1, xyz(-0.5, 0.5, 0.0), xyz(3.0, 0.0, 0.0), false),
                (2.0, 0.1, xyz(0.5, 0.5, 0.0), xyz(-3.0, 0.0, 0.0), false),
            ]),
            world(&[
                (1.0, 0.1, xyz(0.0, 0.5, 0.0), z, false),
                (1.0, 0.15, xyz(0.0, 0.5, 0.0), z, false),
            ]),
            world(&[
                (0.1, 0.02, xyz(0.0, 0.6, 0.0), xyz(80.0, 0.0, 0.0), false),
                (
                    0.1,
                    0.02,
                    xyz(0.0, 0.635, 0.035),
                    xyz(80.0, 0.0, 0.0),
                    false,
                ),
                (1.0, 0.1, xyz(0.4, 0.6, 0.3), z, false),
            ]),
            world(&[
                (1.0, 0.0, xyz(0.0, 0.3, 0.0), z, false),
                (1.0, 0.1, xyz(0.05, 0.7, 0.0), z, false),
                (1.0, 0.0, xyz(0.1, 1.0, 0.0), z, false),
            ]),
            world(&[
                (1.0, 0.0, xyz(0.0, 0.3, 0.0), z, false),
                (1.0, 0.0, xyz(0.0, 0.3, 0.0), xyz(0.1, 0.0, 0.0), false),
            ]),
            // A sparse grid, millions of cells apart: a pair touching 100 km
            // out, lone spheres 7 km and 200 km from it.
            world(&[
                (1.0, 0.03, xyz(1e5, 0.5, 0.0), z, false),
                (1.0, 0.03, xyz(1e5, 0.559, 0.0), xyz(0.0, -1.0, 0.0), false),
                (1.0, 0.03, xyz(1e5 + 7e3, 0.5, 0.0), z, false),
                (1.0, 0.03, xyz(-1e5, 0.3, 0.0), xyz(1.0, 0.0, 0.0), false),
            ]),
            // Spread over more cells than a 64-bit key holds: the far ones
            // share the grid's last cells.
            world(&[
                (1.0, 0.03, xyz(6e10, 0.5, 0.0), z, false),
                (1.0, 0.03, xyz(-6e10, 1.2e8, 6e7), z, false),
                (1.0, 0.03, xyz(0.0, 0.5, -6e7), z, false),
                (1.0, 0.03, xyz(0.0, 0.5, 0.0), z, false),
                (1.0, 0.03, xyz(0.0, 0.559, 0.0), xyz(0.0, -1.0, 0.0), false),
            ]),
        ];
        assert_same(
            &mut worlds,
            1e-3,
            300,
            3,
            &format!("sphere contact's corners, {kind:?}"),
        );
        // The fixed pair stayed where it was, sunk into each other, and
        // the free sphere, dropped onto it, is not inside either.
        let pos = &worlds[0].state().pos;
        assert_eq!((pos[0], pos[1]), (xyz(0.0, 0.1, 0.0), xyz(0.3, 0.15, 0.0)));
        for fixed in [pos[0], pos[1]] {
            assert!((pos[2] - fixed).length() > 0.3 - 1e-3, "{pos:?}");
        }
    }
}

/// Bodies in water dragged across their springs (`[fluid] springs`,
/// forces/rod_drag.rs), their spheres touching each other too (the C
/// applies soft contact, then rod drag, as the engine's list of user forces
/// orders them); every other body in a uniform current, which the water
/// and the rods both feel.
#[test]
fn bodies_dragged_across_their_springs_in_water_are_the_engine_s_to_the_bit() {
    let mut rng = Random::for_entry(23, 0);
    for kind in INTEGRATORS {
        let make = |rng: &mut Random, rods: bool| -> Vec<World> {
            (0..16)
                .map(|k| {
                    let n = 2 + (rng.uniform() * 39.0) as usize;
                    let mut w = random_body(rng, n, true, k % 2 == 0, kind).unwrap();
                    let current = if k % 2 == 1 {
                        animats_engine::Current::Uniform(random_vec(rng, 0.5))
                    } else {
                        animats_engine::Current::Still
                    };
                    let water = FluidMedium {
                        current: current.clone(),
                        ..FluidMedium::water()
                    };
                    let (density, c) = (water.density, 0.8 + 0.1 * (k % 5) as f64);
                    w.add_fluid(water).unwrap();
                    let soft = soft_contact(&w);
                    w.add_force(soft);
                    if rods {
                        let ends: Vec<_> = w.forces().springs.iter().map(|s| s.ends()).collect();
                        let drag =
                            animats_engine::RodDrag::new(density, c, 0.02, current, &ends).unwrap();
                        w.add_force(Box::new(drag));
                    }
                    w
                })
                .collect()
        };
        let mut again = rng.clone();
        let mut worlds = make(&mut rng, true);
        let mut plain = make(&mut again, false);
        let sizes: Vec<usize> = worlds.iter().map(World::len).collect();
        assert_same(
            &mut worlds,
            5e-4,
            400,
            3,
            &format!("bodies dragged across their springs {sizes:?}, {kind:?}"),
        );
        // The rods matter: without them every body ends elsewhere.
        let moved = ending_elsewhere(&worlds, &mut plain);
        assert_eq!(moved, 16, "{kind:?}: the rods changed only {moved} bodies");
    }
}

/// Random bodies of 2 to 40 particles (both of the engine's n-body sums:
/// a set of at most 8 summed straight from the particles, a larger one by
/// its vector kernel, 8 accumulators a row) with n-body gravity among all
/// their particles, softened or not, and a second set among every other
/// particle; and three free bodies, two of them at one place, unsoftened
/// (a pair that pulls nowhere). Positive G, so the bodies pull together.
#[test]
fn bodies_pulled_by_n_body_gravity_are_the_engine_s_to_the_bit() {
    use animats_engine::{NBodyGravity, Targets};
    let mut rng = Random::for_entry(29, 0);
    for kind in INTEGRATORS {
        let make = |rng: &mut Random, pulled: bool| -> Vec<World> {
            let mut worlds: Vec<World> = (0..16)
                .map(|k| {
                    let n = 2 + (rng.uniform() * 39.0) as usize;
                    let mut w = random_body(rng, n, false, k % 2 == 0, kind).unwrap();
                    if pulled {
                        let softening = if k % 2 == 0 { 0.0 } else { 0.05 };
                        w.add_nbody(NBodyGravity::new(2.3, softening, Targets::All))
                            .unwrap();
                        let some: Vec<_> = w.particle_ids().step_by(2).collect();
                        w.add_nbody(NBodyGravity::new(0.7, 0.1, Targets::Only(some)))
                            .unwrap();
                    }
                    w
                })
                .collect();
            let mut free = World::new();
            free.set_integrator(kind);
            for x in [0.0, 0.0, 1.0] {
                free.add_particle(ParticleDef::new(1.5).at(DVec3::new(x, 0.5, 0.0)))
                    .unwrap();
            }
            if pulled {
                free.add_nbody(NBodyGravity::new(1.3, 0.0, Targets::All))
                    .unwrap();
            }
            worlds.push(free);
            worlds
        };
        let mut again = rng.clone();
        let mut worlds = make(&mut rng, true);
        let mut plain = make(&mut again, false);
        let sizes: Vec<usize> = worlds.iter().map(World::len).collect();
        assert!(sizes.iter().any(|&n| n <= 8) && sizes.iter().any(|&n| n > 8));
        assert_same(
            &mut worlds,
            5e-4,
            400,
            3,
            &format!("bodies under n-body gravity {sizes:?}, {kind:?}"),
        );
        // The pulls matter: without them every body ends elsewhere.
        let moved = ending_elsewhere(&worlds, &mut plain);
        assert_eq!(
            moved, 17,
            "{kind:?}: n-body gravity changed only {moved} bodies"
        );
        // The two at one place stay there (their own pair pulls nowhere).
        let free = &worlds[16];
        assert_eq!(free.state().pos[0], free.state().pos[1]);
    }
}

/// Sets of 256 bodies and more, which the engine sums in ranges of rows
/// (each range's reactions in a buffer of its own, added range by range):
/// a cloud of 300 free bodies, and one of 320 whose set leaves out every
/// ninth, each under symplectic Euler and RK4.
#[test]
fn large_n_body_sets_summed_in_ranges_are_the_engine_s_to_the_bit() {
    use animats_engine::{NBodyGravity, Targets};
    // (The second set holds 320 − 36 = 284 bodies: in ranges too.)
    assert!(NBodyGravity::row_ranges(300).len() > 2 && NBodyGravity::row_ranges(284).len() > 2);
    let mut rng = Random::for_entry(37, 0);
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        let make = |rng: &mut Random, n: usize, pulled: bool| -> World {
            let mut w = World::new();
            w.set_integrator(kind);
            let ids: Vec<_> = (0..n)
                .map(|_| {
                    let def = ParticleDef::new(rng.between(0.5, 2.0))
                        .at(random_vec(rng, 4.0))
                        .with_velocity(random_vec(rng, 0.2));
                    w.add_particle(def).unwrap()
                })
                .collect();
            if pulled {
                let targets = if n == 300 {
                    Targets::All
                } else {
                    Targets::Only(ids.iter().copied().filter(|p| p.index() % 9 != 0).collect())
                };
                w.add_nbody(NBodyGravity::new(0.9, 0.05, targets)).unwrap();
            }
            w
        };
        let mut again = rng.clone();
        let mut worlds = vec![make(&mut rng, 300, true), make(&mut rng, 320, true)];
        let mut plain = vec![make(&mut again, 300, false), make(&mut again, 320, false)];
        assert_same(
            &mut worlds,
            1e-3,
            20,
            2,
            &format!("large n-body sets, {kind:?}"),
        );
        for w in &mut plain {
            for _ in 0..40 {
                w.step(1e-3).unwrap();
            }
        }
        for (w, p) in worlds.iter().zip(&plain) {
            assert_ne!(
                w.state().pos,
                p.state().pos,
                "{kind:?}: the pulls moved nothing"
            );
        }
    }
}

/// Random bodies of 2 to 40 particles in a reef's waves, dragged on their
/// spheres and across their springs, each world at a time of its own (set,
/// or reached by steps of its own, so its clock carries a rounding
/// remainder): the C keeps each world's clock as the engine does, and the
/// currents it asks at each stage's time and each piece's are the engine's.
#[test]
fn bodies_in_a_reef_s_waves_each_at_its_own_time_are_the_engine_s_to_the_bit() {
    use animats_engine::RodDrag;
    let reef = reef();
    let mut rng = Random::for_entry(31, 0);
    for kind in INTEGRATORS {
        let make = |rng: &mut Random, at: &dyn Fn(usize) -> f64| -> Vec<World> {
            (0..12)
                .map(|k| {
                    let n = 2 + (rng.uniform() * 39.0) as usize;
                    let mut w = random_body(rng, n, false, k % 2 == 0, kind).unwrap();
                    let water = FluidMedium {
                        current: reef.clone(),
                        ..FluidMedium::water()
                    };
                    w.add_fluid(water).unwrap();
                    let ends: Vec<_> = w.forces().springs.iter().map(|s| s.ends()).collect();
                    let drag = RodDrag::new(1000.0, 1.2, 0.02, reef.clone(), &ends).unwrap();
                    w.add_force(Box::new(drag));
                    w.set_time(at(k));
                    // Every third world steps on its own first: its clock
                    // then holds a carry.
                    for _ in 0..(k % 3) * 37 {
                        w.step(5e-4).unwrap();
                    }
                    w
                })
                .collect()
        };
        let mut again = rng.clone();
        let mut worlds = make(&mut rng, &|k| 0.37 * (k + 1) as f64);
        assert!(worlds.iter().any(|w| w.time_carry() != 0.0));
        let sizes: Vec<usize> = worlds.iter().map(World::len).collect();
        assert_same(
            &mut worlds,
            5e-4,
            400,
            3,
            &format!("bodies in a reef's waves {sizes:?}, {kind:?}"),
        );
        // The time matters: the same bodies, each started at 0, end
        // elsewhere.
        let mut at_zero = make(&mut again, &|_| 0.0);
        for w in &mut at_zero {
            for _ in 0..1200 {
                if w.step(5e-4).is_err() {
                    break;
                }
            }
        }
        let moved = worlds
            .iter()
            .zip(&at_zero)
            .filter(|(a, b)| a.state().pos != b.state().pos)
            .count();
        assert_eq!(moved, 12, "{kind:?}: the time moved only {moved} bodies");
    }
}

/// A shallow reef's waves (1 m deep, 0.3 m high, 2 m long, 1.7 s) with a
/// drift.
fn reef() -> animats_engine::Current {
    animats_engine::Current::Reef(animats_engine::ReefWater {
        surface: 1.0,
        amplitude: 0.3,
        wavelength: 2.0,
        period: 1.7,
        direction: DVec3::new(1.0, 0.0, 0.4),
        drift: DVec3::new(0.05, 0.0, -0.02),
    })
}

/// Implicit Euler (integrators/implicit.rs: one Newton step, the springs',
/// angle joints' and drag's Jacobian, conjugate gradients): random bodies
/// of 2 to 40 particles, half with angle and torque joints, under gravity
/// dropped onto the floor with its contact force and a push (its located
/// collisions take part steps), in still water, in a uniform current
/// and under a reef's waves, every third with a particle held fixed; the
/// solver as the engine's default, at a loose tolerance, and held to 3
/// iterations (the step then keeps its last iterate).
#[test]
fn bodies_under_implicit_euler_are_the_engine_s_to_the_bit() {
    use animats_engine::{Current, Solver};
    let reef = reef();
    let mut rng = Random::for_entry(37, 0);
    let solvers = [
        Solver::default(),
        Solver {
            tolerance: 1e-3,
            max_iterations: 2000,
        },
        Solver {
            tolerance: 1e-9,
            max_iterations: 3,
        },
    ];
    for (case, water) in ["floor", "still", "current", "reef"].iter().enumerate() {
        for solver in solvers {
            let mut worlds: Vec<World> = (0..12)
                .map(|k| {
                    let n = 2 + (rng.uniform() * 39.0) as usize;
                    let kind = IntegratorKind::Implicit;
                    let mut w = random_body(&mut rng, n, true, k % 2 == 0, kind).unwrap();
                    w.set_solver(solver).unwrap();
                    if k % 3 == 0 {
                        let anchor = ParticleDef::new(1.0)
                            .with_radius(0.05)
                            .at(DVec3::new(0.0, 1.5, 0.0))
                            .fixed();
                        let a = w.add_particle(anchor).unwrap();
                        let other = w.particle_ids().next().unwrap();
                        w.add_spring(SpringDef::new(a, other, 300.0, 1.0)).unwrap();
                    }
                    if case == 0 {
                        for p in w.particle_ids().collect::<Vec<_>>() {
                            let x = w.position(p) + DVec3::new(0.0, 1.2, 0.0);
                            w.set_position(p, x).unwrap();
                        }
                        w.add_floor(FloorDef::default()).unwrap();
                        let ids: Vec<_> = w.particle_ids().collect();
                        w.add_constant_force(ids, random_vec(&mut rng, 3.0))
                            .unwrap();
                    } else {
                        let current = match case {
                            1 => Current::Still,
                            2 => Current::Uniform(random_vec(&mut rng, 0.8)),
                            _ => reef.clone(),
                        };
                        w.add_fluid(FluidMedium {
                            current,
                            ..FluidMedium::water()
                        })
                        .unwrap();
                    }
                    w
                })
                .collect();
            let sizes: Vec<usize> = worlds.iter().map(World::len).collect();
            assert_same(
                &mut worlds,
                2e-3,
                250,
                3,
                &format!("implicit Euler, {water}, {solver:?} {sizes:?}"),
            );
            if case == 0 {
                let down = worlds
                    .iter()
                    .filter(|w| w.state().pos.iter().any(|x| x.y < 0.21))
                    .count();
                assert!(down > 6, "only {down} bodies reached the floor");
            }
        }
    }
}

#[test]
fn what_the_c_does_not_step_is_refused_naming_the_world_and_the_entry() {
    let plain = || {
        let mut w = World::new();
        w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
        let a = w.add_particle(ParticleDef::new(1.0).at(DVec3::Y)).unwrap();
        let b = w.add_particle(ParticleDef::new(1.0).at(DVec3::X)).unwrap();
        w.add_spring(SpringDef::new(a, b, 10.0, 0.1)).unwrap();
        w
    };
    // A batch shares one ground; a body held in a plane walks on the flat
    // floor only.
    let sloped = |angle| {
        let mut w = plain();
        let terrain = animats_engine::Terrain::Slope(animats_engine::Slope {
            angle,
            uphill: DVec3::X,
        });
        w.add_floor(FloorDef {
            terrain,
            ..FloorDef::default()
        })
        .unwrap();
        w
    };
    assert!(Batch::pack(&[&sloped(0.2), &sloped(0.2)], 1e-3).is_ok());
    let err = Batch::pack(&[&sloped(0.2), &sloped(0.3)], 1e-3).unwrap_err();
    assert!(
        err.starts_with("world 1: a batch shares one floor")
            && err.contains("a slope of 0.2 rad")
            && err.contains("a slope of 0.3 rad"),
        "{err}"
    );
    let mut held = sloped(0.2);
    let ids: Vec<_> = held.particle_ids().collect();
    held.add_event(Box::new(animats_engine::PlaneConstraint::new(
        DVec3::ZERO,
        DVec3::Z,
        ids,
    )));
    let err = Batch::pack(&[&held], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: a plane constraint on terrain is not in the GPU step yet"
    );
    let mut floor = plain();
    floor.add_floor(FloorDef::default()).unwrap();
    let err = Batch::pack(&[&plain(), &floor], 1e-3).unwrap_err();
    assert!(
        err.starts_with("world 1: a batch shares one floor"),
        "{err}"
    );

    /// A force of the user's own: the C cannot know it.
    #[derive(Clone)]
    struct Breeze;
    impl animats_engine::Force for Breeze {
        fn apply(&mut self, _: &animats_engine::ForceContext, _: &mut [DVec3]) {}
        fn name(&self) -> &str {
            "breeze"
        }
    }
    let mut breezy = plain();
    breezy.add_force(Box::new(Breeze));
    let err = Batch::pack(&[&breezy], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: the user force `breeze` is not in the GPU step yet"
    );

    // Drag across springs is stepped after every soft contact (the C's
    // order).
    let rods = |current| {
        let ends = [(
            animats_engine::ParticleId::from_index(0),
            animats_engine::ParticleId::from_index(1),
        )];
        Box::new(animats_engine::RodDrag::new(1000.0, 1.2, 0.02, current, &ends).unwrap())
    };
    let mut first = plain();
    first.add_force(rods(animats_engine::Current::Still));
    let s = soft_contact(&first);
    first.add_force(s);
    let err = Batch::pack(&[&first], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: the user force `soft contact` is not in the GPU step yet"
    );
    let mut still = plain();
    let s = soft_contact(&still);
    still.add_force(s);
    still.add_force(rods(animats_engine::Current::Still));
    still.add_force(rods(animats_engine::Current::Uniform(DVec3::X)));
    still.add_force(rods(animats_engine::Current::Reef(
        animats_engine::ReefWater::default(),
    )));
    assert!(Batch::pack(&[&still], 1e-3).is_ok());

    // At most 64 planes a world (the C notes which a trial leaves in one
    // word); one floor.
    let mut planar = plain();
    for _ in 0..65 {
        planar.add_event(Box::new(animats_engine::PlaneConstraint::new(
            DVec3::ZERO,
            DVec3::Z,
            vec![animats_engine::ParticleId::from_index(0)],
        )));
    }
    let err = Batch::pack(&[&planar], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: more than 64 plane constraints is not in the GPU step yet"
    );
    let mut floors = plain();
    floors.add_floor(FloorDef::default()).unwrap();
    floors.add_floor(FloorDef::default()).unwrap();
    let err = Batch::pack(&[&floors], 1e-3).unwrap_err();
    assert_eq!(err, "world 0: a second floor is not in the GPU step yet");

    // Sphere contact: once, after the floor, among every particle, without
    // sleeping, on the flat floor, without planes.
    let spheres = |def: animats_engine::SphereContactDef, floor: bool| {
        let mut w = plain();
        if floor {
            w.add_floor(FloorDef::default()).unwrap();
        }
        w.add_sphere_contact(def).unwrap();
        w
    };
    assert!(Batch::pack(&[&spheres(Default::default(), true)], 1e-3).is_ok());
    assert!(Batch::pack(&[&spheres(Default::default(), false)], 1e-3).is_ok());
    let sleepy = animats_engine::SphereContactDef {
        sleep_speed: 0.01,
        ..Default::default()
    };
    let err = Batch::pack(&[&spheres(sleepy, true)], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: sphere contact with sleeping (`sleep_speed` > 0) is not in the GPU step yet"
    );
    let some = animats_engine::SphereContactDef {
        targets: animats_engine::Targets::Only(vec![animats_engine::ParticleId::from_index(0)]),
        ..Default::default()
    };
    let err = Batch::pack(&[&spheres(some, true)], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: sphere contact among some particles only is not in the GPU step yet"
    );
    let mut late = spheres(Default::default(), false);
    late.add_floor(FloorDef::default()).unwrap();
    let err = Batch::pack(&[&late], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: sphere contact before the floor among the world's events is not in the GPU step yet"
    );
    let mut twice = spheres(Default::default(), true);
    twice.add_sphere_contact(Default::default()).unwrap();
    let err = Batch::pack(&[&twice], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: a second sphere contact is not in the GPU step yet"
    );
    let mut planed = spheres(Default::default(), true);
    let ids: Vec<_> = planed.particle_ids().collect();
    planed.add_event(Box::new(animats_engine::PlaneConstraint::new(
        DVec3::ZERO,
        DVec3::Z,
        ids,
    )));
    let err = Batch::pack(&[&planed], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: sphere contact with plane constraints is not in the GPU step yet"
    );
    let mut crowd = plain();
    for k in 0..2047 {
        let at = DVec3::new(k as f64, 1.0, 0.0);
        crowd.add_particle(ParticleDef::new(1.0).at(at)).unwrap();
    }
    crowd.add_sphere_contact(Default::default()).unwrap();
    let err = Batch::pack(&[&crowd], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: sphere contact among more than 2048 particles is not in the GPU step yet"
    );
    let mut rough = sloped(0.2);
    rough.add_sphere_contact(Default::default()).unwrap();
    let err = Batch::pack(&[&rough], 1e-3).unwrap_err();
    assert_eq!(
        err,
        "world 0: sphere contact on terrain is not in the GPU step yet"
    );

    // Implicit Euler's worlds share one solver.
    let implicit = |iterations: u32| {
        let mut w = plain();
        w.set_integrator(IntegratorKind::Implicit);
        w.set_solver(animats_engine::Solver {
            tolerance: 1e-9,
            max_iterations: iterations,
        })
        .unwrap();
        w
    };
    Batch::pack(&[&implicit(50), &implicit(50)], 1e-3).unwrap();
    let err = Batch::pack(&[&implicit(50), &implicit(60)], 1e-3).unwrap_err();
    assert!(
        err.starts_with("world 1: a batch shares one implicit solver"),
        "{err}"
    );

    let mut weightless = plain();
    weightless.set_gravity_force(None).unwrap();
    let err = Batch::pack(&[&plain(), &weightless], 1e-3).unwrap_err();
    assert!(
        err.starts_with("world 1: a batch shares one gravity"),
        "{err}"
    );

    for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(Batch::pack(&[&plain()], dt).is_err(), "dt {dt}");
    }
    assert!(Batch::pack(&[], 1e-3).is_err());
    let batch = Batch::pack(&[&plain()], 1e-3).unwrap();
    assert!(batch.state(0, 1).is_some());
    assert_eq!(batch.state(0, 2), None);
    assert_eq!(batch.state(1, 0), None);
}
