//! # animats-bench
//!
//! The standard benchmark workloads (`docs/WORKLOADS.md`), run through
//! the engine's public API — the code users get — side by side with plain
//! hand-written loops for the same work, so every row carries its ratio.
//!
//! Timing protocol: one warm-up run of each, then `runs` timed runs of each,
//! engine and baseline alternating (so a noisy neighbour hurts both alike);
//! each run starts from a freshly built initial state and only the step loop
//! is timed. Correctness checks are computed after the timed region.

#![warn(missing_docs)]

pub mod allpairs;
pub mod bodies;
pub mod brains;
pub mod diversity;
pub mod hopper;
pub mod mass_spring;
pub mod nbody5;
pub mod pile;
pub mod scene_load;
pub mod seaworld;
pub mod stability;
pub mod stiff;

use animats_engine::{DVec3, IntegratorKind};
use std::time::Instant;

/// The workloads, in the order they are run by default.
pub const WORKLOADS: [&str; 10] = [
    "chain-64",
    "cloth-32",
    "cloth-128",
    "nbody5",
    "allpairs-1000",
    "hopper",
    "brains",
    "seaworld",
    "stability",
    "scene-load",
];

/// Workloads run only when named (they take minutes).
pub const ON_REQUEST: [&str; 4] = ["implicit", "contacts", "bodies", "diversity"];

/// A rayon pool of `threads` threads, for workloads that time one against
/// two.
pub(crate) fn pool(threads: usize) -> Result<rayon::ThreadPool, String> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())
}

/// True when `name` is a workload, run by default or on request.
pub fn is_workload(name: &str) -> bool {
    WORKLOADS.contains(&name) || ON_REQUEST.contains(&name)
}

/// Options of a benchmark run.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Shorter runs where the workload defines a quick mode (nbody5, allpairs-1000).
    pub quick: bool,
    /// Timed runs after the warm-up (at least 5).
    pub runs: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            quick: false,
            runs: 5,
        }
    }
}

/// Median, minimum and maximum of a set of timed runs, s.
#[derive(Clone, Debug, PartialEq)]
pub struct Timing {
    /// Median, s.
    pub median: f64,
    /// Fastest run, s.
    pub min: f64,
    /// Slowest run, s.
    pub max: f64,
    /// Number of runs.
    pub runs: usize,
    /// Every timed run, s, in the order they ran.
    pub times: Vec<f64>,
}

impl Timing {
    /// The timing of one of `n` equal pieces of each run (a run that did
    /// `n` evaluations → per evaluation).
    pub fn divided(&self, n: f64) -> Timing {
        Timing {
            median: self.median / n,
            min: self.min / n,
            max: self.max / n,
            runs: self.runs,
            times: self.times.iter().map(|t| t / n).collect(),
        }
    }

    /// Summarises run times (s).
    pub fn from_runs(runs: Vec<f64>) -> Timing {
        let mut times = runs.clone();
        times.sort_by(f64::total_cmp);
        let n = times.len();
        let median = if n % 2 == 1 {
            times[n / 2]
        } else {
            0.5 * (times[n / 2 - 1] + times[n / 2])
        };
        Timing {
            median,
            min: times[0],
            max: times[n - 1],
            runs: n,
            times: runs,
        }
    }
}

/// What a check compares its value with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// Within `tolerance` of `expected`.
    Near {
        /// The reference value.
        expected: f64,
        /// Largest acceptable |value - expected|.
        tolerance: f64,
    },
    /// At least this.
    AtLeast(f64),
    /// At most this.
    AtMost(f64),
    /// A speed goal of at least this: reported as met or missed, never a
    /// failure (timings on a shared machine are noisy; correctness is not).
    Target(f64),
    /// A speed goal of at most this (a wall time), reported like [`Bound::Target`].
    TargetAtMost(f64),
    /// Reported only.
    Info,
}

/// One correctness (or target) check of a workload's result.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// What is checked, e.g. `com_y`.
    pub name: String,
    /// The value we got.
    pub value: f64,
    /// What it must satisfy.
    pub bound: Bound,
}

impl Check {
    /// A check against a reference value.
    pub fn new(name: &str, value: f64, expected: f64, tolerance: f64) -> Check {
        Check {
            name: name.into(),
            value,
            bound: Bound::Near {
                expected,
                tolerance,
            },
        }
    }
    /// A value that must be at least `min`.
    pub fn at_least(name: &str, value: f64, min: f64) -> Check {
        Check {
            name: name.into(),
            value,
            bound: Bound::AtLeast(min),
        }
    }
    /// A value that must be at most `max`.
    pub fn at_most(name: &str, value: f64, max: f64) -> Check {
        Check {
            name: name.into(),
            value,
            bound: Bound::AtMost(max),
        }
    }
    /// A speed goal: at least `min`, reported, never failed.
    pub fn target(name: &str, value: f64, min: f64) -> Check {
        Check {
            name: name.into(),
            value,
            bound: Bound::Target(min),
        }
    }
    /// A speed goal of at most `max` (a wall time): reported, never a failure.
    pub fn target_at_most(name: &str, value: f64, max: f64) -> Check {
        Check {
            name: name.into(),
            value,
            bound: Bound::TargetAtMost(max),
        }
    }
    /// Whether a speed goal was met (`None` for a correctness check).
    pub fn target_met(&self) -> Option<bool> {
        match self.bound {
            Bound::Target(min) => Some(self.value >= min),
            Bound::TargetAtMost(max) => Some(self.value <= max),
            _ => None,
        }
    }
    /// A value reported without a reference.
    pub fn info(name: &str, value: f64) -> Check {
        Check {
            name: name.into(),
            value,
            bound: Bound::Info,
        }
    }
    /// Whether a correctness check passed (`None` for a speed goal or a
    /// value reported only).
    pub fn passed(&self) -> Option<bool> {
        let v = self.value;
        match self.bound {
            Bound::Near {
                expected,
                tolerance,
            } => Some((v - expected).abs() <= tolerance && v.is_finite()),
            Bound::AtLeast(min) => Some(v >= min),
            Bound::AtMost(max) => Some(v <= max),
            Bound::Target(_) | Bound::TargetAtMost(_) | Bound::Info => None,
        }
    }
}

/// One line of the benchmark table.
#[derive(Clone, Debug)]
pub struct Row {
    /// Workload name.
    pub workload: String,
    /// Integrator (and thread note).
    pub variant: String,
    /// Particles (bodies).
    pub particles: usize,
    /// Springs (0 for the n-body workloads).
    pub springs: usize,
    /// Steps per run.
    pub steps: usize,
    /// Step, s.
    pub dt: f64,
    /// Force evaluations per step.
    pub evaluations: u32,
    /// Pair interactions per step (n-body workloads).
    pub pairs: usize,
    /// Engine timings.
    pub engine: Timing,
    /// Name and timings of the hand-written baseline.
    pub baseline: Option<(String, Timing)>,
    /// Checks of the final state.
    pub checks: Vec<Check>,
}

impl Row {
    /// A row timed per item (an evaluation, a body), with no particle
    /// counts and no baseline.
    pub fn per_item(workload: &str, variant: String, per: Timing, checks: Vec<Check>) -> Row {
        Row {
            workload: workload.into(),
            variant,
            particles: 0,
            springs: 0,
            steps: 0,
            dt: 0.0,
            evaluations: 1,
            pairs: 0,
            engine: per,
            baseline: None,
            checks,
        }
    }

    /// How many threads the measurement used, and how: `"one sim"` (one
    /// world, on one thread or split among several) or `"independent sims"`
    /// (a world or evaluation per thread). Read from the variant, which
    /// names its threads ("one world, 2 threads", "2 threads x 1 copy
    /// each", "… 2 thr"); no mention means one thread.
    pub fn threads(&self) -> (usize, &'static str) {
        let v = &self.variant;
        let n = if v.contains("2 thr") { 2 } else { 1 };
        let mode = if n > 1 && !v.contains("one world") {
            "independent sims"
        } else {
            "one sim"
        };
        (n, mode)
    }

    /// Particle-steps per second (median).
    pub fn particle_steps_per_s(&self) -> f64 {
        (self.particles * self.steps) as f64 / self.engine.median
    }
    /// Spring evaluations per second (median).
    pub fn spring_evals_per_s(&self) -> f64 {
        (self.springs * self.steps) as f64 * self.evaluations as f64 / self.engine.median
    }
    /// Pair interactions per second (median).
    pub fn pairs_per_s(&self) -> f64 {
        (self.pairs * self.steps) as f64 / self.engine.median
    }
    /// Simulated seconds per wall-clock second (median).
    pub fn sim_per_wall(&self) -> f64 {
        self.steps as f64 * self.dt / self.engine.median
    }
    /// Engine median over baseline median.
    pub fn ratio(&self) -> Option<f64> {
        self.baseline
            .as_ref()
            .map(|(_, b)| self.engine.median / b.median)
    }
}

/// What a timed run returns: nothing, and the harness times the call; or
/// [`Inside`], the run's own time.
pub trait RunTime {
    /// The run's own time, s, if it measured one.
    fn inside(self) -> Option<f64>;
}

impl RunTime for () {
    fn inside(self) -> Option<f64> {
        None
    }
}

/// A run's own time, s, measured where it ran: on a thread pool's thread,
/// without the wait for that thread to wake (tens of µs on this machine,
/// a tenth of chain-64's 1,000 steps), which a simulation stepping on its
/// own thread never pays.
pub struct Inside(pub f64);

impl RunTime for Inside {
    fn inside(self) -> Option<f64> {
        Some(self.0)
    }
}

/// Runs `f` on `pool` and times it there (see [`Inside`]).
pub fn in_pool(pool: &rayon::ThreadPool, f: impl FnOnce() + Send) -> Inside {
    pool.install(|| {
        let t = Instant::now();
        f();
        Inside(t.elapsed().as_secs_f64())
    })
}

/// Times `runs` runs of `a` and of `b`, alternating, after one warm-up of
/// each. `setup` builds a fresh state (untimed); `run` is the timed loop
/// (timed around the call, unless it returns its own time, [`Inside`]).
/// Returns the timings and the last states.
pub fn measure_pair<SA, SB, RA: RunTime, RB: RunTime>(
    runs: usize,
    mut setup_a: impl FnMut() -> SA,
    mut run_a: impl FnMut(&mut SA) -> RA,
    mut setup_b: impl FnMut() -> SB,
    mut run_b: impl FnMut(&mut SB) -> RB,
) -> (Timing, Timing, SA, SB) {
    let mut once_a = || {
        let mut s = setup_a();
        let t = Instant::now();
        let own = run_a(&mut s).inside();
        (own.unwrap_or(t.elapsed().as_secs_f64()), s)
    };
    let mut once_b = || {
        let mut s = setup_b();
        let t = Instant::now();
        let own = run_b(&mut s).inside();
        (own.unwrap_or(t.elapsed().as_secs_f64()), s)
    };
    let (_, mut last_a) = once_a();
    let (_, mut last_b) = once_b();
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let (t, s) = once_a();
        ta.push(t);
        last_a = s;
        let (t, s) = once_b();
        tb.push(t);
        last_b = s;
    }
    (Timing::from_runs(ta), Timing::from_runs(tb), last_a, last_b)
}

/// Times `runs` runs of `run` after one warm-up; returns the timing and the
/// last state.
pub fn measure<S>(
    runs: usize,
    mut setup: impl FnMut() -> S,
    mut run: impl FnMut(&mut S),
) -> (Timing, S) {
    let mut once = || {
        let mut s = setup();
        let t = Instant::now();
        run(&mut s);
        (t.elapsed().as_secs_f64(), s)
    };
    let (_, mut last) = once();
    let mut times = Vec::new();
    for _ in 0..runs {
        let (t, s) = once();
        times.push(t);
        last = s;
    }
    (Timing::from_runs(times), last)
}

/// Runs one named workload; each mass-spring workload gives a row per integrator.
pub fn run(name: &str, opts: Options) -> Result<Vec<Row>, String> {
    let runs = opts.runs.max(5);
    match name {
        "chain-64" | "cloth-32" | "cloth-128" => Ok(run_mass_spring(name, runs)),
        "nbody5" => Ok(vec![
            run_nbody5(opts.quick, runs, false),
            run_nbody5(opts.quick, runs, true),
        ]),
        "allpairs-1000" => Ok(run_allpairs(opts.quick, runs)),
        "hopper" => hopper::run(opts.quick, runs),
        "brains" => brains::run(opts.quick, runs),
        "bodies" => bodies::run(opts.quick, runs),
        "diversity" => diversity::run(opts.quick, runs),
        "seaworld" => seaworld::run(opts.quick, runs),
        "implicit" => Ok(run_implicit(opts.quick)),
        "contacts" => Ok(pile::run(opts.quick, runs)),
        "scene-load" => Ok(scene_load::run(opts.quick, runs)),
        "stability" => Ok(stability::run(Some(std::path::Path::new(
            "scenes/seaworld.toml",
        )))),
        _ => Err(format!(
            "unknown workload `{name}` (expected one of: {}; or on request: {})",
            WORKLOADS.join(", "),
            ON_REQUEST.join(", ")
        )),
    }
}

/// `implicit`: 10 s of the stiff, damped cloth-128 curtain ([`stiff::race`];
/// cloth-32 with `--quick`), symplectic Euler at its largest stable step
/// against implicit Euler at each step tried; the goal is implicit at its
/// fastest run within 1 cm of the reference's final centre of mass at least
/// 3× faster.
fn run_implicit(quick: bool) -> Vec<Row> {
    let n = if quick { 32 } else { 128 };
    let mut rows = Vec::new();
    for (drag, name) in [
        (stiff::CURTAIN_DRAG, "with drag"),
        (0.0, "no drag, swinging on"),
    ] {
        rows.extend(race_rows(&stiff::race(n, drag), name));
    }
    rows
}

fn race_rows(race: &stiff::Race, name: &str) -> Vec<Row> {
    let n = race.n;
    let springs = mass_spring::cloth(n).edges.len();
    let row = |leg: &stiff::Leg, what: String, checks: Vec<Check>| Row {
        workload: "implicit".into(),
        variant: format!("curtain cloth-{n} {name}, {what}"),
        particles: n * n,
        springs,
        steps: (stiff::RACE_SECONDS / leg.h).round() as usize,
        dt: leg.h,
        evaluations: 1,
        pairs: 0,
        engine: Timing::from_runs(vec![leg.seconds]),
        baseline: None,
        checks,
    };
    let error = |leg: &stiff::Leg| race.error(leg);
    let mut rows = vec![
        row(
            &race.reference,
            "reference: symplectic at 1/4 step".into(),
            vec![Check::info(
                "final centre of mass y, m",
                race.reference.com.y,
            )],
        ),
        row(
            &race.symplectic,
            "symplectic at its largest stable step".into(),
            vec![
                Check::info("largest stable step, s", race.symplectic_step),
                Check::at_least("finite (1 = yes)", race.symplectic.finite as u8 as f64, 1.0),
                Check::info(
                    "centre of mass from the reference, m",
                    error(&race.symplectic),
                ),
            ],
        ),
    ];
    for leg in &race.implicit {
        rows.push(row(
            leg,
            format!("implicit at {} s", leg.h),
            vec![
                Check::info("centre of mass from the reference, m", error(leg)),
                Check::info("conjugate-gradient iterations a step", leg.iterations),
                Check::at_least("finite (1 = yes)", leg.finite as u8 as f64, 1.0),
            ],
        ));
    }
    match race.best() {
        Some(best) => rows.push(row(
            best,
            "implicit's fastest run within 1 cm".into(),
            vec![
                Check::info("step, s", best.h),
                Check::target(
                    "speed-up over symplectic",
                    race.symplectic.seconds / best.seconds,
                    3.0,
                ),
            ],
        )),
        None => rows.push(row(
            &race.symplectic,
            "implicit: no step tried came within 1 cm faster".into(),
            vec![Check::target("speed-up over symplectic", 0.0, 3.0)],
        )),
    }
    rows
}

fn run_mass_spring(name: &str, runs: usize) -> Vec<Row> {
    use mass_spring::*;
    let spec = match name {
        "chain-64" => chain64(),
        "cloth-32" => cloth(32),
        _ => cloth(128),
    };
    let mut rows = Vec::new();
    let (p1, p2) = (threads(1), threads(2));
    let steps = |w: &mut animats_engine::World| {
        for _ in 0..STEPS {
            w.step(DT).expect("workload stays finite");
        }
    };
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        let base_steps = |b: &mut Baseline| {
            for _ in 0..STEPS {
                match kind {
                    IntegratorKind::Rk4 => b.step_rk4(),
                    _ => b.step_symplectic(),
                }
            }
        };
        let (engine, baseline, world, base) = measure_pair(
            runs,
            || engine_world(&spec, kind),
            |w| in_pool(&p1, || steps(w)),
            || Baseline::new(&spec),
            base_steps,
        );
        let s = summarise(&world.state().pos, &world.state().vel, &spec.pinned);
        let (bx, bv) = base.state();
        let sb = summarise(bx, bv, &spec.pinned);
        let mut checks = Vec::new();
        if let Some((cx, cy, ke)) = reference(name, kind) {
            checks.push(Check::new("com_x", s.com.x, cx, 1e-6));
            checks.push(Check::new("com_y", s.com.y, cy, 1e-6));
            checks.push(Check::new(
                "kinetic",
                s.kinetic,
                ke,
                1e-6 * ke.abs().max(1e-6),
            ));
        }
        checks.push(Check::new("com_y vs baseline", s.com.y, sb.com.y, 1e-6));
        checks.push(Check::new("min_y >= 0", s.min_y.min(0.0), 0.0, 0.0));
        checks.push(Check::new(
            "finite",
            if s.finite { 1.0 } else { 0.0 },
            1.0,
            0.0,
        ));
        let row = |variant: String, engine, baseline, checks| Row {
            workload: name.into(),
            variant,
            particles: spec.positions.len(),
            springs: spec.edges.len(),
            steps: STEPS,
            dt: DT,
            evaluations: kind.evaluations(),
            pairs: 0,
            engine,
            baseline,
            checks,
        };
        let one_thread = engine.median;
        rows.push(row(
            kind.name().into(),
            engine,
            Some(("hand-written SoA loop".into(), baseline)),
            checks,
        ));
        // One world on two threads, where the world is large enough to split
        // (docs/DESIGN.md, "Threads"); the same bits.
        if name == "cloth-128" {
            let (both, both_base, world2, _) = measure_pair(
                runs,
                || engine_world(&spec, kind),
                |w| in_pool(&p2, || steps(w)),
                || Baseline::new(&spec),
                base_steps,
            );
            let same = world2.state() == world.state();
            let speedup = one_thread / both.median;
            rows.push(row(
                format!("{kind}, one world, 2 threads"),
                both,
                Some(("hand-written SoA loop, 1 thread".into(), both_base)),
                vec![
                    Check::new("same bits as 1 thread", f64::from(u8::from(same)), 1.0, 0.0),
                    Check::target("speed-up over 1 thread", speedup, 1.8),
                ],
            ));
        }
    }
    rows
}

/// nbody5 through the engine: the tutorial's user force, or the built-in
/// n-body force (`builtin`).
fn run_nbody5(quick: bool, runs: usize, builtin: bool) -> Row {
    use nbody5::*;
    let steps = if quick { 5_000_000 } else { 50_000_000 };
    let make = if builtin { builtin_world } else { engine_world };
    let (engine, baseline, world, reference) = measure_pair(
        runs,
        make,
        |w| {
            for _ in 0..steps {
                w.step(DT).expect("n-body stays finite");
            }
        },
        Reference::new,
        |r| {
            for _ in 0..steps {
                r.advance(DT);
            }
        },
    );
    let mut short = make();
    let e0 = world_energy(&short);
    for _ in 0..1000 {
        short.step(DT).expect("n-body stays finite");
    }
    // The baseline is checked too: the reference algorithm's own E(1000).
    let mut short_reference = Reference::new();
    for _ in 0..1000 {
        short_reference.advance(DT);
    }
    let mut checks = vec![
        Check::new("E(0)", e0, E0, 5e-10),
        Check::new("E(1000)", world_energy(&short), E1000, 5e-10),
        Check::new(
            "reference algorithm E(1000)",
            short_reference.energy(),
            E1000,
            5e-10,
        ),
    ];
    let e_end = world_energy(&world);
    if steps == 50_000_000 {
        checks.push(Check::new("E(50M)", e_end, E50M, 5e-10));
    }
    let end = if quick { "E(5M)" } else { "E(50M)" };
    checks.push(Check::new(
        &format!("{end} vs reference algorithm"),
        e_end,
        reference.energy(),
        5e-10,
    ));
    Row {
        workload: "nbody5".into(),
        variant: if builtin {
            "symplectic, built-in force".into()
        } else {
            "symplectic, user force".into()
        },
        particles: 5,
        springs: 0,
        steps,
        dt: DT,
        evaluations: 1,
        pairs: 10,
        engine,
        baseline: Some(("reference scalar advance".into(), baseline)),
        checks,
    }
}

fn allpairs_checks(x: &[DVec3], v: &[DVec3], steps: usize) -> Vec<Check> {
    use allpairs::*;
    let (e0_ref, e100_ref, drift_ref, com_ref, rms_ref) = REFERENCE;
    let e0 = energy(&positions(), &vec![DVec3::ZERO; N]);
    let e = energy(x, v);
    let (com, rms) = shape(x);
    let mut checks = vec![Check::new("E(0)", e0, e0_ref, 1e-12)];
    if steps == STEPS {
        checks.push(Check::new("E(100)", e, e100_ref, 1e-12));
        checks.push(Check::new("drift", (e - e0) / e0.abs(), drift_ref, 5e-8));
        checks.push(Check::new("com_x", com, com_ref, 5e-7));
        checks.push(Check::new("rms radius", rms, rms_ref, 1e-10));
    } else {
        checks.push(Check::info("drift", (e - e0) / e0.abs()));
    }
    checks
}

/// A rayon pool of `n` threads: what "1 thread" and "2 threads" mean for a
/// world whose forces use threads (the n-body pairs do). Its threads keep
/// to their own processors (`animats_engine::pin`; the steps run inside
/// the pool, where that pays).
fn threads(n: usize) -> rayon::ThreadPool {
    animats_engine::pin::pinned_pool(n).expect("a thread pool")
}

/// Two threads, two independent all-pairs worlds, one per thread (the
/// throughput an evolution loop sees), against two hand-written loops.
fn allpairs_two_copies(runs: usize, steps: usize) -> (Timing, Timing) {
    use allpairs::*;
    let (pa, pb) = (threads(1), threads(1));
    let on = |p: &rayon::ThreadPool, w: &mut animats_engine::World| {
        in_pool(p, || {
            for _ in 0..steps {
                w.step(DT).expect("all-pairs stays finite");
            }
        })
    };
    let (two, two_base, _, _) = measure_pair(
        runs,
        || (engine_world(), engine_world()),
        |(a, b)| {
            std::thread::scope(|s| {
                s.spawn(|| on(&pa, a));
                s.spawn(|| on(&pb, b));
            })
        },
        || (Baseline::new(), Baseline::new()),
        |(a, b)| {
            std::thread::scope(|s| {
                s.spawn(|| (0..steps).for_each(|_| a.step()));
                s.spawn(|| (0..steps).for_each(|_| b.step()));
            })
        },
    );
    (two, two_base)
}

fn run_allpairs(quick: bool, runs: usize) -> Vec<Row> {
    use allpairs::*;
    let steps = if quick { 20 } else { STEPS };
    let (p1, p2) = (threads(1), threads(2));
    let one = |w: &mut animats_engine::World| {
        for _ in 0..steps {
            w.step(DT).expect("all-pairs stays finite");
        }
    };
    let on = |p: &rayon::ThreadPool, w: &mut animats_engine::World| in_pool(p, || one(w));
    let all_pairs = |b: &mut Baseline| (0..steps).for_each(|_| b.step());
    let (engine, baseline, world, base) =
        measure_pair(runs, engine_world, |w| on(&p1, w), Baseline::new, all_pairs);
    let mut checks = allpairs_checks(&world.state().pos, &world.state().vel, steps);
    checks.push(Check::new(
        "E vs baseline",
        energy(&world.state().pos, &world.state().vel),
        energy(&base.x, &base.v),
        1e-12,
    ));
    let row = |variant: &str, engine: Timing, baseline, pairs, checks| Row {
        workload: "allpairs-1000".into(),
        variant: variant.into(),
        particles: N,
        springs: 0,
        steps,
        dt: DT,
        evaluations: 1,
        pairs,
        engine,
        baseline,
        checks,
    };
    let one_thread = engine.median;
    let single = row(
        "symplectic, 1 thread",
        engine,
        Some(("hand-written loop (all i, j)".into(), baseline)),
        N * N,
        checks,
    );
    // The hand-written loop that sums each pair once (half the pairs).
    let (engine_pairs, pairs_base, _, _) = measure_pair(
        runs,
        engine_world,
        |w| on(&p1, w),
        Baseline::new,
        |b| {
            for _ in 0..steps {
                b.step_pairs();
            }
        },
    );
    let pairwise = row(
        "symplectic, 1 thread (i<j baseline)",
        engine_pairs,
        Some(("hand-written loop (pairs i<j)".into(), pairs_base)),
        N * N,
        vec![],
    );
    // One world, its bodies split between two threads; the same bits.
    let (both, both_base, world2, _) =
        measure_pair(runs, engine_world, |w| on(&p2, w), Baseline::new, all_pairs);
    let same = world2.state().pos == world.state().pos && world2.state().vel == world.state().vel;
    let speedup = one_thread / both.median;
    let shared = row(
        "symplectic, one world, 2 threads",
        both,
        Some(("hand-written loop (all i, j), 1 thread".into(), both_base)),
        N * N,
        vec![
            Check::new("same bits as 1 thread", f64::from(u8::from(same)), 1.0, 0.0),
            Check::target("speed-up over 1 thread", speedup, 1.8),
        ],
    );
    let (two, two_base) = allpairs_two_copies(runs, steps);
    let double = row(
        "symplectic, 2 threads x 1 copy each",
        two,
        Some(("hand-written loop, 2 threads".into(), two_base)),
        2 * N * N,
        vec![],
    );
    vec![single, pairwise, shared, double]
}

#[cfg(test)]
mod target_tests {
    use super::{Check, Row, Timing};

    #[test]
    fn a_row_says_how_many_threads_it_used() {
        let row = |variant: &str| Row {
            workload: "w".into(),
            variant: variant.into(),
            particles: 1,
            springs: 0,
            steps: 1,
            dt: 1.0,
            evaluations: 1,
            pairs: 0,
            engine: Timing::from_runs(vec![1.0]),
            baseline: None,
            checks: vec![],
        };
        assert_eq!(row("rk4").threads(), (1, "one sim"));
        assert_eq!(row("symplectic, 1 thread").threads(), (1, "one sim"));
        assert_eq!(row("rk4, one world, 2 threads").threads(), (2, "one sim"));
        let copies = row("symplectic, 2 threads x 1 copy each").threads();
        assert_eq!(copies, (2, "independent sims"));
        assert_eq!(
            row("evolve 6 lanes x 1000 gens, 2 thr").threads(),
            (2, "independent sims")
        );
    }

    #[test]
    fn a_missed_speed_goal_is_reported_but_is_not_a_failed_check() {
        let missed = Check::target("times real time", 9_699.0, 10_000.0);
        assert_eq!(missed.passed(), None, "not a correctness check");
        assert_eq!(missed.target_met(), Some(false));
        assert_eq!(Check::target("x", 2.0, 1.0).target_met(), Some(true));
        let slow = Check::target_at_most("wall time, s", 4.8, 3.0);
        assert_eq!((slow.passed(), slow.target_met()), (None, Some(false)));
        assert_eq!(
            Check::target_at_most("s", 2.0, 3.0).target_met(),
            Some(true)
        );
        let wrong = Check::new("com_y", 1.0, 2.0, 1e-6);
        assert_eq!(wrong.passed(), Some(false));
        assert_eq!(wrong.target_met(), None);
    }
}
