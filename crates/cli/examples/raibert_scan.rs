//! The grid from which Raibert's hand-set gains (`roobot::raibert::START`)
//! were chosen: thrust, hip servo stiffness and damping, and the foot
//! placement gain, the rest as in START; prints every setting that hops
//! for the whole 20 s, with its distance; then START itself at the
//! evaluation's step (RK4, 8 ms) and at a half and a quarter of it. The
//! roobot is the thesis's scene (`scenes/hop_evolver.toml`) with
//! `brain = "raibert"`.
//!
//! ```sh
//! cargo run --release -p animats --example raibert_scan
//! ```

use animats_creatures::roobot::raibert::START;
use animats_scene::evaluate::{evaluate, Evaluation, SceneProblem};

fn main() {
    let text = animats_scene::HOP_EVOLVER.replace("params = \"initial\"", "brain = \"raibert\"");
    let problem = SceneProblem::parse(&text, "raibert.toml").expect("the thesis's scene");
    let at = |g: &[f64], divide: f64| -> Evaluation {
        let mut scene = problem.scene(g).expect("gains");
        scene.dt /= divide;
        evaluate(scene).expect("an evaluation")
    };
    for thrust in [0.05, 0.1, 0.15] {
        for kp in [2.0, 5.0, 10.0] {
            for kd in [0.1, 0.3] {
                for kv in [0.05, 0.1, 0.2] {
                    let mut g = START;
                    g[0] = thrust;
                    g[4] = kp;
                    g[5] = kd;
                    g[2] = kv;
                    let e = at(&g, 1.0);
                    if e.time >= 20.0 {
                        println!(
                            "thrust {thrust} kp {kp} kd {kd} kv {kv}: {:.1} m",
                            e.distance
                        );
                    }
                }
            }
        }
    }
    for divide in [1.0, 2.0, 4.0] {
        let e = at(&START, divide);
        println!(
            "START at dt {} s: upright {} s, {:.2} m, {}",
            0.008 / divide,
            e.time,
            e.distance,
            e.ended
        );
    }
}
