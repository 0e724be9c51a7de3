//! `contacts`: spheres falling into a pile (issue 12), the broad phase's
//! cost against the number of spheres.
// std's transcendental functions: this code draws or benchmarks, off the step path
#![allow(clippy::disallowed_methods)]

use crate::{Check, Row, Timing};
use animats_engine::{DVec3, FloorDef, IntegratorKind, ParticleDef, SphereContactDef, World};
use std::time::Instant;

/// `n` spheres of radius `r` (50 g, restitution 0.3, friction 0.6/0.4)
/// dropped from a jittered cubic lattice (spacing 2.5 r) into a ring of
/// nailed spheres of the same radius on the floor, around the lattice's
/// footprint; sphere–sphere contact and the floor; symplectic Euler.
pub fn pile(n: usize, r: f64) -> World {
    pile_layers(n, r, (n as f64).cbrt().ceil() as usize)
}

/// [`pile`] from a lattice `layers` deep (and as wide as it takes): the
/// same depth, and so about the same contacts per sphere, for any `n`.
pub fn pile_layers(n: usize, r: f64, layers: usize) -> World {
    pile_walled(n, r, layers, 1)
}

/// [`pile_layers`] inside a ring `rows` spheres tall (nailed spheres
/// stacked in columns): with one row the heap of 1,000 (about five layers
/// deep once fallen) spills over the ring; with eight none can.
pub fn pile_walled(n: usize, r: f64, layers: usize, rows: usize) -> World {
    pile_walled_with(n, r, layers, rows, SphereContactDef::default())
}

/// [`pile_walled`] with the given contact settings (sleeping, say).
pub fn pile_walled_with(
    n: usize,
    r: f64,
    layers: usize,
    rows: usize,
    contact: SphereContactDef,
) -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let side = (n as f64 / layers.max(1) as f64).sqrt().ceil() as usize;
    let ring = 0.5 * side as f64 * 2.5 * r + 4.0 * r;
    let around = (std::f64::consts::TAU * ring / (2.0 * r)).floor() as usize;
    for row in 0..rows {
        for k in 0..around {
            let a = std::f64::consts::TAU * k as f64 / around as f64;
            let x = DVec3::new(ring * a.cos(), r + 2.0 * r * row as f64, ring * a.sin());
            w.add_particle(ParticleDef::new(1.0).with_radius(r).at(x).fixed())
                .unwrap();
        }
    }
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let mut jitter = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.2 * r
    };
    let start = -(side as f64 - 1.0) * 1.25 * r;
    for i in 0..n {
        let (a, b, c) = (i % side, (i / side) % side, i / (side * side));
        let x = DVec3::new(
            start + a as f64 * 2.5 * r + jitter(),
            3.0 * r + c as f64 * 2.5 * r,
            start + b as f64 * 2.5 * r + jitter(),
        );
        w.add_particle(
            ParticleDef::new(0.05)
                .with_radius(r)
                .at(x)
                .with_restitution(0.3)
                .with_friction(0.6, 0.4),
        )
        .unwrap();
    }
    w.add_floor(FloorDef::default()).unwrap();
    w.add_sphere_contact(contact).unwrap();
    w
}

/// How many particles of a [`pile_walled`] world lie further from the
/// vertical axis than the ring's nailed spheres' centres: the spheres that
/// got out.
pub fn outside_ring(w: &World) -> usize {
    let across = |x: DVec3| (x.x * x.x + x.z * x.z).sqrt();
    let pos = &w.state().pos;
    let ring = (0..w.len())
        .filter(|&i| w.particles().inv_mass[i] == 0.0)
        .map(|i| across(pos[i]))
        .fold(0.0, f64::max);
    pos.iter().filter(|&&x| across(x) > ring).count()
}

/// The step, s.
pub const DT: f64 = 1e-3;
/// Steps timed: the first half second of the fall, when the spheres land
/// and pile up.
pub const STEPS: usize = 500;

/// 1,000 and 10,000 spheres (100 and 1,000 with `quick`): steps per second
/// and the ratio of the times per step (goal: at most 12 for 10× the
/// spheres), for the larger pile both as a cube (deeper: more contacts per
/// sphere) and as deep as the smaller one (10× its footprint). Medians of
/// `runs` runs, each from the same start.
pub fn run(quick: bool, runs: usize) -> Vec<Row> {
    let (small, large) = if quick { (100, 1000) } else { (1000, 10000) };
    let depth = (small as f64).cbrt().ceil() as usize;
    let cases = [
        (small, pile(small, 0.02), format!("pile of {small} spheres")),
        (large, pile(large, 0.02), format!("pile of {large} spheres")),
        (
            large,
            pile_layers(large, 0.02, depth),
            format!("pile of {large}, {depth} layers deep"),
        ),
    ];
    let mut per_step = Vec::new();
    let mut rows = Vec::new();
    for (n, start, variant) in cases {
        // Outside the timing: how many pairs touch, on average.
        let mut probe = start.clone();
        let mut touching = 0usize;
        for _ in 0..STEPS {
            probe.step(DT).expect("the pile stays finite");
            touching += probe
                .event::<animats_engine::SphereContact>()
                .map_or(0, |c| c.touching());
        }
        let times: Vec<f64> = (0..runs)
            .map(|_| {
                let mut w = start.clone();
                let clock = Instant::now();
                for _ in 0..STEPS {
                    w.step(DT).expect("the pile stays finite");
                }
                clock.elapsed().as_secs_f64()
            })
            .collect();
        let engine = Timing::from_runs(times);
        per_step.push(engine.median / STEPS as f64);
        let mut checks = vec![
            Check::info("steps per second", STEPS as f64 / engine.median),
            Check::info(
                "touching pairs per sphere, mean over the steps",
                touching as f64 / (STEPS * n) as f64,
            ),
            Check::info("backtracks", probe.stats().backtracks as f64),
        ];
        if per_step.len() > 1 {
            checks.push(Check::target_at_most(
                "time per step against 10x fewer spheres",
                per_step[per_step.len() - 1] / per_step[0],
                12.0,
            ));
        }
        rows.push(Row {
            workload: "contacts".into(),
            variant,
            particles: start.len(),
            springs: 0,
            steps: STEPS,
            dt: DT,
            evaluations: 1,
            pairs: 0,
            engine,
            baseline: None,
            checks,
        });
    }
    rows
}
