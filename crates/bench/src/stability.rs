//! `stability`: the largest stable step (thesis §5.3: "the seaweed fronds
//! become unstable when the timestep exceeds a certain threshold, which
//! varies with the strength of the water current"). For one frond of the
//! default seaweed in the default ReefWater current, and for the whole of
//! SeaWorld, bisect the step: stable means 30 simulated seconds with every
//! particle finite and none faster than a bound far above anything physical
//! in it: 1 m/s for the frond (its segments move at about 10 cm/s), 5 m/s for
//! SeaWorld (whose fastest things, sinking rocks, fall at about 1.4 m/s).
//! An exploding mode (RK4, midpoint, symplectic Euler) crosses any such bound
//! within a few steps; explicit Euler's energy grows slowly instead, so its
//! limit depends on the bound and the duration.

use crate::{Check, Row, Timing};
use animats_creatures::seaworld::{seaweed, SeaweedConstants};
use animats_engine::{Current, DVec3, FloorDef, FluidMedium, IntegratorKind, ReefWater, World};
use std::time::Instant;

/// One frond of 12 segments in the default reef current, over a floor.
pub fn frond(kind: IntegratorKind) -> World {
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    seaweed::build(&mut w, &SeaweedConstants::default(), DVec3::ZERO).expect("valid frond");
    let mut water = FluidMedium::water();
    water.current = Current::Reef(ReefWater::default());
    w.add_fluid(water).expect("valid fluid");
    w.add_floor(FloorDef::default()).expect("valid floor");
    w
}

/// True if `step` advances the system `make` builds for `seconds` without
/// blowing up.
pub fn stable(
    make: &mut dyn FnMut() -> Box<dyn FnMut(f64) -> Result<f64, ()>>,
    step: f64,
    seconds: f64,
    bound: f64,
) -> bool {
    let mut advance = make();
    let n = (seconds / step).ceil() as usize;
    for _ in 0..n {
        match advance(step) {
            Ok(speed) if speed <= bound => {}
            _ => return false,
        }
    }
    true
}

/// Bisects the largest stable step in [lo, hi] to 1% (assumes lo is stable).
pub fn largest_stable_step(
    make: &mut dyn FnMut() -> Box<dyn FnMut(f64) -> Result<f64, ()>>,
    seconds: f64,
    bound: f64,
) -> f64 {
    let (mut lo, mut hi) = (1e-4, 0.2);
    if stable(make, hi, seconds, bound) {
        return hi;
    }
    while hi / lo > 1.01 {
        let mid = (lo * hi).sqrt();
        if stable(make, mid, seconds, bound) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The speed of the fastest particle, m/s.
pub fn fastest(w: &World) -> f64 {
    w.state().vel.iter().map(|v| v.length()).fold(0.0, f64::max)
}

/// [`largest_stable_step`] for the worlds `make` builds, judged by their
/// fastest particle.
pub fn largest_stable_world_step(make: &dyn Fn() -> World, seconds: f64, bound: f64) -> f64 {
    let mut search = || -> Box<dyn FnMut(f64) -> Result<f64, ()>> {
        let mut w = make();
        Box::new(move |h| {
            w.step(h).map_err(|_| ())?;
            Ok(fastest(&w))
        })
    };
    largest_stable_step(&mut search, seconds, bound)
}

/// Runs the search for every explicit integrator: the frond, and SeaWorld;
/// then implicit Euler at ten times symplectic Euler's largest stable step
/// on the stiff bodies of [`crate::stiff`].
pub fn run(seaworld: Option<&std::path::Path>) -> Vec<Row> {
    let explicit = || IntegratorKind::ALL.into_iter().filter(|k| k.is_explicit());
    let mut rows = Vec::new();
    for kind in explicit() {
        let t = Instant::now();
        let limit = largest_stable_world_step(&|| frond(kind), 30.0, 1.0);
        rows.push(row("seaweed frond", kind, limit, t.elapsed().as_secs_f64()));
    }
    if let Some(path) = seaweed_scene(seaworld) {
        for kind in explicit() {
            let t = Instant::now();
            let p = path.clone();
            let mut make = move || -> Box<dyn FnMut(f64) -> Result<f64, ()>> {
                let mut s = animats_scene::load(&p).expect("SeaWorld loads");
                s.world.set_integrator(kind);
                Box::new(move |h| {
                    s.step(h).map_err(|_| ())?;
                    Ok(fastest(&s.world))
                })
            };
            let limit = largest_stable_step(&mut make, 30.0, 5.0);
            rows.push(row("seaworld", kind, limit, t.elapsed().as_secs_f64()));
        }
    }
    use crate::stiff::{bent_frond, chain, hanging_cloth, ten_times};
    let cloth = |kind| hanging_cloth(32, crate::mass_spring::STIFFNESS, kind);
    let frond_bent = |kind| bent_frond(1.0, kind);
    // (what, how to build it, seconds of the search, speed bound in m/s)
    type Case<'a> = (&'a str, &'a dyn Fn(IntegratorKind) -> World, f64, f64);
    let cases: [Case; 4] = [
        ("hanging cloth-32", &cloth, 5.0, 50.0),
        ("chain-64", &chain, 10.0, 50.0),
        ("bent seaweed frond, still water", &frond_bent, 10.0, 5.0),
        ("seaweed frond, reef current", &frond, 30.0, 1.0),
    ];
    for (what, make, seconds, bound) in cases {
        let t = Instant::now();
        let o = ten_times(make, seconds, bound, 10.0);
        let mut r = row(
            what,
            IntegratorKind::Implicit,
            o.implicit,
            t.elapsed().as_secs_f64(),
        );
        r.variant = format!("{what}, implicit at 10x symplectic's step");
        r.checks = vec![
            Check::info("symplectic: largest stable step, s", o.symplectic),
            Check::info("implicit: step taken, s", o.implicit),
            Check::at_least("implicit: finite (1 = yes)", o.finite as u8 as f64, 1.0),
            Check::at_most("implicit: fastest speed, m/s", o.fastest, bound),
            Check::info("implicit: largest energy rise in a step, J", o.largest_rise),
        ];
        rows.push(r);
    }
    rows
}

fn seaweed_scene(p: Option<&std::path::Path>) -> Option<std::path::PathBuf> {
    p.filter(|p| p.exists()).map(|p| p.to_path_buf())
}

fn row(what: &str, kind: IntegratorKind, limit: f64, seconds: f64) -> Row {
    Row {
        workload: "stability".into(),
        variant: format!("{what}, {}", kind.name()),
        particles: 0,
        springs: 0,
        steps: 0,
        dt: limit,
        evaluations: kind.evaluations(),
        pairs: 0,
        engine: Timing::from_runs(vec![seconds]),
        baseline: None,
        checks: vec![Check::info("largest stable step, s", limit)],
    }
}
