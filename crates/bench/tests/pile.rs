//! A thousand spheres poured onto the floor inside a ring of nailed spheres
//! tall enough to hold them: none gets out, no overlap is ever deeper than
//! the envelope, none goes below the floor, the pile loses nearly all the
//! kinetic energy of the fall, and in the fourth second the heap does not
//! shake in place. Awake, it does not come fully to rest: resting spheres
//! end each step with up to the velocity g·h of the step's gravity, and the
//! heap still creeps by about a millimetre a second (`cargo run --release
//! -p animats-bench --example pile_rest -- --rows 8` shows it second by
//! second; an ordered pyramid does rest, see
//! `crates/engine/tests/sphere_contact.rs` and docs/DESIGN.md
//! "Sphere–sphere contact"). With sleeping on (`sleep_speed` twice g·h),
//! the same heap falls asleep and then does not move by a bit.

use animats_bench::pile::{outside_ring, pile_walled, pile_walled_with};
use animats_engine::{SphereContact, SphereContactDef};

#[test]
fn a_thousand_spheres_poured_into_a_ring_lose_their_energy_without_deep_overlaps() {
    let r = 0.02;
    // A ring eight spheres tall holds the whole heap (the benchmark's, one
    // tall, lets 171 of the 1,000 out within these 4 s: `pile_rest`).
    let mut w = pile_walled(1000, r, 10, 8);
    let envelope = SphereContactDef::default().envelope;
    let h = 1e-3;
    let (mut deepest, mut peak, mut lowest) = (0.0f64, 0.0f64, f64::INFINITY);
    let mut probe = SphereContact::new(SphereContactDef::default()).unwrap();
    let free: Vec<usize> = (0..w.len())
        .filter(|&i| w.particles().inv_mass[i] > 0.0)
        .collect();
    // In the fourth second: each free sphere's path step by step, where it
    // started, and the deepest overlap left at a step's end.
    let (mut path, mut start, mut late) = (vec![0.0f64; w.len()], Vec::new(), 0.0f64);
    for step in 0..4000 {
        if step == 3000 {
            start = w.state().pos.clone();
        }
        let before = w.state().pos.clone();
        w.step(h).unwrap();
        let s = w.state();
        let overlap = probe.deepest_overlap(&s.pos, w.particles());
        deepest = deepest.max(overlap);
        if step >= 3000 {
            late = late.max(overlap);
            for &i in &free {
                path[i] += (s.pos[i] - before[i]).length();
            }
        }
        peak = peak.max(w.energy().kinetic);
        lowest = s.pos.iter().map(|x| x.y).fold(lowest, f64::min);
    }
    let left = w.energy().kinetic;
    let outside = outside_ring(&w);
    let mean = w.state().vel.iter().map(|v| v.length()).sum::<f64>() / w.len() as f64;
    let travelled = free.iter().map(|&i| path[i]).sum::<f64>() / free.len() as f64;
    let moved = free
        .iter()
        .map(|&i| (w.state().pos[i] - start[i]).length())
        .sum::<f64>()
        / free.len() as f64;
    println!(
        "deepest overlap {deepest:e} m ({late:e} m in the fourth second), lowest centre {lowest} m, kinetic energy {peak:.3e} -> {left:.3e} J, mean speed {mean:.3e} m/s, outside the ring {outside}; fourth second: travelled {travelled:.3e} m step by step, moved {moved:.3e} m"
    );
    assert_eq!(outside, 0, "spheres got out of the ring");
    assert!(
        deepest <= envelope,
        "overlap {deepest} deeper than the envelope"
    );
    assert!(
        lowest >= r - 1e-12,
        "a sphere went into the floor: {lowest}"
    );
    assert!(left < 1e-3 * peak, "kept {left} of {peak} J");
    // Resting spheres carry at most about one step of gravity, g h.
    assert!(mean < 2.0 * 9.8 * h, "mean speed {mean}");
    // A resting sphere sinks g h² in a step and the contacts take it back:
    // a heap at rest travels about that much a step, one settling travels
    // about as far as it moves. Shaking in place (back and forth between
    // the contacts) is travel far beyond both.
    let sag = 9.81 * h * h * 1000.0;
    assert!(
        travelled < sag.max(2.0 * moved),
        "the heap shakes: {travelled} m step by step in a second, {moved} m from where it started"
    );
    // And what a step leaves overlapping is a few steps' sag, not the
    // envelope's centimetre.
    assert!(
        late < 20.0 * 9.81 * h * h,
        "overlap {late} m left at a step's end"
    );
}

#[test]
fn a_thousand_spheres_that_may_sleep_come_to_rest_and_stay() {
    let (r, h) = (0.02, 1e-3);
    // Twice a step's gravity g h: above what a resting sphere trembles by
    // (with half of g h the heap never sleeps: docs/DESIGN.md, "Sphere–sphere contact").
    let def = SphereContactDef {
        sleep_speed: 2.0 * 9.8 * h,
        ..SphereContactDef::default()
    };
    let mut w = pile_walled_with(1000, r, 10, 8, def);
    let mut probe = SphereContact::new(SphereContactDef::default()).unwrap();
    let mut deepest = 0.0f64;
    for _ in 0..6000 {
        w.step(h).unwrap();
        deepest = deepest.max(probe.deepest_overlap(&w.state().pos, w.particles()));
    }
    let asleep = w.event::<SphereContact>().unwrap().sleeping();
    let settled = w.state().clone();
    for _ in 0..1000 {
        w.step(h).unwrap();
    }
    let moved = w
        .state()
        .pos
        .iter()
        .zip(&settled.pos)
        .filter(|(x, y)| x != y)
        .count();
    let late = probe.deepest_overlap(&w.state().pos, w.particles());
    println!(
        "asleep at 6 s: {asleep}; moved in the 7th second: {moved}; kinetic energy {:e} J; deepest overlap {deepest:e} m, {late:e} m at 7 s; outside {}",
        w.energy().kinetic,
        outside_ring(&w)
    );
    assert_eq!(moved, 0, "spheres moved after the heap fell asleep");
    assert_eq!(w.energy().kinetic, 0.0);
    assert_eq!(outside_ring(&w), 0);
    assert!(deepest <= SphereContactDef::default().envelope);
    assert!(late < 20.0 * 9.81 * h * h, "overlap {late} m left at rest");
}

#[test]
fn extreme_sleep_settings_neither_backtrack_forever_nor_overlap_deeply() {
    // `sleep_time = 0` (asleep as soon as still for a step), and a sleep
    // speed nothing exceeds: spheres must not fall asleep in mid-air, and
    // holding one back where it was must not leave overlaps that the next
    // check calls missed, step after step.
    let (r, h) = (0.02, 1e-3);
    let mut awake = pile_walled(200, r, 5, 8);
    for _ in 0..2000 {
        awake.step(h).unwrap();
    }
    let heap = {
        let p = &awake.state().pos;
        let free: Vec<usize> = (0..awake.len())
            .filter(|&i| awake.particles().inv_mass[i] > 0.0)
            .collect();
        free.iter().map(|&i| p[i].y).sum::<f64>() / free.len() as f64
    };
    // (sleep speed, sleep time, whether the heap must be the awake one's):
    // at 1e300 m/s every touching sphere calm in its trial sleeps after
    // half a second, moving or not, so the heap freezes as it lands.
    for (speed, time, like_awake) in [(0.02, 0.0, true), (1e300, 0.5, false)] {
        let def = SphereContactDef {
            sleep_speed: speed,
            sleep_time: time,
            ..SphereContactDef::default()
        };
        let mut w = pile_walled_with(200, r, 5, 8, def);
        let free: Vec<usize> = (0..w.len())
            .filter(|&i| w.particles().inv_mass[i] > 0.0)
            .collect();
        let mean_y = |w: &animats_engine::World| {
            free.iter().map(|&i| w.state().pos[i].y).sum::<f64>() / free.len() as f64
        };
        let start = mean_y(&w);
        let mut probe = SphereContact::new(SphereContactDef::default()).unwrap();
        let mut deepest = 0.0f64;
        for _ in 0..2000 {
            w.step(h).unwrap();
            deepest = deepest.max(probe.deepest_overlap(&w.state().pos, w.particles()));
        }
        let backtracks = w.stats().backtracks;
        let asleep = w.event::<SphereContact>().unwrap().sleeping();
        let end = mean_y(&w);
        println!("sleep_speed {speed:e}, sleep_time {time}: {backtracks} backtracks in 2,000 steps, deepest overlap {deepest:e} m, {asleep} asleep, mean height {start} -> {end} m");
        // Fallen into a heap like the one awake, not held in the air.
        assert!(
            !like_awake || (end - heap).abs() < 0.1 * heap,
            "mean height {end} m, awake {heap} m"
        );
        assert!(backtracks < 200, "{backtracks} backtracks");
        assert!(deepest <= SphereContactDef::default().envelope);
        assert_eq!(outside_ring(&w), 0);
    }
}
