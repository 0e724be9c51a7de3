//! The largest stable step for a frond of seaweed in the default current
//! (thesis §5.3), per integrator: the higher-order and symplectic methods
//! allow longer steps, and RK4's limit is what `scenes/seaworld.toml`'s
//! `max_dt` is chosen under.

use animats_bench::stability::{frond, largest_stable_world_step};
use animats_engine::IntegratorKind;

fn limit(kind: IntegratorKind) -> f64 {
    largest_stable_world_step(&|| frond(kind), 30.0, 1.0)
}

#[test]
fn rk4_allows_the_longest_step_and_seaworld_stays_under_it() {
    let (euler, midpoint, rk4, symplectic) = (
        limit(IntegratorKind::Euler),
        limit(IntegratorKind::Midpoint),
        limit(IntegratorKind::Rk4),
        limit(IntegratorKind::Symplectic),
    );
    println!("largest stable steps: euler {euler}, midpoint {midpoint}, rk4 {rk4}, symplectic {symplectic}");
    assert!(rk4 > symplectic && symplectic > midpoint && midpoint > euler);
    // For an undamped oscillator, RK4 is stable up to ωh = 2.83 and
    // symplectic Euler up to ωh = 2, while explicit Euler and midpoint grow at
    // any step (only the water's drag holds them, Euler's growth being the
    // faster): the measured limits come in that order, RK4's several times
    // explicit Euler's.
    assert!(rk4 > 5.0 * euler, "rk4 {rk4}, euler {euler}");
    let scene = animats_scene::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/seaworld.toml"
    )))
    .unwrap();
    assert!(
        scene.max_dt < rk4,
        "max_dt {} is not under RK4's limit {rk4}",
        scene.max_dt
    );
    assert!(scene.dt <= scene.max_dt);
}
