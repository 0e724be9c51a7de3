//! `simulate --output x.jsonl` records each controller's state, its sensor
//! levels and its actuator levels beside the particles; the FSM of
//! `scenes/pogo.toml` (a hopping gait written as data) hops in a steady
//! cycle.

mod common;
use common::*;

#[test]
fn jsonl_records_the_fsm_hopping_in_a_steady_cycle() {
    let dir = scratch("pogo");
    let out = dir.join("pogo.jsonl");
    let o = animats(&[
        "simulate",
        "scenes/pogo.toml",
        "--duration",
        "10",
        "--output",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o).1);
    let text = std::fs::read_to_string(&out).unwrap();
    let (mut states, mut heights, mut levels) = (Vec::new(), Vec::new(), Vec::new());
    for line in text.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        let c = &v["controllers"][0];
        assert_eq!(c["name"], "hop");
        assert_eq!(c["kind"], "fsm");
        // Its inputs are the sensors, its output the actuator, as named.
        assert_eq!(c["inputs"][0], v["sensors"]["foot_touch"]);
        assert_eq!(c["inputs"][1], v["sensors"]["leg_length"]);
        assert_eq!(c["outputs"][0], v["actuators"]["leg_muscle"]);
        states.push(c["state"].as_str().unwrap().to_string());
        heights.push(v["particles"][1]["position"][1].as_f64().unwrap());
        levels.push(c["outputs"][0].as_f64().unwrap());
    }
    assert_eq!(states.len(), 1 + 20_000, "t = 0 and every 0.5 ms step");
    // The cycle: stance → thrust → flight → stance, nothing else.
    let mut cycles = 0;
    for (a, b) in states.iter().zip(&states[1..]) {
        if a != b {
            let ok = matches!(
                (a.as_str(), b.as_str()),
                ("stance", "thrust") | ("thrust", "flight") | ("flight", "stance")
            );
            assert!(ok, "{a} → {b}");
            cycles += (b == "stance") as usize;
        }
    }
    assert!(cycles >= 20, "{cycles} hops in 10 s");
    // The muscle's rate limit: at most 5 levels/s, 0.0025 per step.
    for w in levels.windows(2) {
        assert!((w[1] - w[0]).abs() <= 0.0025 + 1e-12);
    }
    // A limit cycle: the last five peaks of the body agree within 1 cm.
    let peaks: Vec<f64> = (1..heights.len() - 1)
        .filter(|&i| {
            heights[i] > heights[i - 1] && heights[i] >= heights[i + 1] && heights[i] > 0.34
        })
        .map(|i| heights[i])
        .collect();
    let last = &peaks[peaks.len() - 5..];
    let (lo, hi) = last
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(*x), h.max(*x)));
    assert!(hi - lo < 0.01, "peaks {last:?}");
}
