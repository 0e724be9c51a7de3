//! The mass-spring workloads `cloth-N` and `chain-64` (`docs/WORKLOADS.md` §1),
//! built through the engine's public API, and the plain hand-written
//! structure-of-arrays loop they are compared with.
// std's transcendental functions: this code draws or benchmarks, off the step path
#![allow(clippy::disallowed_methods)]

use animats_engine::{
    ByPieces, DVec3, DiscreteEvent, EventContext, EventState, IntegratorKind, ParticleDef,
    ParticleId, Properties, SpringDef, TrialPiece, World,
};
use std::f64::consts::PI;
use std::ops::Range;

/// Particle mass, kg.
pub const MASS: f64 = 0.001;
/// Grid spacing, m.
pub const SPACING: f64 = 0.02;
/// Spring stiffness, N/m.
pub const STIFFNESS: f64 = 100.0;
/// Spring damping along its axis, N s/m.
pub const DAMPING: f64 = 0.05;
/// Gravity, m/s² (down).
pub const GRAVITY: f64 = 9.81;
/// Floor restitution.
pub const RESTITUTION: f64 = 0.5;
/// Step, s.
pub const DT: f64 = 1e-3;
/// Steps per run.
pub const STEPS: usize = 1000;

/// A mass-spring system's initial configuration.
#[derive(Clone, Debug)]
pub struct Spec {
    /// Initial positions (velocities start at zero).
    pub positions: Vec<DVec3>,
    /// Which particles are pinned.
    pub pinned: Vec<bool>,
    /// Springs as an edge list, in the order the workload lists them.
    pub edges: Vec<(u32, u32)>,
}

/// `cloth-N`: an N×N sheet shaped as a shallow dome, structural and shear springs.
pub fn cloth(n: usize) -> Spec {
    let mut positions = Vec::with_capacity(n * n);
    let s = |k: usize| (PI * k as f64 / (n - 1) as f64).sin();
    for i in 0..n {
        for j in 0..n {
            let y = 0.3 + 0.1 * s(i) * s(j);
            positions.push(DVec3::new(i as f64 * SPACING, y, j as f64 * SPACING));
        }
    }
    let mut edges = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let p = (i * n + j) as u32;
            let n32 = n as u32;
            if j + 1 < n {
                edges.push((p, p + 1));
            }
            if i + 1 < n {
                edges.push((p, p + n32));
            }
            if i + 1 < n && j + 1 < n {
                edges.push((p, p + n32 + 1));
            }
            if i + 1 < n && j > 0 {
                edges.push((p, p + n32 - 1));
            }
        }
    }
    Spec {
        pinned: vec![false; positions.len()],
        positions,
        edges,
    }
}

/// `chain-64`: a horizontal chain pinned at one end, swinging down.
pub fn chain64() -> Spec {
    let positions: Vec<DVec3> = (0..64)
        .map(|i| DVec3::new(i as f64 * SPACING, 1.0, 0.0))
        .collect();
    let mut pinned = vec![false; 64];
    pinned[0] = true;
    Spec {
        positions,
        pinned,
        edges: (0..63).map(|i| (i, i + 1)).collect(),
    }
}

/// A spec as a world, through the public API: point particles of the
/// workloads' mass and restitution, springs of stiffness `k` and damping `c`
/// at rest, gravity; no floor.
pub fn spring_world(spec: &Spec, k: f64, c: f64, kind: IntegratorKind) -> World {
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -GRAVITY, 0.0));
    for (x, &pinned) in spec.positions.iter().zip(&spec.pinned) {
        let mut def = ParticleDef::new(MASS)
            .at(*x)
            .with_radius(0.0)
            .with_restitution(RESTITUTION);
        def.fixed = pinned;
        w.add_particle(def).expect("valid workload particle");
    }
    for &(a, b) in &spec.edges {
        let def = SpringDef::new(
            ParticleId::from_index(a as usize),
            ParticleId::from_index(b as usize),
            k,
            c,
        );
        w.add_spring(def).expect("valid workload spring");
    }
    w
}

/// The workload as a world: [`spring_world`] with the workload's springs,
/// and a floor that only collides (no friction, no envelope: the workload's
/// floor rule, applied after each full step).
pub fn engine_world(spec: &Spec, kind: IntegratorKind) -> World {
    let mut w = spring_world(spec, STIFFNESS, DAMPING, kind);
    w.add_event(Box::new(WorkloadFloor));
    w
}

/// The workloads' floor rule, applied after each whole step: `if y < 0 { if
/// v_y < 0 { v_y ← −e v_y }; y ← 0 }` for point particles. The engine's own
/// floor is more careful (it reflects the speed at the plane, so an impact
/// never adds energy, and lets bounces end): a user event reproduces the
/// published rule exactly, as any user can plug in their own.
///
/// The rule looks at each particle on its own, so the event keeps no records:
/// it settles pieces (each thread checks and handles the piece it has just
/// integrated, inside the integrator's loop), and `check` and `handle` are
/// its piece-by-piece versions over every particle, for the integrators
/// that do not write by pieces.
#[derive(Clone, Debug, Default)]
pub struct WorkloadFloor;

/// Whether a moving particle of `pos` (inverse masses `inv_mass`) is below
/// the floor.
fn below(pos: &[DVec3], inv_mass: &[f64]) -> bool {
    pos.iter()
        .zip(inv_mass)
        .any(|(x, &w)| x.y < 0.0 && w != 0.0)
}

impl DiscreteEvent for WorkloadFloor {
    fn check(&mut self, ctx: &EventContext) -> EventState {
        self.check_piece(ctx, 0..ctx.pos.len())
            .unwrap_or(EventState::None)
    }

    fn handle(&mut self, t: f64, pos: &mut [DVec3], vel: &mut [DVec3], p: &Properties) {
        self.handle_piece(t, 0, pos, vel, p);
    }

    fn name(&self) -> &str {
        "workload floor"
    }

    fn by_pieces(&self) -> Option<&dyn ByPieces> {
        Some(self)
    }
}

impl ByPieces for WorkloadFloor {
    fn check_piece(&self, ctx: &EventContext, range: Range<usize>) -> Option<EventState> {
        Some(
            if below(&ctx.pos[range.clone()], &ctx.particles.inv_mass[range]) {
                EventState::Occurring
            } else {
                EventState::None
            },
        )
    }

    fn handles_pieces(&self) -> bool {
        true
    }

    fn settles_pieces(&self) -> bool {
        true
    }

    fn settle_piece(&self, piece: &mut TrialPiece) -> EventState {
        // The read-only scan first: most steps of most pieces have nothing
        // below the floor, and it is cheaper than the loop that writes.
        let p = piece.particles;
        if !below(piece.pos, &p.inv_mass[piece.first..]) {
            return EventState::None;
        }
        self.handle_piece(piece.t, piece.first, piece.pos, piece.vel, p);
        EventState::Occurring
    }

    fn handle_piece(
        &self,
        _t: f64,
        first: usize,
        pos: &mut [DVec3],
        vel: &mut [DVec3],
        p: &Properties,
    ) {
        for (i, (x, v)) in pos.iter_mut().zip(vel.iter_mut()).enumerate() {
            if x.y < 0.0 && p.inv_mass[first + i] != 0.0 {
                if v.y < 0.0 {
                    v.y *= -p.restitution[first + i];
                }
                x.y = 0.0;
            }
        }
    }
}

/// The plain hand-written structure-of-arrays loop over an edge list.
pub struct Baseline {
    x: Vec<DVec3>,
    v: Vec<DVec3>,
    w: Vec<f64>,
    edges: Vec<(u32, u32, f64)>,
    f: Vec<DVec3>,
    // RK4 buffers
    x0: Vec<DVec3>,
    v0: Vec<DVec3>,
    dx: Vec<DVec3>,
    dv: Vec<DVec3>,
}

impl Baseline {
    /// The workload at its initial state.
    pub fn new(spec: &Spec) -> Self {
        let n = spec.positions.len();
        let x = spec.positions.clone();
        let edges = spec
            .edges
            .iter()
            .map(|&(a, b)| (a, b, (x[b as usize] - x[a as usize]).length()))
            .collect();
        Baseline {
            w: spec
                .pinned
                .iter()
                .map(|&p| if p { 0.0 } else { 1.0 / MASS })
                .collect(),
            x,
            v: vec![DVec3::ZERO; n],
            edges,
            f: vec![DVec3::ZERO; n],
            x0: vec![DVec3::ZERO; n],
            v0: vec![DVec3::ZERO; n],
            dx: vec![DVec3::ZERO; n],
            dv: vec![DVec3::ZERO; n],
        }
    }

    fn springs(edges: &[(u32, u32, f64)], x: &[DVec3], v: &[DVec3], f: &mut [DVec3]) {
        f.fill(DVec3::ZERO);
        for &(a, b, l0) in edges {
            let (a, b) = (a as usize, b as usize);
            let d = x[b] - x[a];
            let l = d.length();
            let n = d / l;
            let fs = n * (STIFFNESS * (l - l0) + DAMPING * (v[b] - v[a]).dot(n));
            f[a] += fs;
            f[b] -= fs;
        }
    }

    #[inline]
    fn accel(w: f64, f: DVec3) -> DVec3 {
        w * (f + MASS * DVec3::new(0.0, -GRAVITY, 0.0))
    }

    fn floor(x: &mut [DVec3], v: &mut [DVec3]) {
        for (x, v) in x.iter_mut().zip(v.iter_mut()) {
            if x.y < 0.0 {
                if v.y < 0.0 {
                    v.y *= -RESTITUTION;
                }
                x.y = 0.0;
            }
        }
    }

    /// One semi-implicit Euler step.
    pub fn step_symplectic(&mut self) {
        Self::springs(&self.edges, &self.x, &self.v, &mut self.f);
        for i in 0..self.x.len() {
            self.v[i] += DT * Self::accel(self.w[i], self.f[i]);
            self.x[i] += DT * self.v[i];
        }
        Self::floor(&mut self.x, &mut self.v);
    }

    /// One classical RK4 step, floor after the step.
    pub fn step_rk4(&mut self) {
        let n = self.x.len();
        self.x0.copy_from_slice(&self.x);
        self.v0.copy_from_slice(&self.v);
        let h = 0.5 * DT;
        // k1 at (x0, v0); (x, v) then hold the trial states.
        Self::springs(&self.edges, &self.x, &self.v, &mut self.f);
        for i in 0..n {
            let a = Self::accel(self.w[i], self.f[i]);
            self.dx[i] = self.v0[i];
            self.dv[i] = a;
            self.x[i] = self.x0[i] + h * self.v0[i];
            self.v[i] = self.v0[i] + h * a;
        }
        for step in [h, DT] {
            Self::springs(&self.edges, &self.x, &self.v, &mut self.f);
            for i in 0..n {
                let a = Self::accel(self.w[i], self.f[i]);
                let v = self.v[i];
                self.dx[i] += 2.0 * v;
                self.dv[i] += 2.0 * a;
                self.x[i] = self.x0[i] + step * v;
                self.v[i] = self.v0[i] + step * a;
            }
        }
        Self::springs(&self.edges, &self.x, &self.v, &mut self.f);
        for i in 0..n {
            let a = Self::accel(self.w[i], self.f[i]);
            let v = self.v[i];
            self.x[i] = self.x0[i] + DT / 6.0 * (self.dx[i] + v);
            self.v[i] = self.v0[i] + DT / 6.0 * (self.dv[i] + a);
        }
        Self::floor(&mut self.x, &mut self.v);
    }

    /// Positions and velocities.
    pub fn state(&self) -> (&[DVec3], &[DVec3]) {
        (&self.x, &self.v)
    }
}

/// The workload's checks: centre of mass and kinetic energy (equal masses).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Centre of mass, m.
    pub com: DVec3,
    /// Kinetic energy of the moving particles, J.
    pub kinetic: f64,
    /// Lowest particle height, m.
    pub min_y: f64,
    /// True when every coordinate is finite.
    pub finite: bool,
}

/// Centre of mass, kinetic energy and sanity of a state.
pub fn summarise(x: &[DVec3], v: &[DVec3], pinned: &[bool]) -> Summary {
    let n = x.len() as f64;
    Summary {
        com: x.iter().sum::<DVec3>() / n,
        kinetic: v
            .iter()
            .zip(pinned)
            .filter(|(_, &p)| !p)
            .map(|(v, _)| 0.5 * MASS * v.length_squared())
            .sum(),
        min_y: x.iter().map(|p| p.y).fold(f64::INFINITY, f64::min),
        finite: x.iter().chain(v).all(|p| p.is_finite()),
    }
}

/// Reference final states from `WORKLOADS.md` (com_x, com_y, kinetic energy).
pub fn reference(workload: &str, kind: IntegratorKind) -> Option<(f64, f64, f64)> {
    use IntegratorKind::{Rk4, Symplectic};
    Some(match (workload, kind) {
        ("chain-64", Symplectic) => (-0.5269383, 0.3888052, 0.08421876),
        ("chain-64", Rk4) => (-0.5279053, 0.393785, 0.08954462),
        ("cloth-32", Symplectic) => (0.31, 0.0003815829, 0.0004608662),
        ("cloth-32", Rk4) => (0.31, 0.0003249338, 0.0001634381),
        ("cloth-128", Symplectic) => (1.27, 0.0, 0.0009081919),
        ("cloth-128", Rk4) => (1.27, 8.037089e-07, 0.001083626),
        _ => return None,
    })
}
