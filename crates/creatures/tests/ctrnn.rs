//! The CTRNN against closed forms: a lone neuron's state decays as
//! exp(−t/τ) and rises to a step of input as 1 − exp(−t/τ), with the
//! error of a first-order method in the step; Beer's two-neuron network
//! oscillates; an untouched network asks for level 0.5.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_creatures::brain::Brain;
use animats_creatures::brains::{Ctrnn, CtrnnEntry};

fn entry(inputs: usize, outputs: usize, neurons: usize) -> CtrnnEntry {
    CtrnnEntry {
        name: "c".into(),
        inputs: (0..inputs).map(|i| format!("s{i}")).collect(),
        outputs: (0..outputs).map(|i| format!("o{i}")).collect(),
        neurons: Some(neurons),
        clock: None,
        tau: None,
        bias: None,
        gain: None,
        weights: None,
        input_weights: None,
    }
}

/// Runs `net` for `t` seconds at step `dt` with sensor level `level`;
/// returns neuron 0's state.
fn run(net: &mut Ctrnn, t: f64, dt: f64, level: f64) -> f64 {
    let steps = (t / dt).round() as usize;
    let mut out = vec![0.0; net.outputs];
    for k in 0..steps {
        net.think(k as f64 * dt, dt, &[level], &mut out);
    }
    net.state[0]
}

#[test]
fn a_lone_neuron_decays_as_exp_minus_t_over_tau_to_first_order() {
    let tau = 0.5;
    let mut e = entry(1, 1, 1);
    e.tau = Some(vec![tau]);
    let err = |dt: f64| {
        let mut net = e.build().unwrap();
        net.state[0] = 1.0;
        // level 0.5 is input 0: no drive, a pure leak.
        run(&mut net, 1.0, dt, 0.5) - (-1.0 / tau).exp()
    };
    let (e1, e2, e3) = (err(1e-3), err(5e-4), err(2.5e-4));
    // Implicit leak: (1 + h)^−n = exp(−t/τ)(1 + t h /(2τ) + O(h²)), h = dt/τ.
    let predicted = (-2.0f64).exp() * 2.0 * (1e-3 / tau) / 2.0;
    assert!(
        (e1 - predicted).abs() < 0.01 * predicted,
        "{e1} vs {predicted}"
    );
    for (a, b) in [(e1, e2), (e2, e3)] {
        let order = (a / b).log2();
        assert!((order - 1.0).abs() < 0.01, "order {order}");
    }
}

#[test]
fn a_step_of_input_gives_one_minus_exp() {
    // Input weight 2 on a sensor at level 1 (input 2·1 − 1 = 1): drive 2,
    // y(t) = 2 (1 − e^−t/τ); at dt = 10 µs within 1e-4 of it.
    let tau = 0.2;
    let mut e = entry(1, 1, 1);
    e.tau = Some(vec![tau]);
    e.input_weights = Some(vec![2.0]);
    for t in [0.1, 0.2, 0.5, 1.0] {
        let mut net = e.build().unwrap();
        let y = run(&mut net, t, 1e-5, 1.0);
        let exact = 2.0 * (1.0 - (-t / tau).exp());
        assert!((y - exact).abs() < 1e-4, "t {t}: {y} vs {exact}");
    }
}

#[test]
fn an_untouched_network_asks_for_the_middle_level() {
    let mut net = entry(1, 2, 4).build().unwrap();
    let mut out = [0.0; 2];
    net.think(0.0, 1e-3, &[0.5], &mut out);
    assert_eq!(out, [0.5, 0.5]);
}

#[test]
fn beers_two_neuron_network_oscillates_whatever_the_step() {
    // Beer (1995), a limit cycle: w11 = w22 = 4.5, w12 = −1 (from neuron 1
    // to 2), w21 = 1, θ = [−2.75, −1.75], τ = g = 1; rows here are "into
    // neuron i". τ = 0.1 s scales its ≈ 29 s cycle to ≈ 2.9 s.
    let mut e = entry(0, 2, 2);
    e.tau = Some(vec![0.1, 0.1]);
    e.weights = Some(vec![4.5, 1.0, -1.0, 4.5]);
    e.bias = Some(vec![-2.75, -1.75]);
    let mut periods = Vec::new();
    for dt in [4e-4, 2e-4, 1e-4] {
        let mut net = e.build().unwrap();
        let mut out = [0.0; 2];
        let (mut lo, mut hi) = (1.0f64, 0.0f64);
        let mut ups = Vec::new();
        let mut last = 0.0;
        let steps = (30.0 / dt) as usize;
        for k in 0..steps {
            net.think(k as f64 * dt, dt, &[], &mut out);
            let t = (k + 1) as f64 * dt;
            if t > 5.0 {
                lo = lo.min(out[0]);
                hi = hi.max(out[0]);
                if last < 0.5 && out[0] >= 0.5 {
                    ups.push(t);
                }
            }
            last = out[0];
        }
        assert!(hi - lo > 0.5, "dt {dt}: output swings only {lo}..{hi}");
        assert!(ups.len() >= 5, "dt {dt}: {ups:?}");
        periods.push((ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64);
    }
    // The period converges as the step shrinks (first order: differences
    // halve).
    let (d1, d2) = (periods[0] - periods[1], periods[1] - periods[2]);
    assert!((d1 / d2 - 2.0).abs() < 0.3, "periods {periods:?}");
    assert!((periods[2] - 2.9).abs() < 0.1, "periods {periods:?}");
}

#[test]
fn mistakes_are_refused_by_field() {
    let mut e = entry(1, 2, 1);
    assert_eq!(e.build().unwrap_err().field, "neurons");
    e.neurons = Some(2);
    e.tau = Some(vec![0.1, 0.0]);
    assert_eq!(e.build().unwrap_err().field, "tau");
    e.tau = None;
    e.weights = Some(vec![1.0; 3]);
    assert_eq!(e.build().unwrap_err().field, "weights");
    e.weights = None;
    e.input_weights = Some(vec![f64::NAN, 0.0]);
    assert_eq!(e.build().unwrap_err().field, "input_weights");
    e.input_weights = None;
    e.neurons = Some(1_000_001);
    assert_eq!(e.build().unwrap_err().field, "neurons");
}
