//! Small worlds (under 16 particles) step particle by particle, larger ones
//! by flat loops over coordinates (docs/DESIGN.md, "A
//! step"): both must give the same bits. A chain of 12
//! springs under gravity and drag is stepped alone, and again beside 40
//! free particles that touch nothing (which put it on the other path); its
//! trajectory must be identical, for every explicit integrator, and a blow-up must
//! be caught and named on both paths.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_engine::{DVec3, IntegratorKind, ParticleDef, SimError, SpringDef, World};

fn chain(extra: usize, stiffness: f64) -> World {
    let mut w = World::new();
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let mut last = w
        .add_particle(ParticleDef::new(1.0).at(DVec3::new(0.0, 2.0, 0.0)).fixed())
        .unwrap();
    for k in 1..13 {
        let x = DVec3::new(0.1 * k as f64, 2.0 + 0.01 * (k % 3) as f64, 0.02 * k as f64);
        let p = w
            .add_particle(ParticleDef::new(0.1 + 0.01 * k as f64).at(x))
            .unwrap();
        w.add_spring(SpringDef::new(last, p, stiffness, 0.3))
            .unwrap();
        last = p;
    }
    for k in 0..extra {
        let x = DVec3::new(-5.0 - k as f64, 10.0, 3.0);
        w.add_particle(ParticleDef::new(1.0).at(x).with_velocity(DVec3::X))
            .unwrap();
    }
    w
}

#[test]
fn a_small_world_steps_the_same_bits_as_inside_a_large_one() {
    // The explicit integrators: the implicit one's conjugate gradients sum
    // over every particle, so the free ones change its iterations.
    for kind in IntegratorKind::ALL.into_iter().filter(|k| k.is_explicit()) {
        let (mut small, mut large) = (chain(0, 200.0), chain(40, 200.0));
        small.set_integrator(kind);
        large.set_integrator(kind);
        for step in 0..2000 {
            small.step(1e-3).unwrap();
            large.step(1e-3).unwrap();
            let n = small.len();
            assert_eq!(
                small.state().pos[..n],
                large.state().pos[..n],
                "{kind}, step {step}"
            );
            assert_eq!(small.state().vel[..n], large.state().vel[..n], "{kind}");
        }
    }
}

#[test]
fn a_blow_up_is_named_on_both_paths() {
    // Far too stiff for the step: the chain's explicit steps blow up.
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        let mut names = Vec::new();
        for extra in [0, 40] {
            let mut w = chain(extra, 1e12);
            w.set_integrator(kind);
            let error = (0..10_000).find_map(|_| w.step(1e-2).err());
            match error {
                Some(SimError::NonFinite { particle, .. }) => {
                    assert!(particle.index() < 13, "{kind}: blamed {particle:?}");
                    // The world stays at its last finite state.
                    assert!(w.state().pos.iter().all(|x| x.is_finite()));
                    names.push(particle);
                }
                other => panic!("{kind} with {extra} more: {other:?}"),
            }
        }
        assert_eq!(names[0], names[1], "{kind}");
    }
}

/// An event that never happens: a world that has one takes the general
/// step (trial, check, accept), one without it the step of a small world
/// alone.
#[derive(Clone)]
struct Never;

impl animats_engine::DiscreteEvent for Never {
    fn check(&mut self, _: &animats_engine::EventContext) -> animats_engine::EventState {
        animats_engine::EventState::None
    }
    fn handle(&mut self, _: f64, _: &mut [DVec3], _: &mut [DVec3], _: &animats_engine::Properties) {
    }
}

/// A push that changes with the time and the velocity, so that a step
/// evaluating it at the wrong time or state gives other bits.
#[derive(Clone)]
struct Push;

impl animats_engine::Force for Push {
    fn apply(&mut self, ctx: &animats_engine::ForceContext, forces: &mut [DVec3]) {
        forces[5] += DVec3::new((40.0 * ctx.t).sin(), 0.0, 0.0) - 0.3 * ctx.vel[5];
    }
    fn name(&self) -> &str {
        "push"
    }
}

#[test]
fn a_small_world_without_events_steps_as_one_with_an_event_that_never_happens() {
    // Every integrator, the implicit one included (alone and beside the
    // event, its solves see the same particles).
    for kind in IntegratorKind::ALL {
        let (mut alone, mut general) = (chain(0, 200.0), chain(0, 200.0));
        general.add_event(Box::new(Never));
        for w in [&mut alone, &mut general] {
            w.set_integrator(kind);
            w.add_force(Box::new(Push));
        }
        for step in 0..2000 {
            let (a, g) = (alone.step(1e-3).unwrap(), general.step(1e-3).unwrap());
            assert_eq!(a, g, "{kind}, step {step}");
            assert_eq!(
                alone.state().pos,
                general.state().pos,
                "{kind}, step {step}"
            );
            assert_eq!(
                alone.state().vel,
                general.state().vel,
                "{kind}, step {step}"
            );
        }
        assert_eq!(alone.time().to_bits(), general.time().to_bits(), "{kind}");
        assert_eq!(alone.stats(), general.stats(), "{kind}");
    }
    // A blow-up: the same particle named at the same time, and both worlds
    // left at the same last finite state.
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        let (mut alone, mut general) = (chain(0, 1e12), chain(0, 1e12));
        general.add_event(Box::new(Never));
        for w in [&mut alone, &mut general] {
            w.set_integrator(kind);
        }
        let a = (0..10_000).find_map(|_| alone.step(1e-2).err());
        let g = (0..10_000).find_map(|_| general.step(1e-2).err());
        assert!(
            matches!(a, Some(SimError::NonFinite { .. })),
            "{kind}: {a:?}"
        );
        assert_eq!(format!("{a:?}"), format!("{g:?}"), "{kind}");
        assert_eq!(alone.state().pos, general.state().pos, "{kind}");
        assert_eq!(alone.time().to_bits(), general.time().to_bits(), "{kind}");
    }
}
