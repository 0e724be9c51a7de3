//! `scene-load`: parsing and building a large scene file, the cloth of
//! `bench/scenes/cloth.py` (SIDE × SIDE beads, springs to the grid
//! neighbours) written as text here, for sides 128 and 256 (16 and 32
//! with `--quick`). Loading once counted every entry's line from the start
//! of the file, quadratic in its size (a 16,384-particle cloth took 35 s);
//! this row keeps that in view: the larger file, four times the bytes,
//! should take about four times as long. (From side 64 to 128 the time per
//! byte doubles as the parsed document, about 37 bytes of memory per byte
//! of text, outgrows the caches; from 128 to 256 it is flat again.)

use crate::{measure, Check, Row};
use std::fmt::Write;

/// The cloth scene that `bench/scenes/cloth.py` writes for `side` (its
/// text, but for a final blank line).
pub fn cloth_scene(side: usize) -> String {
    let h = 1.0 / (side - 1) as f64;
    let mut out = String::from(
        "[world]\ngravity = [0.0, -9.8, 0.0]\ndt = 0.0001\nintegrator = \"symplectic\"\nduration = 0.1\n\n",
    );
    for i in 0..side {
        for j in 0..side {
            let fixed = j == side - 1 && (i == 0 || i == side - 1);
            // Writing to a String cannot fail.
            let _ = write!(
                out,
                "[[particle]]\nname = \"p{i}_{j}\"\nmass = 0.001\nradius = 0.002\nposition = [{:.6}, {:.6}, 0.0]\n{}\n",
                i as f64 * h,
                1.0 + j as f64 * h,
                if fixed { "fixed = true\n" } else { "" }
            );
        }
    }
    let spring = |out: &mut String, a: (usize, usize), b: (usize, usize)| {
        let _ = write!(
            out,
            "[[spring]]\na = \"p{}_{}\"\nb = \"p{}_{}\"\nstiffness = 100.0\ndamping = 0.01\n\n",
            a.0, a.1, b.0, b.1
        );
    };
    for i in 0..side {
        for j in 0..side {
            if i + 1 < side {
                spring(&mut out, (i, j), (i + 1, j));
            }
            if j + 1 < side {
                spring(&mut out, (i, j), (i, j + 1));
            }
        }
    }
    out
}

/// One row per side: the median time to parse and build the scene, with
/// its particle and spring counts checked; the larger side's row adds the
/// time per byte against the smaller's (goal: at most 1.5, i.e. linear
/// within noise and the larger file's cache misses).
pub fn run(quick: bool, runs: usize) -> Vec<Row> {
    let sides = if quick { [16, 32] } else { [128, 256] };
    let mut rows: Vec<Row> = Vec::new();
    let mut per_byte = Vec::new();
    for side in sides {
        let text = cloth_scene(side);
        let (timing, scene) = measure(
            runs,
            || None,
            |s| *s = Some(animats_scene::parse(&text, "cloth.toml")),
        );
        let (particles, springs) = match scene {
            Some(Ok(scene)) => (scene.world.len(), scene.world.forces().springs.len()),
            // Reported through the checks below (0 particles fails them).
            _ => (0, 0),
        };
        per_byte.push(timing.median / text.len() as f64);
        let mut checks = vec![
            Check::new("particles", particles as f64, (side * side) as f64, 0.0),
            Check::new(
                "springs",
                springs as f64,
                (2 * side * (side - 1)) as f64,
                0.0,
            ),
            Check::info("megabytes", text.len() as f64 / 1e6),
            Check::info(
                "megabytes per second",
                text.len() as f64 / 1e6 / timing.median,
            ),
        ];
        if let [small, large] = per_byte[..] {
            checks.push(Check::target_at_most(
                "time per byte against the 4x smaller file",
                large / small,
                1.5,
            ));
        }
        rows.push(Row {
            workload: "scene-load".into(),
            variant: format!("cloth-{side} scene file, parse and build"),
            particles,
            springs,
            steps: 1,
            dt: 0.0,
            evaluations: 0,
            pairs: 0,
            engine: timing,
            baseline: None,
            checks,
        });
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The text loads into the cloth it describes: counts, a nailed top
    /// corner and a free bead at the grid spacing.
    #[test]
    fn the_cloth_scene_loads_as_the_cloth() {
        let side = 5;
        let scene = animats_scene::parse(&cloth_scene(side), "cloth.toml").expect("loads");
        let w = &scene.world;
        assert_eq!(w.len(), 25);
        assert_eq!(w.forces().springs.len(), 2 * 5 * 4);
        let p = w.particles();
        let fixed: Vec<usize> = (0..25).filter(|&k| p.fixed[k]).collect();
        // Row-major in (i, j): the top corners are (0, 4) and (4, 4).
        assert_eq!(fixed, vec![4, 24]);
        let s = w.state();
        assert!((s.pos[1].y - 1.25).abs() < 1e-12, "{:?}", s.pos[1]);
    }
}
