//! The jellyfish: what must hold (issue 4). Alone in still water with the
//! food directly above, it rises to it; with the food beside it, it steers
//! towards it; its energy stays in [0, 1] and it goes through track and
//! hover; and the FSM follows Appendix B's thresholds.

use animats_creatures::jellyfish::{
    Behaviour, Jellyfish, JellyfishConstants, JellyfishFsm, Senses,
};
use animats_creatures::Actor;
use animats_engine::{DVec3, FloorDef, FluidMedium, ParticleDef, World};

/// A SeaWorld jellyfish (Appendix B's first: 0.2 kg dome masses) at 0.4 m in
/// still water over the floor, food at `food`.
fn pond(food: DVec3) -> (World, Jellyfish, animats_engine::ParticleId) {
    let mut w = World::new();
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let f = w
        .add_particle(ParticleDef::new(1.0).with_volume(1e-3).at(food).fixed())
        .unwrap();
    let j = Jellyfish::build(
        &mut w,
        "jelly",
        &JellyfishConstants::new(0.2, 0.02),
        DVec3::new(0.0, 0.4, 0.0),
        f,
    )
    .unwrap();
    w.add_fluid(FluidMedium::water()).unwrap();
    w.add_floor(FloorDef::default()).unwrap();
    (w, j, f)
}

fn run(w: &mut World, j: &mut Jellyfish, seconds: f64, mut each: impl FnMut(&World, &Jellyfish)) {
    for _ in 0..(seconds / 0.01).round() as usize {
        j.act(w, 0.01);
        w.step(0.01).unwrap();
        each(w, j);
    }
}

#[test]
fn with_the_food_directly_above_it_rises_to_it() {
    let (mut w, mut j, food) = pond(DVec3::new(0.0, 0.9, 0.0));
    let mut closest = f64::INFINITY;
    let mut lowest_up = 1.0f64;
    run(&mut w, &mut j, 10.0, |w, j| {
        closest = closest.min((j.body.centre(w) - w.position(food)).length());
        lowest_up = lowest_up.min(j.body.normal(w).y);
    });
    assert!(closest < 0.05, "closest approach {closest} m");
    // The balance reflex keeps the dome within 60° of upright.
    assert!(
        lowest_up > 0.5,
        "it tipped over (normal·y down to {lowest_up})"
    );
}

#[test]
fn with_the_food_beside_it_steers_towards_it() {
    for side in [
        DVec3::new(0.6, 0.9, 0.0),
        DVec3::new(-0.3, 0.9, 0.4),
        DVec3::new(0.0, 0.9, -0.5),
    ] {
        let (mut w, mut j, _) = pond(side);
        let start = j.food_distance(&w);
        let mut closest = start;
        let mut lowest_up = 1.0f64;
        run(&mut w, &mut j, 30.0, |w, j| {
            closest = closest.min(j.food_distance(w));
            lowest_up = lowest_up.min(j.body.normal(w).y);
        });
        assert!(
            closest < 0.5 * start,
            "food at {side}: got no nearer than {closest} m of {start} m"
        );
        assert!(
            j.food_distance(&w) < start,
            "food at {side}: ended {} m away, started {start} m",
            j.food_distance(&w)
        );
        assert!(
            lowest_up > 0.5,
            "food at {side}: tipped to normal·y = {lowest_up}"
        );
    }
}

#[test]
fn energy_stays_in_range_and_it_both_tracks_and_hovers() {
    let (mut w, mut j, _) = pond(DVec3::new(0.5, 0.9, 0.2));
    let mut seen = std::collections::HashSet::new();
    run(&mut w, &mut j, 60.0, |_, j| {
        let e = j.fsm.energy();
        assert!((0.0..=1.0).contains(&e), "energy {e}");
        seen.insert(j.fsm.behaviour());
        let status = j.status().unwrap();
        assert_eq!(status.energy, Some(e));
        assert_eq!(status.state, j.fsm.behaviour().name());
    });
    for b in [Behaviour::Idle, Behaviour::Track, Behaviour::Hover] {
        assert!(seen.contains(&b), "never {b}");
    }
}

fn senses(depth: f64) -> Senses {
    Senses {
        food: vec![0.2, 0.3, 0.4],
        depth,
        time: 0.0,
        lean: vec![0.0; 3],
    }
}

#[test]
fn fsm_follows_appendix_b() {
    let dt = 0.01;
    // Rested (energy 1): idle chooses track, which drains 0.1/s over a 1 s pulse.
    let mut fsm = JellyfishFsm::new(1.0);
    fsm.step(&senses(0.4), dt);
    assert_eq!(fsm.behaviour(), Behaviour::Track);
    let mut pulses = Vec::new();
    let mut track_steps = 0;
    while fsm.behaviour() == Behaviour::Track {
        let o = fsm.step(&senses(0.4), dt);
        track_steps += 1;
        if let Some(p) = o.pulse {
            pulses.push(p);
        }
        assert!(track_steps <= 101, "the pulse did not end");
    }
    // One pulse lasts the pulse period: 100 steps of 10 ms (101 when the
    // accumulated phase lands a rounding error short of 2π).
    assert!(track_steps >= 100, "pulse over after {track_steps} steps");
    // Idle could not raise a full charge (clamped at 1); each track step drains 0.1 dt.
    let expected = 1.0 - 0.1 * dt * track_steps as f64;
    assert!(
        (fsm.energy() - expected).abs() < 1e-9,
        "energy {}",
        fsm.energy()
    );
    // Pulse level 0.5 + ½ sin φ, the recovery stroke a tenth as strong.
    let peak = pulses.iter().cloned().fold(0.0, f64::max);
    let trough = pulses.iter().cloned().fold(1.0, f64::min);
    assert!(
        (peak - 1.0).abs() < 1e-3 && (trough - 0.45).abs() < 1e-3,
        "peak {peak}, trough {trough}"
    );
    // The dome mass smelling the least (index 0) is pushed hardest at the peak.
    let mut fsm = JellyfishFsm::new(1.0);
    fsm.step(&senses(0.4), dt);
    let mut max_push = [f64::MIN; 3];
    for _ in 0..99 {
        if let Some(st) = fsm.step(&senses(0.4), dt).steer {
            for i in 0..3 {
                max_push[i] = max_push[i].max(st[i]);
            }
        }
    }
    assert!(
        max_push[0] > max_push[1] && max_push[0] > max_push[2],
        "{max_push:?}"
    );

    // Too high (depth sense saturated): stays idle and rests.
    let mut fsm = JellyfishFsm::new(1.0);
    let o = fsm.step(&senses(1.0), dt);
    assert_eq!((fsm.behaviour(), o.pulse), (Behaviour::Idle, None));
}

#[test]
fn a_tired_jellyfish_hovers_until_rested_then_tracks_again() {
    let dt = 0.01;
    let mut fsm = JellyfishFsm::new(1.0);
    // Track until the energy falls below 0.5: then it hovers.
    let mut steps = 0;
    while !(fsm.behaviour() == Behaviour::Hover) {
        fsm.step(&senses(0.5), dt);
        steps += 1;
        assert!(steps < 10_000);
    }
    assert!(
        fsm.energy() <= 0.5 + 1e-9 && fsm.energy() >= 0.2,
        "hovering at energy {}",
        fsm.energy()
    );
    assert_eq!(fsm.hover_depth(), Some(0.5));
    // At its hover depth it idles (energy +0.4/s) and re-decides each step;
    // past 0.9 it tracks again.
    let e0 = fsm.energy();
    let mut t = 0.0;
    while fsm.behaviour() != Behaviour::Track {
        fsm.step(&senses(0.5), dt);
        t += dt;
        assert!(t < 10.0);
    }
    assert!(fsm.energy() > 0.9);
    // Every other step is idle (+0.4 dt), so the climb takes about twice (0.9 − e0)/0.4 s.
    let expected = 2.0 * (0.9 - e0) / 0.4;
    assert!(
        (t - expected).abs() < 0.1,
        "rested in {t} s, expected about {expected} s"
    );
}
