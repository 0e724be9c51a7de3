//! Stiff bodies for the implicit integrator: a cloth hanging from two
//! corners, chain-64 without its floor, and a seaweed frond let go from a
//! bent start in still water; each world's total mechanical energy (with the
//! water's buoyancy, which the engine's `energy()` leaves out); and the
//! check that implicit Euler stays finite and never gains energy at ten
//! times the largest step at which symplectic Euler is stable.

use crate::mass_spring::{self, DAMPING, GRAVITY, MASS, SPACING, STIFFNESS};
use crate::stability::largest_stable_step;
use animats_creatures::seaworld::{seaweed, SeaweedConstants};
use animats_engine::{
    DVec3, FluidMedium, IntegratorKind, ParticleDef, ParticleId, SpringDef, World,
};

/// The cloth-N grid (structural and shear springs of the workload's
/// stiffness `k` and damping), flat at height 1 m, pinned at the two corners
/// of its first row, falling under gravity; no floor.
pub fn hanging_cloth(n: usize, k: f64, kind: IntegratorKind) -> World {
    let spec = mass_spring::cloth(n);
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -GRAVITY, 0.0));
    for i in 0..n {
        for j in 0..n {
            let mut def = ParticleDef::new(MASS)
                .at(DVec3::new(i as f64 * SPACING, 1.0, j as f64 * SPACING))
                .with_radius(0.0);
            def.fixed = i == 0 && (j == 0 || j == n - 1);
            w.add_particle(def).expect("valid cloth particle");
        }
    }
    for &(a, b) in &spec.edges {
        let (a, b) = (
            ParticleId::from_index(a as usize),
            ParticleId::from_index(b as usize),
        );
        w.add_spring(SpringDef::new(a, b, k, DAMPING))
            .expect("valid cloth spring");
    }
    w
}

/// chain-64 (the workload's chain, pinned at one end, swinging down) without
/// the workload's floor.
pub fn chain(kind: IntegratorKind) -> World {
    let spec = mass_spring::chain64();
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -GRAVITY, 0.0));
    for (x, &pinned) in spec.positions.iter().zip(&spec.pinned) {
        let mut def = ParticleDef::new(MASS).at(*x).with_radius(0.0);
        def.fixed = pinned;
        w.add_particle(def).expect("valid chain particle");
    }
    for &(a, b) in &spec.edges {
        let (a, b) = (
            ParticleId::from_index(a as usize),
            ParticleId::from_index(b as usize),
        );
        w.add_spring(SpringDef::new(a, b, STIFFNESS, DAMPING))
            .expect("valid chain spring");
    }
    w
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
    let mut search = || -> Box<dyn FnMut(f64) -> Result<f64, ()>> {
        let mut w = make(IntegratorKind::Symplectic);
        Box::new(move |h| {
            w.step(h).map_err(|_| ())?;
            Ok(w.state().vel.iter().map(|v| v.length()).fold(0.0, f64::max))
        })
    };
    let symplectic = largest_stable_step(&mut search, seconds, bound);
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
        fastest = w
            .state()
            .vel
            .iter()
            .map(|v| v.length())
            .fold(fastest, f64::max);
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
