//! The controller kinds a scene declares, against their definitions:
//! the oscillator's formula, a network computed by hand, FSM timing and
//! thresholds, and genomes that round-trip.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_creatures::brain::Brain;
use animats_creatures::brains::{
    Condition, Fsm, FsmState, Neural, Oscillator, OscillatorEntry, Transition,
};
use std::f64::consts::{PI, TAU};

#[test]
fn the_oscillator_is_offset_plus_amplitude_times_sine() {
    let mut o = Oscillator {
        frequency: 1.5,
        amplitude: vec![0.4, 0.2],
        phase: vec![0.0, PI / 3.0],
        offset: vec![0.5, 0.3],
        duty: None,
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
fn a_skewed_oscillator_rises_for_its_duty_and_half_is_the_sine() {
    let (f, amp, off) = (1.25, 0.4, 0.5);
    let mut o = Oscillator {
        frequency: f,
        amplitude: vec![amp, amp],
        phase: vec![0.7, -2.0],
        offset: vec![off, off],
        duty: Some(vec![0.5, 0.2]),
    };
    let mut out = [0.0; 2];
    // 1000 samples a cycle over two cycles: output 0 is the sine; output 1
    // rises from trough to crest in 0.2 of a cycle and falls in 0.8.
    let dt = 1.0 / (1000.0 * f);
    let (mut rising, mut falling) = (0usize, 0usize);
    let mut last = f64::NAN;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..2000 {
        let t = k as f64 * dt;
        o.think(t, dt, &[], &mut out);
        let sine = off + amp * (TAU * f * t + 0.7).sin();
        assert!(
            (out[0] - sine).abs() < 1e-12,
            "duty 0.5 at t {t}: {} against {sine}",
            out[0]
        );
        if last.is_finite() {
            if out[1] > last {
                rising += 1;
            } else {
                falling += 1;
            }
        }
        last = out[1];
        lo = lo.min(out[1]);
        hi = hi.max(out[1]);
    }
    // 1999 intervals: 0.2 of them rising, to within the two turns a cycle.
    assert!(
        (rising as f64 - 0.2 * 1999.0).abs() <= 4.0,
        "rising {rising} of 1999"
    );
    assert_eq!(rising + falling, 1999);
    assert!((lo - (off - amp)).abs() < 1e-5 && (hi - (off + amp)).abs() < 1e-5);
    // The trough is where the sine's is: at 2π f t + phase = −π/2.
    let t_trough = (1.5 * PI + 2.0) / (TAU * f);
    o.think(t_trough, dt, &[], &mut out);
    assert!((out[1] - (off - amp)).abs() < 1e-12, "{}", out[1]);
    // and the crest a fifth of a cycle later.
    o.think(t_trough + 0.2 / f, dt, &[], &mut out);
    assert!((out[1] - (off + amp)).abs() < 1e-12, "{}", out[1]);

    // Genome: the duties after the offsets; each must stay inside (0, 1).
    let g = o.genome();
    assert_eq!(g.len(), 1 + 4 * 2);
    assert_eq!(&g[7..], &[0.5, 0.2]);
    let mut p = o.clone();
    p.set_genome(&g).unwrap();
    assert_eq!(p, o);
    for bad in [0.0, 1.0, -0.3] {
        let mut h = g.clone();
        h[8] = bad;
        assert!(p.set_genome(&h).unwrap_err().contains("duty"), "{bad}");
    }
    assert_eq!(o.bounds()[8], (0.1, 0.9));

    // The entry: a duty per output, each strictly inside (0, 1).
    let entry = |duty: Vec<f64>| OscillatorEntry {
        name: "c".into(),
        outputs: vec!["a".into(), "b".into()],
        frequency: None,
        amplitude: None,
        phase: None,
        offset: None,
        duty: Some(duty),
    };
    assert!(entry(vec![0.3, 0.6]).build().is_ok());
    assert!(entry(vec![0.3]).build().is_err());
    let e = entry(vec![0.3, 1.0]).build().unwrap_err();
    assert!(e.to_string().contains("duty"), "{e}");
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
