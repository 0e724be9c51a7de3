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
fn backtracking_is_what_keeps_the_bounce_on_time() {
    // The impact's energy is right however late it is found (the rebound is
    // computed from the speed at the plane), but its time is not: without
    // backtracking (an infinite envelope, nothing is ever "missed") the
    // sphere sinks up to a whole step into the floor before it is found and
    // put back, and the bounce starts late. Dropped from 1 m (lowest
    // point), it lands at t1 = √(2/g) at v1 = g t1 and then follows
    // y = e v1 (t − t1) − g (t − t1)² / 2 until the next impact.
    let e = 0.8;
    let dt = 10.0 * 1e-3 / (2.0 * G * 1.0f64).sqrt(); // ≈ 2.3 ms
    let t1 = (2.0 / G).sqrt();
    let v1 = G * t1;
    let error_at = |envelope: f64, h: f64| {
        let (mut w, p) = ball_world(IntegratorKind::Rk4, e, envelope, 1.05);
        let steps = ((t1 + 0.2) / h).round() as usize;
        for _ in 0..steps {
            w.step(h).unwrap();
        }
        let s = w.time() - t1;
        let exact = e * v1 * s - 0.5 * G * s * s;
        ((w.position(p).y - 0.05) - exact).abs()
    };
    let with = error_at(1e-3, dt);
    let without = error_at(f64::INFINITY, 4.0 * dt);
    println!("height error 0.2 s after the bounce: {with:.2e} m with backtracking, {without:.2e} m without");
    // With it, the impact is placed within the 1 mm envelope: off by at most
    // e × envelope in height (plus the integration error).
    assert!(with < 1e-3, "with backtracking: {with} m");
    assert!(without > 5.0 * with, "without backtracking: {without} m");
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
#[derive(Clone)]
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

// ----- contact that settles (issue 9) -------------------------------------

/// The restitutions and steps the settling properties are checked over: the
/// whole range [0, 1) and steps up to 8 ms.
const RESTITUTIONS: [f64; 6] = [0.0, 0.25, 0.5, 0.75, 0.9, 0.99];
const STEPS: [f64; 4] = [1e-3, 2e-3, 4e-3, 8e-3];

/// Steps until the sphere rests on the plane (|v| < 1e-6, lowest point on
/// it); returns the number of impacts, or panics after `limit` seconds.
fn settle(w: &mut World, p: ParticleId, dt: f64, limit: f64, label: &str) -> usize {
    let r = w.particles().radius[p.index()];
    let mut impacts = 0;
    while w.time() < limit {
        w.step(dt).unwrap();
        impacts += w.event::<FloorCollision>().unwrap().collisions().len();
        let v = w.velocity(p);
        if v.y == 0.0 && (w.position(p).y - r).abs() < 1e-12 && v.length() < 1e-6 {
            return impacts;
        }
    }
    panic!(
        "{label}: still moving after {limit} s and {impacts} impacts: at {}, v = {}",
        w.position(p),
        w.velocity(p)
    );
}

#[test]
fn a_dropped_sphere_stops_bouncing_and_rests_for_every_integrator_restitution_and_step() {
    for kind in IntegratorKind::ALL {
        for e in RESTITUTIONS {
            for dt in STEPS {
                let label = format!("{kind}, e = {e}, dt = {dt}");
                let (mut w, p) = ball_world(kind, e, 0.01, 0.35);
                // Bounce heights fall by e² a bounce, so the series of flight
                // times sums to (1 + e) / (1 - e) times the first fall.
                let fall = (2.0 * 0.3 / G).sqrt();
                let limit = 2.0 + fall * (1.0 + e) / (1.0 - e);
                let impacts = settle(&mut w, p, dt, limit, &label);
                assert!(impacts >= 1, "{label}: never hit the floor");
                // And it stays: a second of resting changes nothing.
                let at = w.position(p);
                for _ in 0..(1.0 / dt) as usize {
                    w.step(dt).unwrap();
                }
                assert_eq!(w.position(p), at, "{label}: moved while resting");
                assert_eq!(w.velocity(p), DVec3::ZERO, "{label}");
            }
        }
    }
}

/// A sphere dropped 1 cm onto the floor while a constant tangential push
/// acts on it (the scene of issue 9: 0.1 kg, r = 5 cm, push 0.168 N).
fn pushed_ball(kind: IntegratorKind, e: f64, push: DVec3) -> (World, ParticleId) {
    let (mut w, p) = ball_world(kind, e, 0.01, 0.06);
    w.add_constant_force(vec![p], push).unwrap();
    (w, p)
}

#[test]
fn a_push_below_static_friction_never_moves_a_landed_sphere() {
    // Default friction μs = 0.5, μk = 0.3: μs N = 0.49 N, μk N = 0.29 N.
    let push = DVec3::new(0.15, 0.0, 0.075);
    for kind in IntegratorKind::ALL {
        for e in RESTITUTIONS {
            for dt in STEPS {
                let label = format!("{kind}, e = {e}, dt = {dt}");
                let (mut w, p) = pushed_ball(kind, e, push);
                // It lands, bounces, slides to a stop against kinetic
                // friction (the push is below μk N too), then static friction
                // holds it.
                // Until it stops (bounces of e = 0.99 last tens of seconds).
                while !(w.velocity(p).length() < 1e-9 && w.position(p).y - 0.05 < 1e-12) {
                    w.step(dt).unwrap();
                    assert!(
                        w.time() < 120.0,
                        "{label}: never came to rest; v = {}",
                        w.velocity(p)
                    );
                }
                let (t, at) = (w.time(), w.position(p));
                // Then 60 s of pushing.
                for _ in 0..(60.0 / dt).round() as usize {
                    w.step(dt).unwrap();
                }
                let drift = (w.position(p) - at).length();
                assert!(
                    drift < 1e-3,
                    "{label}: drifted {drift} m in the 60 s after resting at t = {t}"
                );
            }
        }
    }
}

#[test]
fn a_push_above_static_friction_accelerates_at_the_kinetic_rate_along_itself() {
    // 0.6 N along +x, above μs N = 0.49 N: a = (F - μk N) / m = 3.06 m/s².
    let (m, n) = (0.1, 0.1 * G);
    let push = 0.6;
    let expected = (push - 0.3 * n) / m;
    for kind in IntegratorKind::ALL {
        for dt in STEPS {
            let label = format!("{kind}, dt = {dt}");
            let (mut w, p) = ball_world(kind, 0.5, 0.01, 0.05);
            // At rest on the plane, with a lateral velocity left over from
            // roundoff that static friction would cancel.
            w.set_velocity(p, DVec3::new(0.0, 0.0, 1e-15)).unwrap();
            w.add_constant_force(vec![p], DVec3::new(push, 0.0, 0.0))
                .unwrap();
            let steps = (1.0 / dt).round() as usize;
            for _ in 0..steps {
                w.step(dt).unwrap();
            }
            let v = w.velocity(p);
            assert!(
                (v.x - expected * w.time()).abs() < 1e-9,
                "{label}: v = {v}, expected {}",
                expected * w.time()
            );
            assert!(
                w.position(p).z.abs() < 1e-12,
                "{label}: slipped sideways to z = {}",
                w.position(p).z
            );
            assert_eq!(w.position(p).y, 0.05, "{label}: left the floor");
        }
    }
}

/// Kinetic plus gravitational potential energy of a lone ball, J.
fn ball_energy(w: &World, p: ParticleId) -> f64 {
    let m = w.particles().mass[p.index()];
    0.5 * m * w.velocity(p).length_squared() + m * G * w.position(p).y
}

#[test]
fn no_impact_adds_mechanical_energy() {
    // Over every step that contains an impact, the energy after is at most
    // the energy before plus what the integrator itself adds in one step of
    // free flight under gravity: ½ m g² h² for explicit Euler, nothing for
    // the others (midpoint and RK4 are exact for a constant force,
    // symplectic Euler loses ½ m g² h²).
    for kind in IntegratorKind::ALL {
        for e in [0.0, 0.5, 0.9, 1.0] {
            for dt in STEPS {
                let label = format!("{kind}, e = {e}, dt = {dt}");
                let (mut w, p) = ball_world(kind, e, 0.01, 0.55);
                let m = 0.1;
                let own = match kind {
                    IntegratorKind::Euler => 0.5 * m * G * G * dt * dt,
                    _ => 0.0,
                };
                let mut impacts = 0;
                for _ in 0..(3.0 / dt) as usize {
                    let before = ball_energy(&w, p);
                    w.step(dt).unwrap();
                    if !w.event::<FloorCollision>().unwrap().collisions().is_empty() {
                        impacts += 1;
                        let after = ball_energy(&w, p);
                        assert!(
                            after <= before + own + 1e-12 * before.abs(),
                            "{label}: impact at t = {} took the energy from {before} to {after} J",
                            w.time()
                        );
                    }
                }
                assert!(impacts >= 1, "{label}");
            }
        }
    }
}

#[test]
fn an_elastic_ball_keeps_its_energy_over_twenty_bounces() {
    // e = 1 at the default envelope (1 cm) and the default step (1 ms), for
    // the integrators that are exact in free flight under a constant force.
    for kind in [IntegratorKind::Rk4, IntegratorKind::Midpoint] {
        let (mut w, p) = ball_world(kind, 1.0, FloorDef::default().envelope, 0.55);
        let start = ball_energy(&w, p);
        let mut bounces = 0;
        while bounces < 20 {
            w.step(1e-3).unwrap();
            bounces += w.event::<FloorCollision>().unwrap().collisions().len();
            assert!(w.time() < 20.0, "{kind}: only {bounces} bounces");
        }
        let end = ball_energy(&w, p);
        let change = (end - start) / start;
        println!("{kind}: energy change over 20 bounces {:.3e}", change);
        assert!(change.abs() < 0.005, "{kind}: energy changed by {change}");
    }
}
