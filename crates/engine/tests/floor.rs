//! The floor: collisions (a discrete event with backtracking) and contact
//! (normal reaction, static and kinetic friction).

use animats_engine::{
    DiscreteEvent, EventContext, EventState, FloorCollision, FloorDef, IntegratorKind, ParticleDef,
    ParticleId, Properties, World,
};
use glam::DVec3;

const G: f64 = 9.8;

fn ball_world(
    kind: IntegratorKind,
    restitution: f64,
    envelope: f64,
    y0: f64,
) -> (World, ParticleId) {
    let mut w = World::new();
    w.set_gravity(DVec3::new(0.0, -G, 0.0));
    w.set_integrator(kind);
    let p = w
        .add_particle(
            ParticleDef::new(0.1)
                .with_radius(0.05)
                .with_restitution(restitution)
                .at(DVec3::new(0.0, y0, 0.0)),
        )
        .unwrap();
    w.add_floor(FloorDef {
        envelope,
        rest_speed: 0.05,
        ..FloorDef::default()
    })
    .unwrap();
    (w, p)
}

/// Apex heights (of the sphere's lowest point) reached after each bounce,
/// computed from the state just after it: y + v²/2g is exact for free flight.
fn apexes(w: &mut World, p: ParticleId, dt: f64, seconds: f64) -> Vec<f64> {
    let r = w.particles().radius[p.index()];
    let mut out = Vec::new();
    for _ in 0..(seconds / dt).round() as usize {
        w.step(dt).unwrap();
        // No tunnelling: every accepted state has the sphere above the plane.
        assert!(
            w.position(p).y - r >= -1e-12,
            "sphere below the floor at t = {}",
            w.time()
        );
        let bounced = !w.event::<FloorCollision>().unwrap().collisions().is_empty();
        if bounced {
            let (y, v) = (w.position(p).y - r, w.velocity(p).y);
            out.push(y + v * v / (2.0 * G));
        }
    }
    out
}

#[test]
fn bouncing_ball_apexes_fall_by_restitution_squared() {
    // Dropped from 1 m it hits at 4.4 m/s and spends envelope/v ≈ 0.23 ms
    // within the 1 mm collision envelope; we step 10× that, so most impacts
    // are first missed and the step is retaken in shorter pieces.
    let (e, envelope) = (0.8, 1e-3);
    let contact_time = envelope / (2.0 * G * 1.0f64).sqrt();
    let dt = 10.0 * contact_time;
    for kind in [IntegratorKind::Rk4, IntegratorKind::Midpoint] {
        let (mut w, p) = ball_world(kind, e, envelope, 1.05);
        let apex = apexes(&mut w, p, dt, 3.0);
        println!(
            "{kind}: dt = {dt:.3e} s, apexes {apex:?}, backtracks {}",
            w.stats().backtracks
        );
        assert!(apex.len() >= 5, "{kind}: only {} bounces", apex.len());
        let mut previous = 1.0;
        for (i, &h) in apex.iter().take(5).enumerate() {
            let ratio = h / previous;
            // The impact is handled up to one envelope below the plane, so the
            // apex can be off by about envelope/h: under 1% for these heights.
            assert!(
                (ratio - e * e).abs() / (e * e) < 0.02,
                "{kind}: bounce {i}: ratio {ratio}, expected {}",
                e * e
            );
            previous = h;
        }
        assert!(
            w.stats().backtracks > 0,
            "{kind}: the backtracking path was not exercised"
        );
    }
}

#[test]
fn backtracking_is_what_keeps_the_bounce_faithful() {
    // Same drop with an infinite envelope (no event is ever "missed"): the
    // impact is found up to a whole step late and the apex is wrong by far
    // more. This shows the backtracking above is doing the work.
    let e = 0.8;
    let dt = 10.0 * 1e-3 / (2.0 * G * 1.0f64).sqrt();
    let (mut w, p) = ball_world(IntegratorKind::Rk4, e, f64::INFINITY, 1.05);
    let apex = apexes(&mut w, p, dt * 4.0, 1.0);
    assert_eq!(w.stats().backtracks, 0);
    let ratio = apex[0] / 1.0;
    assert!(
        (ratio - e * e).abs() / (e * e) > 0.02,
        "unexpectedly accurate without backtracking: {ratio}"
    );
}

#[test]
fn a_ball_comes_to_rest_on_the_floor() {
    let (mut w, p) = ball_world(IntegratorKind::Rk4, 0.5, 1e-3, 0.55);
    for _ in 0..5000 {
        w.step(1e-3).unwrap();
    }
    assert!(
        (w.position(p).y - 0.05).abs() < 1e-12,
        "ball at {}",
        w.position(p)
    );
    assert_eq!(w.velocity(p), DVec3::ZERO);
}

fn slider(kind: IntegratorKind, v0: f64) -> (World, ParticleId) {
    let mut w = World::new();
    w.set_gravity(DVec3::new(0.0, -G, 0.0));
    w.set_integrator(kind);
    let p = w
        .add_particle(
            ParticleDef::new(2.0)
                .with_radius(0.1)
                .with_friction(0.5, 0.3)
                .at(DVec3::new(0.0, 0.1, 0.0))
                .with_velocity(DVec3::new(v0 * 0.6, 0.0, v0 * 0.8)),
        )
        .unwrap();
    w.add_floor(FloorDef::default()).unwrap();
    (w, p)
}

#[test]
fn a_sliding_particle_stops_at_v2_over_2_mu_k_g_and_stays_stopped() {
    let v0 = 2.0;
    let expected = v0 * v0 / (2.0 * 0.3 * G);
    for kind in IntegratorKind::ALL {
        let (mut w, p) = slider(kind, v0);
        for _ in 0..1500 {
            w.step(1e-3).unwrap();
        }
        let stopped_at = w.position(p);
        let d = DVec3::new(stopped_at.x, 0.0, stopped_at.z).length();
        assert!(
            (d - expected).abs() / expected < 0.02,
            "{kind}: slid {d} m, expected {expected}"
        );
        // It slid straight: friction opposes the velocity, never turns it.
        assert!((stopped_at.x / stopped_at.z - 0.75).abs() < 1e-9);
        for _ in 0..1000 {
            w.step(1e-3).unwrap();
        }
        assert!(
            (w.position(p) - stopped_at).length() < 1e-6,
            "{kind}: crept from {stopped_at} to {}",
            w.position(p)
        );
        assert!(w.velocity(p).length() < 1e-6);
        assert_eq!(w.position(p).y, 0.1, "{kind}: did not stay on the floor");
    }
}

#[test]
fn static_friction_holds_below_mu_s_n_and_kinetic_acts_above() {
    let (m, mu_s, mu_k) = (2.0, 0.5, 0.3);
    for kind in IntegratorKind::ALL {
        for (fraction, moves) in [(0.45, false), (0.7, true)] {
            let (mut w, p) = slider(kind, 0.0);
            let push = fraction * m * G;
            w.add_constant_force(vec![p], DVec3::new(push, 0.0, 0.0))
                .unwrap();
            for _ in 0..1000 {
                w.step(1e-3).unwrap();
            }
            let v = w.velocity(p).x;
            if moves {
                // Newton with kinetic friction: a = (F - μk m g) / m.
                let expected = (fraction - mu_k) * G * 1.0;
                assert!(
                    (v - expected).abs() / expected < 0.01,
                    "{kind}: v = {v}, expected {expected}"
                );
            } else {
                assert!(fraction < mu_s);
                assert_eq!(w.position(p).x, 0.0, "{kind}: static friction let it slip");
                assert_eq!(v, 0.0);
            }
        }
    }
}

/// A user-defined event, written outside the engine: a wall at x = 1 that
/// reflects spheres elastically. It plugs into the world without any change
/// to an integrator, and gets the backtracking for free.
struct Wall {
    envelope: f64,
    hits: Vec<usize>,
}

impl DiscreteEvent for Wall {
    fn check(&mut self, ctx: &EventContext) -> EventState {
        self.hits.clear();
        let mut state = EventState::None;
        for (i, p) in ctx.pos.iter().enumerate() {
            let depth = p.x + ctx.particles.radius[i] - 1.0;
            if depth > 0.0 {
                self.hits.push(i);
                state = state.max(if depth > self.envelope {
                    EventState::Missed
                } else {
                    EventState::Occurring
                });
            }
        }
        state
    }
    fn handle(&mut self, _t: f64, pos: &mut [DVec3], vel: &mut [DVec3], particles: &Properties) {
        for &i in &self.hits {
            pos[i].x = 1.0 - particles.radius[i];
            vel[i].x = -vel[i].x.abs();
        }
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

#[test]
fn a_user_event_plugs_in_and_backtracks() {
    let mut w = World::new();
    let p = w
        .add_particle(
            ParticleDef::new(1.0)
                .with_radius(0.1)
                .with_velocity(DVec3::new(10.0, 0.0, 0.0)),
        )
        .unwrap();
    w.add_event(Box::new(Wall {
        envelope: 1e-4,
        hits: vec![],
    }));
    let mut max_x = f64::MIN;
    for _ in 0..20 {
        w.step(0.01).unwrap(); // 10 cm per step against a 0.1 mm envelope
        max_x = max_x.max(w.position(p).x);
    }
    assert!(max_x <= 0.9 + 1e-12, "went through the wall: {max_x}");
    assert_eq!(w.velocity(p).x, -10.0);
    // Reflected 0.9 m from the start, so after 0.2 s it is back at 0.9 - 1.1 = -0.2.
    assert!(
        (w.position(p).x + 0.2).abs() < 1e-4 + 1e-9,
        "at {}",
        w.position(p).x
    );
    assert!(
        w.stats().backtracks >= 9,
        "a 1e-4 envelope needs ~10 halvings: {}",
        w.stats().backtracks
    );
}
