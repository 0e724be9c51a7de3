//! Implicit Euler at ten times the largest step at which symplectic Euler is
//! stable (found by the bench's stability search): a hanging cloth-32,
//! chain-64 and a SeaWorld seaweed frond stay finite, and their total
//! mechanical energy never rises from one step to the next.

use animats_bench::stiff::{bent_frond, chain, hanging_cloth, ten_times, Outcome};
use animats_engine::IntegratorKind;

fn check(what: &str, o: Outcome) {
    println!(
        "{what}: symplectic stable to {:.4e} s; implicit at {:.4e} s: finite {}, energy {:.6e} -> {:.6e} J, largest rise over a step {:.3e} J",
        o.symplectic, o.implicit, o.finite, o.energy.0, o.energy.1, o.largest_rise
    );
    assert!(
        o.finite,
        "{what}: implicit Euler blew up at {} s",
        o.implicit
    );
    // Rounding in a sum of thousands of energies of order |E| is ~1e-13 |E|.
    let rounding = 1e-12 * o.energy.0.abs().max(1e-3);
    assert!(
        o.largest_rise <= rounding,
        "{what}: energy rose by {:e} J in one step",
        o.largest_rise
    );
    assert!(o.energy.1 < o.energy.0, "{what}: no energy was lost");
}

#[test]
fn hanging_cloth_32_at_ten_times_symplectics_step() {
    let make =
        |kind: IntegratorKind| hanging_cloth(32, animats_bench::mass_spring::STIFFNESS, kind);
    check("hanging cloth-32", ten_times(&make, 5.0, 50.0, 10.0));
}

#[test]
fn chain_64_at_ten_times_symplectics_step() {
    check("chain-64", ten_times(&chain, 10.0, 50.0, 10.0));
}

#[test]
fn seaweed_frond_at_ten_times_symplectics_step() {
    let make = |kind: IntegratorKind| bent_frond(1.0, kind);
    check("seaweed frond", ten_times(&make, 10.0, 5.0, 10.0));
}

#[test]
fn seaweed_frond_in_the_reef_current_stays_finite_at_ten_times() {
    // The current drives the frond, so its energy may rise: only finiteness
    // and the search's speed bound (1 m/s) are asserted.
    let o = ten_times(&animats_bench::stability::frond, 30.0, 1.0, 10.0);
    println!(
        "frond in the reef current: symplectic stable to {:.4e} s; implicit at {:.4e} s: finite {}",
        o.symplectic, o.implicit, o.finite
    );
    assert!(o.finite);
    assert!(o.fastest <= 1.0, "fastest particle {} m/s", o.fastest);
}
