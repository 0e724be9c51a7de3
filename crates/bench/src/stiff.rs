//! Stiff bodies for the implicit integrator: a cloth hanging from two
//! corners, chain-64 without its floor, and a seaweed frond let go from a
//! bent start in still water; each world's total mechanical energy (with the
//! water's buoyancy, which the engine's `energy()` leaves out); the check
//! that implicit Euler stays finite and never gains energy at ten times the
//! largest step at which symplectic Euler is stable; and the race of the
//! two on a stiff, damped curtain of cloth-128 ([`race`]).
// std's transcendental functions: this code draws or benchmarks, off the step path
#![allow(clippy::disallowed_methods)]

use crate::mass_spring::{self, spring_world, DAMPING, SPACING, STIFFNESS};
use crate::stability::{self, largest_stable_world_step};
use animats_creatures::seaworld::{seaweed, SeaweedConstants};
use animats_engine::{DVec3, FluidMedium, IntegratorKind, LinearDrag, Solver, Targets, World};
use std::time::Instant;

/// The cloth-N grid (structural and shear springs of the workload's
/// stiffness `k` and damping), flat at height 1 m, pinned at the two corners
/// of its first row, falling under gravity; no floor.
pub fn hanging_cloth(n: usize, k: f64, kind: IntegratorKind) -> World {
    let mut spec = mass_spring::cloth(n);
    for (p, x) in spec.positions.iter_mut().enumerate() {
        x.y = 1.0; // flat
        spec.pinned[p] = p == 0 || p == n - 1;
    }
    spring_world(&spec, k, DAMPING, kind)
}

/// chain-64 (the workload's chain, pinned at one end, swinging down) without
/// the workload's floor.
pub fn chain(kind: IntegratorKind) -> World {
    spring_world(&mass_spring::chain64(), STIFFNESS, DAMPING, kind)
}

/// The default seaweed frond (SeaWorld's) in still water, bent over by
/// `tilt` radians about its base, let go.
pub fn bent_frond(tilt: f64, kind: IntegratorKind) -> World {
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let frond =
        seaweed::build(&mut w, &SeaweedConstants::default(), DVec3::ZERO).expect("valid frond");
    let base = w.position(frond.particles[0]);
    let (s, c) = tilt.sin_cos();
    for &p in &frond.particles[1..] {
        let r = w.position(p) - base;
        let turned = DVec3::new(r.x * c + r.y * s, -r.x * s + r.y * c, r.z);
        w.set_position(p, base + turned).expect("finite position");
    }
    w.add_fluid(FluidMedium::water()).expect("valid fluid");
    w
}

/// Kinetic plus potential energy, J, with each fluid's buoyancy counted as
/// the potential `−F·x` of its constant upthrust.
pub fn mechanical_energy(w: &World) -> f64 {
    let g = w.forces().g();
    let (p, s) = (w.particles(), w.state());
    let mut buoyancy = 0.0;
    for fluid in w.forces().fluids() {
        fluid.targets.for_each(w.len(), |i| {
            let upthrust = g * (-p.volume[i] * fluid.density);
            buoyancy -= upthrust.dot(s.pos[i]);
        });
    }
    w.energy().total() + buoyancy
}

/// What [`ten_times`] found.
#[derive(Clone, Copy, Debug)]
pub struct Outcome {
    /// Symplectic Euler's largest stable step, s.
    pub symplectic: f64,
    /// The step implicit Euler took, s.
    pub implicit: f64,
    /// Whether every particle stayed finite.
    pub finite: bool,
    /// The largest rise of the total energy over one step, J (≤ 0 when it
    /// never rose).
    pub largest_rise: f64,
    /// The total energy at the start and the end, J.
    pub energy: (f64, f64),
    /// The fastest speed of any particle at the end of any step, m/s.
    pub fastest: f64,
}

/// Finds symplectic Euler's largest stable step for `make` (the bench's
/// stability search: `seconds` simulated, no particle faster than `bound`),
/// then runs implicit Euler at `factor` times it for the same time.
pub fn ten_times(
    make: &dyn Fn(IntegratorKind) -> World,
    seconds: f64,
    bound: f64,
    factor: f64,
) -> Outcome {
    let symplectic =
        largest_stable_world_step(&|| make(IntegratorKind::Symplectic), seconds, bound);
    let h = factor * symplectic;
    let mut w = make(IntegratorKind::Implicit);
    let e0 = mechanical_energy(&w);
    let (mut last, mut largest_rise, mut finite) = (e0, f64::NEG_INFINITY, true);
    let mut fastest = 0.0f64;
    for _ in 0..(seconds / h).ceil() as usize {
        if w.step(h).is_err() {
            finite = false;
            break;
        }
        fastest = fastest.max(stability::fastest(&w));
        let e = mechanical_energy(&w);
        largest_rise = largest_rise.max(e - last);
        last = e;
    }
    Outcome {
        symplectic,
        implicit: h,
        finite,
        largest_rise,
        energy: (e0, last),
        fastest,
    }
}

/// The curtain's spring stiffness, N/m: 40× the workload's, so that it
/// stretches by about 5 cm under its own weight.
pub const CURTAIN_STIFFNESS: f64 = 4000.0;
/// The curtain's spring damping, N s/m (`c/m` = 1000 /s: a strongly damped
/// cloth, whose explicit step this limits as much as the stiffness does).
pub const CURTAIN_DAMPING: f64 = 1.0;
/// The curtain's linear drag on each particle, N s/m: the springs' damping
/// acts only along them and cannot settle the curtain's swinging, this
/// damps every motion at `b/2m` = 0.5 /s, so the curtain comes to rest
/// within the 10 s (amplitudes fall by e⁻⁵).
pub const CURTAIN_DRAG: f64 = 1e-3;
/// The race's simulated time, s.
pub const RACE_SECONDS: f64 = 10.0;
/// How close the final centre of mass must come to the reference's, m.
pub const RACE_TOLERANCE: f64 = 0.01;
/// The implicit solver's tolerance in the race.
pub const RACE_SOLVER_TOLERANCE: f64 = 1e-3;

/// The cloth-N grid (the workload's masses, spacing and springs) hung as a
/// curtain: vertical, in the plane z = 0, from its two top corners, at rest
/// and unstretched at the start, with springs of stiffness `k` and damping
/// `c` and linear drag `drag` (N s/m) on every particle. It stays in its
/// plane (nothing pushes it out).
pub fn curtain(n: usize, k: f64, c: f64, drag: f64, kind: IntegratorKind) -> World {
    let mut spec = mass_spring::cloth(n);
    let top = 1.0 + n as f64 * SPACING;
    for (p, x) in spec.positions.iter_mut().enumerate() {
        let (i, j) = (p / n, p % n);
        *x = DVec3::new(j as f64 * SPACING, top - i as f64 * SPACING, 0.0);
        spec.pinned[p] = p == 0 || p == n - 1;
    }
    let mut w = spring_world(&spec, k, c, kind);
    if drag > 0.0 {
        w.add_linear_drag(LinearDrag {
            coefficient: drag,
            targets: Targets::All,
        })
        .expect("valid drag");
    }
    w
}

/// One timed run of the race.
#[derive(Clone, Debug)]
pub struct Leg {
    /// The integrator.
    pub kind: IntegratorKind,
    /// Its step, s.
    pub h: f64,
    /// Wall time, s.
    pub seconds: f64,
    /// The final centre of mass, m.
    pub com: DVec3,
    /// Conjugate-gradient iterations a step (0 for symplectic Euler).
    pub iterations: f64,
    /// (time, total energy) about every 20 ms.
    pub energy: Vec<(f64, f64)>,
    /// Whether it stayed finite.
    pub finite: bool,
}

/// Simulates `RACE_SECONDS` of the cloth-`n` curtain (with linear drag
/// `drag`) with `kind` at step `h`.
pub fn leg(n: usize, drag: f64, kind: IntegratorKind, h: f64) -> Leg {
    let mut w = curtain(n, CURTAIN_STIFFNESS, CURTAIN_DAMPING, drag, kind);
    w.set_solver(Solver {
        tolerance: RACE_SOLVER_TOLERANCE,
        ..Solver::default()
    })
    .expect("valid solver settings");
    let steps = (RACE_SECONDS / h).round() as usize;
    let every = ((0.02 / h).round() as usize).max(1);
    let mut energy = vec![(0.0, w.energy().total())];
    let (mut iterations, mut finite) = (0u64, true);
    let start = Instant::now();
    for i in 1..=steps {
        if w.step(h).is_err() {
            finite = false;
            break;
        }
        iterations += w.last_step().solver_iterations as u64;
        if i % every == 0 {
            // Outside the timing would be fairer, but it is one energy sum
            // per 20 ms of simulation: under 1 % of either run.
            energy.push((w.time(), w.energy().total()));
        }
    }
    Leg {
        kind,
        h,
        seconds: start.elapsed().as_secs_f64(),
        com: w.centre_of_mass(),
        iterations: iterations as f64 / steps as f64,
        energy,
        finite,
    }
}

/// The race: the reference, symplectic Euler at its largest stable step,
/// and implicit Euler at each step tried.
#[derive(Clone, Debug)]
pub struct Race {
    /// The cloth's size.
    pub n: usize,
    /// The linear drag on each particle, N s/m.
    pub drag: f64,
    /// Symplectic Euler's largest stable step, s.
    pub symplectic_step: f64,
    /// Symplectic Euler at a quarter of it.
    pub reference: Leg,
    /// Symplectic Euler at it.
    pub symplectic: Leg,
    /// Implicit Euler at every step tried, largest first.
    pub implicit: Vec<Leg>,
}

impl Race {
    /// How far `leg` ended from the reference, m.
    pub fn error(&self, leg: &Leg) -> f64 {
        (leg.com - self.reference.com).length()
    }

    /// The fastest implicit run within [`RACE_TOLERANCE`] of the reference.
    pub fn best(&self) -> Option<&Leg> {
        self.implicit
            .iter()
            .filter(|l| l.finite && self.error(l) <= RACE_TOLERANCE)
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
    }
}

/// Symplectic Euler's largest stable step on the cloth-`n` curtain with
/// linear drag `drag`, by the bench's stability search over its first second
/// (no particle faster than 50 m/s). A larger cloth has a higher top mode
/// (its grid comes closer to the bound of an infinite one), so the search
/// runs on the cloth itself.
pub fn symplectic_step(n: usize, drag: f64) -> f64 {
    let make = || {
        curtain(
            n,
            CURTAIN_STIFFNESS,
            CURTAIN_DAMPING,
            drag,
            IntegratorKind::Symplectic,
        )
    };
    largest_stable_world_step(&make, 1.0, 50.0)
}

/// Symplectic Euler's run at its largest stable step ([`symplectic_step`],
/// shortened by 10 % at a time, at most ten times, until the whole 10 s
/// stays finite).
pub fn stable_symplectic(n: usize, drag: f64) -> Leg {
    let mut h = symplectic_step(n, drag);
    let mut run = leg(n, drag, IntegratorKind::Symplectic, h);
    for _ in 0..10 {
        if run.finite {
            break;
        }
        h *= 0.9;
        run = leg(n, drag, IntegratorKind::Symplectic, h);
    }
    run
}

/// The steps implicit Euler tries, largest first.
pub const IMPLICIT_STEPS: [f64; 10] = [1.0, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001];

/// Runs the race on the cloth-`n` curtain with linear drag `drag`.
/// Symplectic Euler's largest stable step is searched over the first second
/// ([`symplectic_step`]); should the whole 10 s still blow up at it, the
/// step is shortened by 10 % until it does not. Implicit Euler tries
/// [`IMPLICIT_STEPS`] until a run takes longer than symplectic Euler's (a
/// smaller step would too).
pub fn race(n: usize, drag: f64) -> Race {
    let symplectic = stable_symplectic(n, drag);
    let symplectic_step = symplectic.h;
    let reference = leg(n, drag, IntegratorKind::Symplectic, symplectic_step / 4.0);
    let mut implicit = Vec::new();
    for h in IMPLICIT_STEPS {
        let l = leg(n, drag, IntegratorKind::Implicit, h);
        let slower = l.seconds > symplectic.seconds;
        implicit.push(l);
        if slower {
            break;
        }
    }
    Race {
        n,
        drag,
        symplectic_step,
        reference,
        symplectic,
        implicit,
    }
}
