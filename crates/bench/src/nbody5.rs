//! `nbody5`: the Computer Language Benchmarks Game's n-body
//! (`docs/WORKLOADS.md`), run through the engine with the tutorial's user-defined
//! force (`examples/nbody/gravity.rs`) and with the built-in n-body force,
//! beside the reference scalar `advance`.

use animats_engine::{DVec3, IntegratorKind, ParticleDef, World};
use std::f64::consts::PI;

#[path = "../../../examples/nbody/gravity.rs"]
mod tutorial;

/// 4π²: the Sun's mass in units of AU and years.
pub const SOLAR_MASS: f64 = 4.0 * PI * PI;
/// Days per year: velocities are given in AU/day.
pub const DAYS_PER_YEAR: f64 = 365.24;
/// Step, years.
pub const DT: f64 = 0.01;

/// Published energies: E(0), E(1000 steps), E(50,000,000 steps).
pub const E0: f64 = -0.169075164;
/// E after 1,000 steps.
pub const E1000: f64 = -0.169087605;
/// E after 50,000,000 steps.
pub const E50M: f64 = -0.169059907;

/// (position, velocity, mass) of Sun, Jupiter, Saturn, Uranus, Neptune, with
/// the Sun's velocity set so the total momentum is zero (`offset_momentum`).
// The published initial conditions, digit for digit.
#[allow(clippy::excessive_precision)]
pub fn bodies() -> [(DVec3, DVec3, f64); 5] {
    let planet = |p: [f64; 3], v: [f64; 3], m: f64| {
        (
            DVec3::from_array(p),
            DVec3::from_array(v) * DAYS_PER_YEAR,
            m * SOLAR_MASS,
        )
    };
    let mut b = [
        (DVec3::ZERO, DVec3::ZERO, SOLAR_MASS),
        planet(
            [
                4.84143144246472090e+00,
                -1.16032004402742839e+00,
                -1.03622044471123109e-01,
            ],
            [
                1.66007664274403694e-03,
                7.69901118419740425e-03,
                -6.90460016972063023e-05,
            ],
            9.54791938424326609e-04,
        ),
        planet(
            [
                8.34336671824457987e+00,
                4.12479856412430479e+00,
                -4.03523417114321381e-01,
            ],
            [
                -2.76742510726862411e-03,
                4.99852801234917238e-03,
                2.30417297573763929e-05,
            ],
            2.85885980666130812e-04,
        ),
        planet(
            [
                1.28943695621391310e+01,
                -1.51111514016986312e+01,
                -2.23307578892655734e-01,
            ],
            [
                2.96460137564761618e-03,
                2.37847173959480950e-03,
                -2.96589568540237556e-05,
            ],
            4.36624404335156298e-05,
        ),
        planet(
            [
                1.53796971148509165e+01,
                -2.59193146099879641e+01,
                1.79258772950371181e-01,
            ],
            [
                2.68067772490389322e-03,
                1.62824170038242295e-03,
                -9.51592254519715870e-05,
            ],
            5.15138902046611451e-05,
        ),
    ];
    let p: DVec3 = b.iter().map(|(_, v, m)| *v * *m).sum();
    b[0].1 = -p / SOLAR_MASS;
    b
}

/// The system as a world: five particles, the tutorial's user force with
/// G = 1, symplectic Euler.
pub fn engine_world() -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    for (p, v, m) in bodies() {
        w.add_particle(ParticleDef::new(m).at(p).with_velocity(v))
            .expect("valid body");
    }
    let bodies: Vec<_> = w.particle_ids().collect();
    w.add_force(Box::new(tutorial::NBodyGravity::new(1.0, &bodies)));
    w
}

/// The same system with the engine's built-in n-body force
/// ([`animats_engine::NBodyGravity`], G = 1, no softening) instead of the
/// tutorial's user force.
pub fn builtin_world() -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    for (p, v, m) in bodies() {
        w.add_particle(ParticleDef::new(m).at(p).with_velocity(v))
            .expect("valid body");
    }
    w.add_nbody(animats_engine::NBodyGravity::new(
        1.0,
        0.0,
        animats_engine::Targets::All,
    ))
    .expect("valid n-body force");
    w
}

/// The reference program's data and `advance`, as published (scalar).
pub struct Reference {
    /// (position, velocity, mass) per body.
    pub bodies: [(DVec3, DVec3, f64); 5],
}

impl Reference {
    /// The initial state.
    pub fn new() -> Self {
        Reference { bodies: bodies() }
    }

    /// One step of the reference algorithm.
    pub fn advance(&mut self, dt: f64) {
        let b = &mut self.bodies;
        for i in 0..5 {
            for j in i + 1..5 {
                let d = b[i].0 - b[j].0;
                let d2 = d.length_squared();
                let mag = dt / (d2 * d2.sqrt());
                let (mi, mj) = (b[i].2, b[j].2);
                b[i].1 -= d * (mj * mag);
                b[j].1 += d * (mi * mag);
            }
        }
        for body in b.iter_mut() {
            body.0 += dt * body.1;
        }
    }

    /// Total energy.
    pub fn energy(&self) -> f64 {
        energy(&self.bodies)
    }
}

impl Default for Reference {
    fn default() -> Self {
        Self::new()
    }
}

/// Total energy of (position, velocity, mass) bodies, G = 1.
pub fn energy(b: &[(DVec3, DVec3, f64)]) -> f64 {
    let mut e = 0.0;
    for i in 0..b.len() {
        e += 0.5 * b[i].2 * b[i].1.length_squared();
        for j in i + 1..b.len() {
            e -= b[i].2 * b[j].2 / (b[i].0 - b[j].0).length();
        }
    }
    e
}

/// Energy of the engine's world, computed the reference way.
pub fn world_energy(w: &World) -> f64 {
    let b: Vec<_> = w
        .particle_ids()
        .map(|p| (w.position(p), w.velocity(p), w.particles().mass[p.index()]))
        .collect();
    energy(&b)
}
