//! Sleeping spheres (`SphereContactDef::sleep_speed`), against what an
//! awake world does:
//!
//! - a resting column falls asleep once still for `sleep_time`, where it
//!   rests awake, and then does not move by a bit;
//! - a blow passes through a row of sleeping spheres as through awake ones
//!   (Newton's cradle on the floor: the same velocities after it);
//! - a sleeper whose support is taken away by hand falls freely;
//! - a sleeper pushed slowly by a driven neighbour moves with it, as if
//!   awake (not as a nailed wall);
//! - a change of the forces (gravity turned round) wakes sleepers;
//! - a snapshot holds the sleep: restored, a world goes on bit for bit
//!   (and one that does not fit is refused, naming it);
//! - bad settings are refused, naming the field.
//!
//! The heap of a thousand is in `crates/bench/tests/pile.rs`.

use animats_engine::{
    FloorDef, IntegratorKind, ParticleDef, ParticleId, SphereContact, SphereContactDef, World,
};
use glam::DVec3;

const R: f64 = 0.02;
const H: f64 = 1e-3;
const G: f64 = 9.8;
/// Twice a step's gravity g h: above what a resting sphere trembles by.
const SLEEP: f64 = 0.02;

fn contact(sleep_speed: f64) -> SphereContactDef {
    SphereContactDef {
        sleep_speed,
        ..SphereContactDef::default()
    }
}

/// `n` spheres stacked on the floor, each resting on the one below.
fn column(n: usize, sleep_speed: f64) -> (World, Vec<ParticleId>) {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    w.set_gravity(DVec3::new(0.0, -G, 0.0));
    let ids = (0..n)
        .map(|k| {
            let x = DVec3::new(0.0, R + 2.0 * R * k as f64, 0.0);
            w.add_particle(
                ParticleDef::new(0.05)
                    .with_radius(R)
                    .at(x)
                    .with_restitution(0.3),
            )
            .unwrap()
        })
        .collect();
    w.add_floor(FloorDef::default()).unwrap();
    w.add_sphere_contact(contact(sleep_speed)).unwrap();
    (w, ids)
}

fn sleeping(w: &World) -> usize {
    w.event::<SphereContact>().unwrap().sleeping()
}

fn run(w: &mut World, steps: usize) {
    for _ in 0..steps {
        w.step(H).unwrap();
    }
}

#[test]
fn a_resting_column_falls_asleep_where_it_rests_and_stays_to_the_bit() {
    let (mut w, _) = column(3, SLEEP);
    let (mut awake, _) = column(3, 0.0);
    let mut fell_asleep = None;
    for step in 1..=1000 {
        w.step(H).unwrap();
        awake.step(H).unwrap();
        if fell_asleep.is_none() && sleeping(&w) == 3 {
            fell_asleep = Some(step);
        }
    }
    let fell_asleep = fell_asleep.expect("the column fell asleep within a second");
    println!("asleep after {fell_asleep} steps");
    // Still from the first step on, so asleep as soon as `sleep_time` is up.
    let time = SphereContactDef::default().sleep_time;
    assert!(fell_asleep as f64 * H >= time && fell_asleep as f64 * H <= time + 2.0 * H);
    assert_eq!(w.energy().kinetic, 0.0);
    // Where the awake column rests (which rests to the bit as well).
    for (x, y) in w.state().pos.iter().zip(&awake.state().pos) {
        assert!((*x - *y).length() < 1e-6, "asleep at {x}, awake at {y}");
    }
    let before = w.state().clone();
    run(&mut w, 1000);
    assert_eq!(w.state().pos, before.pos);
    assert_eq!(w.state().vel, before.vel);
    assert_eq!(sleeping(&w), 3);
}

/// Four spheres in a row on a frictionless floor, touching, and a fifth
/// sent into them at 1 m/s after `wait` steps (restitution 1).
fn cradle(sleep_speed: f64, wait: usize) -> (World, Vec<ParticleId>) {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    w.set_gravity(DVec3::new(0.0, -G, 0.0));
    let ids: Vec<ParticleId> = (0..5)
        .map(|k| {
            let x = if k == 0 {
                DVec3::new(-0.3, R, 0.0)
            } else {
                DVec3::new(2.0 * R * k as f64, R, 0.0)
            };
            w.add_particle(
                ParticleDef::new(0.05)
                    .with_radius(R)
                    .at(x)
                    .with_restitution(1.0)
                    .with_friction(0.0, 0.0),
            )
            .unwrap()
        })
        .collect();
    w.add_floor(FloorDef::default()).unwrap();
    w.add_sphere_contact(contact(sleep_speed)).unwrap();
    run(&mut w, wait);
    w.set_velocity(ids[0], DVec3::X).unwrap();
    (w, ids)
}

#[test]
fn a_blow_passes_through_sleeping_spheres_as_through_awake_ones() {
    let (mut w, ids) = cradle(SLEEP, 1000);
    let (mut awake, _) = cradle(0.0, 1000);
    assert_eq!(sleeping(&w), 4, "the row sleeps before the blow");
    run(&mut w, 500);
    run(&mut awake, 500);
    for (k, &b) in ids.iter().enumerate() {
        let (v, u) = (w.velocity(b), awake.velocity(b));
        println!("ball {k}: {v} asleep before, {u} awake");
        assert!((v - u).length() < 1e-9, "ball {k}: {v} against {u}");
    }
    // And it is the cradle's answer: the last ball leaves with the blow.
    assert!((w.velocity(ids[4]) - DVec3::X).length() < 1e-6);
    assert!(!w.event::<SphereContact>().unwrap().is_asleep(ids[4]));
}

#[test]
fn a_sleeper_whose_support_is_taken_away_falls_freely() {
    let (mut w, ids) = column(2, SLEEP);
    run(&mut w, 1000);
    assert_eq!(sleeping(&w), 2);
    let top = w.position(ids[1]);
    w.set_position(ids[0], DVec3::new(1.0, R, 0.0)).unwrap();
    let n = 50;
    run(&mut w, n);
    // Symplectic Euler from rest: y falls by g h² n (n + 1) / 2.
    let fallen = G * H * H * (n * (n + 1)) as f64 / 2.0;
    let y = w.position(ids[1]).y;
    assert!(
        (top.y - y - fallen).abs() < 1e-12,
        "fell {} m, free fall {fallen} m",
        top.y - y
    );
    assert_eq!(sleeping(&w), 0);
}

/// Two spheres touching side by side on a frictionless floor, and a
/// sideways force on the first (0 until `wait` steps, then growing by
/// 0.012 N/s: slow enough that the pair stays under the sleep speed for
/// half a second).
fn pushed(sleep_speed: f64, wait: usize, steps: usize) -> (World, Vec<ParticleId>) {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    w.set_gravity(DVec3::new(0.0, -G, 0.0));
    let ids: Vec<ParticleId> = (0..2)
        .map(|k| {
            w.add_particle(
                ParticleDef::new(0.05)
                    .with_radius(R)
                    .at(DVec3::new(2.0 * R * k as f64, R, 0.0))
                    .with_friction(0.0, 0.0),
            )
            .unwrap()
        })
        .collect();
    let push = w.add_constant_force(vec![ids[0]], DVec3::ZERO).unwrap();
    w.add_floor(FloorDef::default()).unwrap();
    w.add_sphere_contact(contact(sleep_speed)).unwrap();
    run(&mut w, wait);
    for k in 1..=steps {
        let f = DVec3::new(0.012 * k as f64 * H, 0.0, 0.0);
        w.forces_mut().constant_forces.set(push, f);
        w.step(H).unwrap();
    }
    (w, ids)
}

#[test]
fn a_sleeper_pushed_slowly_moves_as_if_awake() {
    let (w0, _) = pushed(SLEEP, 1000, 0);
    assert_eq!(sleeping(&w0), 2, "the pair sleeps before the push");
    let (w, ids) = pushed(SLEEP, 1000, 500);
    let (awake, _) = pushed(0.0, 1000, 500);
    let start = w0.position(ids[1]).x;
    let (moved, expected) = (
        w.position(ids[1]).x - start,
        awake.position(ids[1]).x - start,
    );
    // Both pushed together from rest: x = k t³ / (6 · 2m), 2.5 mm.
    println!("pushed sphere moved {moved} m asleep before, {expected} m awake");
    assert!(
        (expected - 2.5e-3).abs() < 0.05 * 2.5e-3,
        "awake: {expected} m"
    );
    assert!(
        (moved - expected).abs() < 0.01 * expected,
        "moved {moved} m, awake {expected} m"
    );
    assert!(w.velocity(ids[1]).x < SLEEP, "faster than the sleep speed");
}

#[test]
fn gravity_turned_round_wakes_sleepers() {
    let (mut w, ids) = column(2, SLEEP);
    run(&mut w, 1000);
    assert_eq!(sleeping(&w), 2);
    let start: Vec<DVec3> = ids.iter().map(|&i| w.position(i)).collect();
    w.set_gravity(DVec3::new(0.0, G, 0.0));
    let n = 100;
    run(&mut w, n);
    let risen = G * H * H * (n * (n + 1)) as f64 / 2.0;
    for (k, &i) in ids.iter().enumerate() {
        let up = w.position(i).y - start[k].y;
        assert!(
            (up - risen).abs() < 1e-9,
            "sphere {k} rose {up} m, not {risen} m"
        );
    }
}

/// A column of two on the floor and a ball dropped from 2 m onto it, which
/// lands (about 0.62 s) after the column has fallen asleep (0.5 s).
fn column_and_ball() -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    w.set_gravity(DVec3::new(0.0, -G, 0.0));
    for y in [R, 3.0 * R, 2.0] {
        let sphere = ParticleDef::new(0.05).with_radius(R).with_restitution(0.3);
        w.add_particle(sphere.at(DVec3::new(0.0, y, 0.0))).unwrap();
    }
    w.add_floor(FloorDef::default()).unwrap();
    w.add_sphere_contact(contact(SLEEP)).unwrap();
    w
}

/// Every step's positions, velocities and sleepers from now to `until` steps.
fn record(w: &mut World, until: usize) -> Vec<(Vec<DVec3>, Vec<DVec3>, usize)> {
    let mut out = Vec::new();
    while w.stats().steps < until as u64 {
        w.step(H).unwrap();
        out.push((w.state().pos.clone(), w.state().vel.clone(), sleeping(w)));
    }
    out
}

#[test]
fn a_restored_snapshot_goes_on_bit_for_bit_with_its_sleepers() {
    let mut w = column_and_ball();
    run(&mut w, 300);
    let timing = w.snapshot(); // the column still, not yet asleep
    let mut from_timing = record(&mut w, 550);
    let asleep = w.snapshot(); // the column asleep, the ball falling
    assert_eq!(sleeping(&w), 2);
    assert!(asleep.sleep.is_some());
    let from_asleep = record(&mut w, 1500);
    assert!(
        from_asleep.iter().any(|s| s.2 == 0),
        "the ball never woke the column"
    );
    from_timing.extend_from_slice(&from_asleep);
    for (name, snap, expected) in [
        ("at 0.3 s", &timing, &from_timing),
        ("at 0.55 s", &asleep, &from_asleep),
    ] {
        // Into the same world, and through JSON into one built anew.
        w.restore(snap).unwrap();
        assert_eq!(&record(&mut w, 1500), expected, "restored {name}");
        let text = serde_json::to_string(snap).unwrap();
        let mut fresh = column_and_ball();
        fresh
            .restore(&serde_json::from_str(&text).unwrap())
            .unwrap();
        assert_eq!(
            &record(&mut fresh, 1500),
            expected,
            "restored {name} from JSON"
        );
    }
    // Without its sleep the restored world goes another way: the snapshot
    // is what carries it.
    let mut forgetful = asleep.clone();
    forgetful.sleep = None;
    w.restore(&forgetful).unwrap();
    assert_eq!(sleeping(&w), 0);
    assert_ne!(record(&mut w, 1500), from_asleep);
}

#[test]
fn a_snapshot_whose_sleep_does_not_fit_is_refused_naming_it() {
    let mut w = column_and_ball();
    run(&mut w, 600);
    let snap = w.snapshot();
    // Of a world with one sphere fewer.
    let mut text: serde_json::Value = serde_json::to_value(&snap).unwrap();
    text["sleep"]["asleep"].as_array_mut().unwrap().pop();
    let short: animats_engine::Snapshot = serde_json::from_value(text).unwrap();
    let before = w.snapshot();
    let e = w.restore(&short).unwrap_err().to_string();
    assert!(e.contains("sleep") && e.contains("asleep"), "{e}");
    assert_eq!(w.snapshot(), before, "a refused snapshot changed the world");
    // Into a world without sphere contact.
    let mut plain = World::new();
    for _ in 0..3 {
        plain
            .add_particle(ParticleDef::new(0.05).with_radius(R))
            .unwrap();
    }
    plain.set_gravity(DVec3::new(0.0, -G, 0.0));
    let e = plain.restore(&snap).unwrap_err().to_string();
    assert!(
        e.contains("sleep") && e.contains("no sphere contact"),
        "{e}"
    );
    // Into a world whose spheres never sleep (it would hold them forever).
    let (mut awake, _) = column(3, 0.0);
    let e = awake.restore(&snap).unwrap_err().to_string();
    assert!(e.contains("never sleep"), "{e}");
}

#[test]
fn bad_sleep_settings_are_refused_naming_the_field() {
    for (speed, time, field) in [
        (-1.0, 0.5, "sleep_speed"),
        (f64::NAN, 0.5, "sleep_speed"),
        (0.02, -0.1, "sleep_time"),
        (0.02, f64::INFINITY, "sleep_time"),
    ] {
        let def = SphereContactDef {
            sleep_speed: speed,
            sleep_time: time,
            ..SphereContactDef::default()
        };
        match SphereContact::new(def) {
            Ok(_) => panic!("accepted sleep_speed {speed}, sleep_time {time}"),
            Err(e) => assert!(e.to_string().contains(field), "{e}"),
        }
    }
}
