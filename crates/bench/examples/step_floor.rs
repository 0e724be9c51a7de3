//! What a step of a small world costs beyond its force: nbody5's five
//! bodies stepped by symplectic Euler with a user force that does nothing,
//!
//! - by the engine, as a world without events steps
//!   (`World::trial_alone`);
//! - by the engine with an event that never happens, which takes the
//!   general step (trial, events, accept);
//! - by hand: the forces zeroed, the force called through `dyn Force`, the
//!   update and its finiteness check, and nothing else.
//!
//! `cargo run --release -p animats-bench --example step_floor`; prints the
//! median of 5 runs of 2 M steps each, ns a step.

use animats_engine::{
    DVec3, DiscreteEvent, EventContext, EventState, Force, ForceContext, IntegratorKind,
    ParticleDef, Properties, World,
};
use std::hint::black_box;
use std::time::Instant;

const STEPS: usize = 2_000_000;
const DT: f64 = 0.01;

/// A user force that adds nothing (but is not known to the compiler to do
/// nothing).
#[derive(Clone)]
struct Nothing;

impl Force for Nothing {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        black_box((ctx.pos.as_ptr(), forces.as_mut_ptr()));
    }
    fn name(&self) -> &str {
        "nothing"
    }
}

/// An event that never happens.
#[derive(Clone)]
struct Never;

impl DiscreteEvent for Never {
    fn check(&mut self, _: &EventContext) -> EventState {
        EventState::None
    }
    fn handle(&mut self, _: f64, _: &mut [DVec3], _: &mut [DVec3], _: &Properties) {}
}

fn world(event: bool) -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    for (p, v, m) in animats_bench::nbody5::bodies() {
        w.add_particle(ParticleDef::new(m).at(p).with_velocity(v))
            .expect("a valid body");
    }
    w.add_force(Box::new(Nothing));
    if event {
        w.add_event(Box::new(Never));
    }
    w
}

/// ns a step of `run` (which takes `STEPS` steps), the median of 5.
fn median(mut run: impl FnMut()) -> f64 {
    run(); // warm-up
    let mut t: Vec<f64> = (0..5)
        .map(|_| {
            let start = Instant::now();
            run();
            start.elapsed().as_secs_f64() * 1e9 / STEPS as f64
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[2]
}

fn by_engine(event: bool) -> f64 {
    let mut w = world(event);
    median(|| {
        for _ in 0..STEPS {
            w.step(DT).expect("nothing blows up");
        }
    })
}

fn by_hand() -> f64 {
    let b = animats_bench::nbody5::bodies();
    let mut x: Vec<DVec3> = b.iter().map(|b| b.0).collect();
    let mut v: Vec<DVec3> = b.iter().map(|b| b.1).collect();
    let w: Vec<f64> = b.iter().map(|b| 1.0 / b.2).collect();
    let (mut x1, mut v1, mut f) = (x.clone(), v.clone(), vec![DVec3::ZERO; 5]);
    let mut force: Box<dyn Force> = Box::new(Nothing);
    let world = world(false);
    let particles = world.particles();
    median(|| {
        for step in 0..STEPS {
            f.fill(DVec3::ZERO);
            let ctx = ForceContext {
                t: step as f64 * DT,
                dt: DT,
                pos: &x,
                vel: &v,
                particles,
                gravity: DVec3::ZERO,
            };
            force.apply(&ctx, &mut f);
            let mut finite = true;
            for i in 0..5 {
                let vi = v[i] + f[i] * (DT * w[i]);
                let xi = x[i] + vi * DT;
                (v1[i], x1[i]) = (vi, xi);
                finite &= vi.is_finite() & xi.is_finite();
            }
            assert!(finite, "nothing blows up");
            std::mem::swap(&mut x, &mut x1);
            std::mem::swap(&mut v, &mut v1);
        }
    })
}

fn main() {
    println!("five bodies, symplectic Euler, a force that does nothing: ns a step, median of 5 runs of {STEPS} steps");
    println!(
        "engine, no events (step alone)      {:6.1}",
        by_engine(false)
    );
    println!(
        "engine, an event that never happens {:6.1}",
        by_engine(true)
    );
    println!("by hand (zero, call, update, check) {:6.1}", by_hand());
}
