//! Does a heap come to rest? 1,000 spheres poured into the ring of
//! [`animats_bench::pile`], the ring `--rows` spheres tall (default 1, the
//! benchmark's; 8 holds the whole heap in), simulated for `--seconds`
//! (default 12) at 1 ms, with sleeping at `--sleep` m/s (default off).
//! Each second it prints how many spheres sleep; the kinetic energy; how far
//! the spheres moved in that second (mean and largest) and how many moved
//! more than 1 mm; how far they travelled step by step (mean) and how far
//! they sank (mean fall of the centres); the fastest sphere's speed at the
//! step's end; the deepest overlap the contacts' passes left at a step's
//! end; and how many spheres are outside the ring. `--layers` adds, for
//! each layer of the heap (by the height of the centres, a diameter a
//! layer), how far its spheres moved in the second, in all and sideways,
//! and how far their mean position moved (a drift common to the layer,
//! against each sphere wandering its own way).
//!
//! `cargo run --release -p animats-bench --example pile_rest -- --rows 8`
// std's transcendental functions: this code draws or benchmarks, off the step path
#![allow(clippy::disallowed_methods)]

use animats_bench::pile::{outside_ring, pile_walled_with};
use animats_engine::{SphereContact, SphereContactDef};

fn main() {
    let (mut rows, mut seconds, mut layers) = (1usize, 12usize, false);
    let mut contact = SphereContactDef::default();
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        if flag == "--layers" {
            layers = true;
            continue;
        }
        if flag == "--sleep" {
            match args.next().and_then(|v| v.parse::<f64>().ok()) {
                Some(v) if v > 0.0 && v.is_finite() => contact.sleep_speed = v,
                _ => {
                    eprintln!("pile_rest: expected --sleep SPEED (m/s, > 0)");
                    std::process::exit(2);
                }
            }
            continue;
        }
        let value = args.next().and_then(|v| v.parse::<usize>().ok());
        match (flag.as_str(), value) {
            ("--rows", Some(v)) if v >= 1 => rows = v,
            ("--seconds", Some(v)) if v >= 1 => seconds = v,
            _ => {
                eprintln!(
                    "pile_rest: expected --rows N (>= 1), --seconds S (>= 1), --sleep SPEED and --layers, got {flag:?}"
                );
                std::process::exit(2);
            }
        }
    }
    let (r, h) = (0.02, 1e-3);
    let mut w = pile_walled_with(1000, r, 10, rows, contact);
    let free: Vec<usize> = (0..w.len())
        .filter(|&i| w.particles().inv_mass[i] > 0.0)
        .collect();
    let mut before = w.state().pos.clone();
    let Ok(mut probe) = SphereContact::new(SphereContactDef::default()) else {
        unreachable!("the default contact settings are valid")
    };
    println!("ring {rows} tall; per second: spheres asleep, kinetic energy, distance moved (mean, largest), moved > 1 mm, travelled step by step (mean), sank (mean), fastest at a step's end, deepest overlap left, outside the ring");
    let mut path = vec![0.0f64; w.len()];
    let mut last = w.state().pos.clone();
    for s in 1..=seconds {
        let mut left = 0.0f64;
        path.iter_mut().for_each(|p| *p = 0.0);
        for _ in 0..1000 {
            last.clone_from(&w.state().pos);
            if let Err(e) = w.step(h) {
                eprintln!("pile_rest: {e}");
                std::process::exit(1);
            }
            for ((p, x), x0) in path.iter_mut().zip(&w.state().pos).zip(&last) {
                *p += (*x - *x0).length();
            }
            left = left.max(probe.deepest_overlap(&w.state().pos, w.particles()));
        }
        let st = w.state();
        let moved: Vec<f64> = free
            .iter()
            .map(|&i| (st.pos[i] - before[i]).length())
            .collect();
        let mean = moved.iter().sum::<f64>() / moved.len() as f64;
        let largest = moved.iter().copied().fold(0.0, f64::max);
        let over = moved.iter().filter(|&&d| d > 1e-3).count();
        // The distance travelled step by step, against `mean`, the distance
        // from where the second began: much larger means back and forth.
        let travelled = free.iter().map(|&i| path[i]).sum::<f64>() / free.len() as f64;
        let sank = free.iter().map(|&i| before[i].y - st.pos[i].y).sum::<f64>() / free.len() as f64;
        let fastest = free.iter().map(|&i| st.vel[i].length()).fold(0.0, f64::max);
        let outside = outside_ring(&w);
        let asleep = w.event::<SphereContact>().map_or(0, |c| c.sleeping());
        println!(
            "t = {s:>2} s  asleep {asleep:>4}  {:.2e} J  moved {mean:.2e} / {largest:.2e} m  > 1 mm: {over:>4}  travelled {travelled:.2e} m  sank {sank:+.1e} m  fastest {fastest:.2e} m/s  overlap {left:.1e} m  outside {outside}",
            w.energy().kinetic
        );
        if layers {
            // (spheres, moved, moved sideways, sum of the moves) by layer.
            let mut bins: Vec<(usize, f64, f64, animats_engine::DVec3)> = Vec::new();
            for (k, &i) in free.iter().enumerate() {
                let layer = (st.pos[i].y / (2.0 * r)).max(0.0) as usize;
                if bins.len() <= layer {
                    bins.resize(layer + 1, (0, 0.0, 0.0, animats_engine::DVec3::ZERO));
                }
                let d = st.pos[i] - before[i];
                bins[layer].0 += 1;
                bins[layer].1 += moved[k];
                bins[layer].2 += d.x.hypot(d.z);
                bins[layer].3 += d;
            }
            for (l, &(n, all, sideways, sum)) in bins.iter().enumerate().filter(|(_, b)| b.0 > 0) {
                let n = n as f64;
                println!(
                    "    layer {l}: {n:>4} spheres, moved {:.2e} m, sideways {:.2e} m, their mean {:.2e} m",
                    all / n,
                    sideways / n,
                    (sum / n).length()
                );
            }
        }
        before = st.pos.clone();
    }
}
