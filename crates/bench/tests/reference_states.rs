//! The engine, driven through its public API, reproduces the reference final
//! states published with the standard workloads (`docs/WORKLOADS.md`):
//! an end-to-end check of springs, gravity, the floor event and two
//! integrators against independent implementations.

use animats_bench::{allpairs, mass_spring, nbody5};
use animats_engine::IntegratorKind;

#[test]
fn chain_and_cloth_end_where_the_reference_loops_end() {
    for (name, spec) in [
        ("chain-64", mass_spring::chain64()),
        ("cloth-32", mass_spring::cloth(32)),
    ] {
        for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
            let mut w = mass_spring::engine_world(&spec, kind);
            for _ in 0..mass_spring::STEPS {
                w.step(mass_spring::DT).unwrap();
            }
            let s = mass_spring::summarise(&w.state().pos, &w.state().vel, &spec.pinned);
            let (cx, cy, ke) = mass_spring::reference(name, kind).unwrap();
            // The table prints 7 significant digits; floor bounces amplify
            // rounding differences between peers to about 1e-6 m (WORKLOADS.md).
            assert!(
                (s.com.x - cx).abs() < 1e-6,
                "{name} {kind}: com_x {}",
                s.com.x
            );
            assert!(
                (s.com.y - cy).abs() < 1e-6,
                "{name} {kind}: com_y {}",
                s.com.y
            );
            assert!(
                (s.kinetic - ke).abs() < 1e-6 * ke,
                "{name} {kind}: kinetic {}",
                s.kinetic
            );
            assert!(s.finite && s.min_y >= 0.0);
        }
    }
}

#[test]
fn cloth_spring_counts_match_the_workload_definition() {
    assert_eq!(mass_spring::cloth(32).edges.len(), 3906);
    assert_eq!(mass_spring::cloth(128).edges.len(), 64770);
    assert_eq!(mass_spring::cloth(128).positions.len(), 16384);
}

#[test]
fn nbody5_through_the_user_force_matches_the_published_energies() {
    let mut w = nbody5::engine_world();
    assert!((nbody5::world_energy(&w) - nbody5::E0).abs() < 5e-10);
    for _ in 0..1000 {
        w.step(nbody5::DT).unwrap();
    }
    assert!(
        (nbody5::world_energy(&w) - nbody5::E1000).abs() < 5e-10,
        "{}",
        nbody5::world_energy(&w)
    );
    // And it follows the reference algorithm step for step.
    let mut r = nbody5::Reference::new();
    for _ in 0..1000 {
        r.advance(nbody5::DT);
    }
    assert!((nbody5::world_energy(&w) - r.energy()).abs() < 1e-13);
}

#[test]
fn nbody5_through_the_built_in_force_matches_the_published_energies() {
    let mut w = nbody5::builtin_world();
    assert!((nbody5::world_energy(&w) - nbody5::E0).abs() < 5e-10);
    let mut r = nbody5::Reference::new();
    for _ in 0..1000 {
        w.step(nbody5::DT).unwrap();
        r.advance(nbody5::DT);
    }
    let e = nbody5::world_energy(&w);
    assert!((e - nbody5::E1000).abs() < 5e-10, "{e}");
    // The same orbits as the reference algorithm, to rounding (its sums
    // are in another order).
    for (k, p) in w.particle_ids().enumerate() {
        let d = (w.position(p) - r.bodies[k].0).length();
        assert!(d < 1e-10, "body {k} is {d} AU from the reference");
    }
}

#[test]
fn allpairs_matches_the_reference_energy_and_shape() {
    let mut w = allpairs::engine_world();
    for _ in 0..allpairs::STEPS {
        w.step(allpairs::DT).unwrap();
    }
    let (x, v) = (&w.state().pos, &w.state().vel);
    let (e0, e100, _, com, rms) = allpairs::REFERENCE;
    let e_start = allpairs::energy(
        &allpairs::positions(),
        &vec![animats_engine::DVec3::ZERO; allpairs::N],
    );
    assert!((e_start - e0).abs() < 1e-12, "E(0) = {e_start}");
    assert!(
        (allpairs::energy(x, v) - e100).abs() < 1e-12,
        "E(100) = {}",
        allpairs::energy(x, v)
    );
    let (c, r) = allpairs::shape(x);
    assert!(
        (c - com).abs() < 5e-7 && (r - rms).abs() < 1e-10,
        "com_x {c}, rms {r}"
    );
}
