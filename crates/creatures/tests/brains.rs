//! The controller kinds a scene declares, against their definitions:
//! the oscillator's formula, a network computed by hand, FSM timing and
//! thresholds, and genomes that round-trip.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_creatures::brain::Brain;
use animats_creatures::brains::{Condition, Fsm, FsmState, Neural, Oscillator, Transition};
use std::f64::consts::{PI, TAU};

#[test]
fn the_oscillator_is_offset_plus_amplitude_times_sine() {
    let mut o = Oscillator {
        frequency: 1.5,
        amplitude: vec![0.4, 0.2],
        phase: vec![0.0, PI / 3.0],
        offset: vec![0.5, 0.3],
    };
    let mut out = [0.0; 2];
    for k in 0..200 {
        let t = k as f64 * 0.013;
        o.think(t, 0.013, &[], &mut out);
        for (i, got) in out.iter().enumerate() {
            let expected = o.offset[i] + o.amplitude[i] * (TAU * 1.5 * t + o.phase[i]).sin();
            assert!((got - expected).abs() < 1e-14, "t {t} output {i}");
        }
    }
    let g = o.genome();
    assert_eq!(g.len(), 1 + 3 * 2);
    let mut p = o.clone();
    p.set_genome(&[2.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6]).unwrap();
    assert_eq!(p.frequency, 2.0);
    assert_eq!(p.amplitude, [0.1, 0.2]);
    assert_eq!(p.phase, [0.3, 0.4]);
    assert_eq!(p.offset, [0.5, 0.6]);
    p.set_genome(&g).unwrap();
    assert_eq!(p, o);
    assert!(p.set_genome(&g[..3]).is_err());
    assert!(p.set_genome(&[f64::NAN; 7]).is_err());
    for (x, (lo, hi)) in g.iter().zip(o.bounds()) {
        assert!(lo <= *x && *x <= hi);
    }
}

#[test]
fn a_network_computes_what_is_written_by_hand() {
    // 2 inputs + clock (2) → 2 tanh → 1 logistic.
    let mut n = Neural::new(2, &[2], 1, Some(0.5));
    assert_eq!(n.sizes, [4, 2, 1]);
    assert_eq!(Neural::weight_count(&n.sizes), 2 * 5 + 3);
    let w: Vec<f64> = (0..13).map(|i| 0.1 * i as f64 - 0.6).collect();
    n.set_genome(&w).unwrap();
    let (s0, s1, t) = (0.9, 0.2, 0.7);
    let x = [
        2.0 * s0 - 1.0,
        2.0 * s1 - 1.0,
        (TAU * 0.5 * t).sin(),
        (TAU * 0.5 * t).cos(),
    ];
    let h: Vec<f64> = (0..2)
        .map(|j| {
            let a: f64 = (0..4).map(|i| w[j * 4 + i] * x[i]).sum::<f64>() + w[8 + j];
            a.tanh()
        })
        .collect();
    let a = w[10] * h[0] + w[11] * h[1] + w[12];
    let expected = 1.0 / (1.0 + (-a).exp());
    let mut out = [0.0];
    n.think(t, 0.01, &[s0, s1], &mut out);
    assert!(
        (out[0] - expected).abs() < 1e-14,
        "{} vs {expected}",
        out[0]
    );
    // Random default weights are small and seeded.
    let mut r1 = Neural::new(3, &[8], 2, None);
    let mut r2 = r1.clone();
    r1.randomise(7);
    r2.randomise(7);
    assert_eq!(r1.weights, r2.weights);
    assert!(r1.weights.iter().all(|w| w.abs() <= 1.0 / 3f64.sqrt()));
    r2.randomise(8);
    assert_ne!(r1.weights, r2.weights);
}

fn two_states() -> Fsm {
    Fsm::new(
        vec![
            FsmState {
                name: "down".into(),
                levels: vec![0.0],
                rate: None,
                transitions: vec![Transition {
                    to: 1,
                    condition: Condition::None,
                    after: Some(0.1),
                }],
            },
            FsmState {
                name: "up".into(),
                levels: vec![1.0],
                rate: Some(5.0),
                transitions: vec![Transition {
                    to: 0,
                    condition: Condition::Above {
                        input: 0,
                        threshold: 0.5,
                    },
                    after: None,
                }],
            },
        ],
        0,
        vec![0.5],
    )
}

#[test]
fn fsm_transitions_happen_on_time_and_on_thresholds_and_rates_limit_the_levels() {
    let dt = 0.01;
    let mut f = two_states();
    let mut out = [0.0];
    // In `down` the level is 0 at once; after 0.1 s (10 steps) it goes `up`.
    let mut k = 0;
    while f.state() == Some("down") {
        f.think(k as f64 * dt, dt, &[0.0], &mut out);
        if f.state() == Some("down") {
            assert_eq!(out[0], 0.0);
        }
        k += 1;
        assert!(k < 100);
    }
    let mut t = k as f64 * dt;
    assert_eq!(k, 11, "leaves `down` at the step where 0.1 s have passed");
    // In `up` the level climbs at 5 per s: 0.05 per step.
    assert!((out[0] - 0.05).abs() < 1e-12, "{}", out[0]);
    for _ in 0..5 {
        f.think(t, dt, &[0.2], &mut out);
        t += dt;
    }
    assert!((out[0] - 0.30).abs() < 1e-12, "{}", out[0]);
    // The sensor passing 0.5 sends it back down.
    f.think(t, dt, &[0.6], &mut out);
    assert_eq!(f.state(), Some("down"));
    assert_eq!(out[0], 0.0);
    // Genome: down's level, its after; up's level, its rate, its threshold.
    assert_eq!(f.genome(), [0.0, 0.1, 1.0, 5.0, 0.5]);
    f.set_genome(&[0.2, 0.3, 0.9, 7.0, 0.4]).unwrap();
    assert_eq!(f.genome(), [0.2, 0.3, 0.9, 7.0, 0.4]);
    assert_eq!(f.bounds().len(), 5);
    f.reset();
    assert_eq!(f.state(), Some("down"));
}

/// The thesis's creatures' FSMs are brains too: the roobot's FSM reads its
/// senses and actuator levels as inputs and answers Keep with NaN and Reset
/// with the initial level it was given.
#[test]
fn the_roobot_fsm_is_a_brain_whose_keep_is_nan_and_reset_the_initial_level() {
    use animats_creatures::roobot::{HopFsm, HopParams};
    let mut fsm = HopFsm::new(HopParams::INITIAL);
    let p = HopParams::INITIAL.0;
    // In stance with the leg angle below p1: the leg and ankle are set, the
    // hip reset to its initial level (here 0.37, to tell it from 0.5).
    let mut inputs = [
        0.0,
        p[1] - 0.1,
        0.0,
        0.0,
        0.0,
        0.6,
        0.5,
        0.5,
        0.55,
        0.37,
        0.42,
    ];
    let mut out = [0.0; 3];
    fsm.think(0.0, 0.008, &inputs, &mut out);
    assert_eq!(Brain::state(&fsm), Some("stance"));
    assert!(out[0].is_finite() && out[2].is_finite());
    assert_eq!(out[1], 0.37);
    // Past p1 it leaps: the leg is kept (NaN), hip and ankle reset.
    inputs[1] = p[1] + 0.1;
    fsm.think(0.008, 0.008, &inputs, &mut out);
    assert_eq!(Brain::state(&fsm), Some("leap"));
    assert!(out[0].is_nan());
    assert_eq!((out[1], out[2]), (0.37, 0.42));
    assert_eq!(fsm.genome(), p);
    assert_eq!(fsm.bounds().len(), 14);
}
