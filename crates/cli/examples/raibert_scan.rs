//! The grid from which Raibert's hand-set gains (`roobot::raibert::START`)
//! were chosen: thrust, hip servo stiffness and damping, and the foot
//! placement gain, the rest as in START; prints every setting that hops
//! for the whole 20 s, with its distance and hops; then START itself at
//! the evaluation's step (RK4, 8 ms) and at a half and a quarter of it.
//!
//! ```sh
//! cargo run --release -p animats --example raibert_scan
//! ```

use animats_creatures::roobot::evaluate::EvalSettings;
use animats_creatures::roobot::raibert::{evaluate, START};
fn main() {
    let s = EvalSettings::default();
    for thrust in [0.05, 0.1, 0.15] {
        for kp in [2.0, 5.0, 10.0] {
            for kd in [0.1, 0.3] {
                for kv in [0.05, 0.1, 0.2] {
                    let mut g = START;
                    g[0] = thrust;
                    g[4] = kp;
                    g[5] = kd;
                    g[2] = kv;
                    let e = evaluate(g, &s).unwrap();
                    if e.time_up >= 20.0 {
                        println!(
                            "thrust {thrust} kp {kp} kd {kd} kv {kv}: {:.1} m, {} hops",
                            e.distance, e.hops
                        );
                    }
                }
            }
        }
    }
    for divide in [1.0, 2.0, 4.0] {
        let mut t = EvalSettings::default();
        t.dt /= divide;
        let e = evaluate(START, &t).unwrap();
        println!(
            "START at dt {} s: upright {} s, {:.2} m, {} hops, {}",
            t.dt, e.time_up, e.distance, e.hops, e.ending
        );
    }
}
