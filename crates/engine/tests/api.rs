//! The world's public API refuses what would break it later (bad handles,
//! bad values), and its time always agrees with its state.

use animats_engine::{
    DiscreteEvent, EventContext, EventState, Force, ForceContext, ParticleDef, ParticleId,
    Properties, SimError, World,
};
use glam::DVec3;

#[test]
fn setters_refuse_foreign_handles_and_bad_values_and_change_nothing() {
    let mut w = World::new();
    let p = w
        .add_particle(ParticleDef::new(1.0).with_radius(0.1))
        .unwrap();
    let ghost = ParticleId::from_index(7);
    assert!(w.set_position(ghost, DVec3::ONE).is_err());
    assert!(w.set_velocity(ghost, DVec3::ONE).is_err());
    assert!(w.set_mass(ghost, 1.0).is_err());
    assert!(w.set_volume(ghost, 1.0).is_err());
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = w.set_mass(p, bad).unwrap_err();
        assert_eq!(e.field, "mass", "{e}");
    }
    assert!(w.set_volume(p, -1e-6).is_err());
    assert!(w.set_position(p, DVec3::new(0.0, f64::NAN, 0.0)).is_err());
    assert!(w
        .set_velocity(p, DVec3::new(f64::INFINITY, 0.0, 0.0))
        .is_err());
    assert_eq!(w.particles().mass[0], 1.0);
    assert_eq!(w.position(p), DVec3::ZERO);
    // Forces naming particles of another world are refused when added.
    assert!(w.add_constant_force(vec![p, ghost], DVec3::X).is_err());
    assert!(w
        .add_spring(animats_engine::SpringDef::new(p, ghost, 1.0, 0.0))
        .is_err());
    assert!(w
        .set_fluid_current(3, animats_engine::Current::Still)
        .is_err());
    w.step(0.01).unwrap();
}

/// A force that goes to NaN from time `at` on.
#[derive(Clone)]
struct BreaksAt(f64);
impl Force for BreaksAt {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        if ctx.t >= self.0 {
            forces[0].x = f64::NAN;
        }
    }
}

/// An event that is always "missed" in anything longer than `finest`, so
/// every step is taken in the smallest pieces the world allows.
#[derive(Clone)]
struct AlwaysMissed {
    finest: f64,
}
impl DiscreteEvent for AlwaysMissed {
    fn check(&mut self, ctx: &EventContext) -> EventState {
        if ctx.h > self.finest {
            EventState::Missed
        } else {
            EventState::Occurring
        }
    }
    fn handle(&mut self, _t: f64, _p: &mut [DVec3], _v: &mut [DVec3], _q: &Properties) {}
}

#[test]
fn after_a_blow_up_inside_a_backtracked_step_time_and_state_agree() {
    let dt = 0.01;
    let mut w = World::new();
    let p = w
        .add_particle(ParticleDef::new(1.0).with_velocity(DVec3::X))
        .unwrap();
    // Pieces of dt/8; the force breaks inside the sixth piece of the second
    // step (RK4 evaluates it at the piece's middle), so five are accepted.
    w.add_event(Box::new(AlwaysMissed {
        finest: dt / 8.0 * 1.01,
    }));
    w.add_force(Box::new(BreaksAt(dt * (1.0 + 5.25 / 8.0))));
    w.step(dt).unwrap();
    match w.step(dt) {
        Err(SimError::NonFinite { time, .. }) => {
            assert!((time - dt * (1.0 + 6.0 / 8.0)).abs() < 1e-15, "{time}")
        }
        other => panic!("expected a blow-up, got {other:?}"),
    }
    // The pieces up to 5/8 of the step were accepted: the particle (moving
    // at 1 m/s) is there, and the clock says so too.
    let x = w.position(p).x;
    assert!((x - dt * (1.0 + 5.0 / 8.0)).abs() < 1e-15, "x = {x}");
    assert!(
        (w.time() - x).abs() < 1e-15,
        "time {} but the state is at {x}",
        w.time()
    );
}
