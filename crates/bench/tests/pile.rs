//! A thousand spheres poured onto the floor inside a ring of nailed spheres
//! tall enough to hold them: none gets out, no overlap is ever deeper than
//! the envelope, none goes below the floor, and the pile loses nearly all
//! the kinetic energy of the fall. It does not come fully to rest: resting
//! spheres end each step with up to the velocity g·h of the step's gravity,
//! and a step-to-step chatter in the heap's columns keeps several mJ (a
//! known gap: `cargo run --release -p animats-bench --example pile_rest --
//! --rows 8` shows it second by second; an ordered pyramid does rest, see
//! `crates/engine/tests/sphere_contact.rs` and docs/DESIGN.md
//! "Sphere–sphere contact").

use animats_bench::pile::{outside_ring, pile_walled};
use animats_engine::{SphereContact, SphereContactDef};

#[test]
fn a_thousand_spheres_poured_into_a_ring_lose_their_energy_without_deep_overlaps() {
    let r = 0.02;
    // A ring eight spheres tall holds the whole heap (the benchmark's, one
    // tall, lets 171 of the 1,000 out within these 4 s: `pile_rest`).
    let mut w = pile_walled(1000, r, 10, 8);
    let envelope = SphereContactDef::default().envelope;
    let h = 1e-3;
    let (mut deepest, mut peak, mut lowest) = (0.0f64, 0.0f64, f64::INFINITY);
    let mut probe = SphereContact::new(SphereContactDef::default()).unwrap();
    for _ in 0..4000 {
        w.step(h).unwrap();
        let s = w.state();
        deepest = deepest.max(probe.deepest_overlap(&s.pos, w.particles()));
        peak = peak.max(w.energy().kinetic);
        lowest = s.pos.iter().map(|x| x.y).fold(lowest, f64::min);
    }
    let left = w.energy().kinetic;
    let outside = outside_ring(&w);
    let mean = w.state().vel.iter().map(|v| v.length()).sum::<f64>() / w.len() as f64;
    println!(
        "deepest overlap {deepest:e} m, lowest centre {lowest} m, kinetic energy {peak:.3e} -> {left:.3e} J, mean speed {mean:.3e} m/s, outside the ring {outside}"
    );
    assert_eq!(outside, 0, "spheres got out of the ring");
    assert!(
        deepest <= envelope,
        "overlap {deepest} deeper than the envelope"
    );
    assert!(
        lowest >= r - 1e-12,
        "a sphere went into the floor: {lowest}"
    );
    assert!(left < 1e-3 * peak, "kept {left} of {peak} J");
    // Resting spheres carry at most about one step of gravity, g h.
    assert!(mean < 2.0 * 9.8 * h, "mean speed {mean}");
}
