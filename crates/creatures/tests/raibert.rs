//! Raibert's three-part controller on the roobot's body does what each of
//! its parts is for: the stance thrust sets the hopping height, the foot
//! placement sets the forward speed, and a hand-set controller hops for the
//! whole 20 s; evaluations are deterministic.

use animats_creatures::roobot::evaluate::{Ending, EvalSettings};
use animats_creatures::roobot::raibert::{evaluate, evaluate_with, START};

/// Mean of the hip's highest point in each flight after the first 5 s, and
/// the mean forward speed over the last 10 s.
fn gait(gains: [f64; 8]) -> (f64, f64, Ending) {
    let settings = EvalSettings::default();
    let (mut apexes, mut top, mut x10) = (Vec::new(), f64::MIN, None);
    let mut last_x = 0.0;
    let e = evaluate_with(gains, &settings, |w, r| {
        let hip = w.position(r.body.hip);
        let flying = !r.foot_down(w);
        if w.time() > 5.0 {
            if flying {
                top = top.max(hip.y);
            } else if top > f64::MIN {
                apexes.push(top);
                top = f64::MIN;
            }
        }
        if (w.time() - 10.0).abs() < 0.5 * settings.dt {
            x10 = Some(hip.x);
        }
        last_x = hip.x;
    })
    .unwrap();
    let apex = apexes.iter().sum::<f64>() / apexes.len().max(1) as f64;
    let speed = x10.map_or(f64::NAN, |x| (last_x - x) / 10.0);
    (apex, speed, e.ending)
}

#[test]
fn the_hand_set_gains_hop_for_20_s_and_evaluations_repeat() {
    let settings = EvalSettings::default();
    let a = evaluate(START, &settings).unwrap();
    let b = evaluate(START, &settings).unwrap();
    assert_eq!(a, b);
    println!("Raibert, hand-set gains: {a:?}");
    assert_eq!(a.ending, Ending::Timeout, "{a:?}");
    assert!(a.hops > 20 && a.distance > 5.0, "{a:?}");
}

#[test]
fn more_stance_thrust_hops_higher() {
    let mut apexes = Vec::new();
    for thrust in [0.1, 0.125, 0.15] {
        let mut g = START;
        g[0] = thrust;
        let (apex, _, ending) = gait(g);
        println!("thrust {thrust}: apex {apex:.3} m ({ending:?})");
        assert_eq!(ending, Ending::Timeout);
        apexes.push(apex);
    }
    assert!(apexes[0] < apexes[1] && apexes[1] < apexes[2], "{apexes:?}");
}

#[test]
fn the_speed_wanted_sets_the_speed_it_hops_at() {
    let mut speeds = Vec::new();
    for wanted in [0.5, 0.75, 1.0] {
        let mut g = START;
        g[3] = wanted;
        g[2] = 0.15;
        let (_, speed, ending) = gait(g);
        println!("wanted {wanted} m/s: {speed:.3} m/s ({ending:?})");
        assert_eq!(ending, Ending::Timeout);
        speeds.push(speed);
    }
    assert!(speeds[0] < speeds[1] && speeds[1] < speeds[2], "{speeds:?}");
    // Tracked within a third.
    for (s, w) in speeds.iter().zip([0.5, 0.75, 1.0]) {
        assert!((s - w).abs() < w / 3.0, "{s} m/s for {w} wanted");
    }
}
