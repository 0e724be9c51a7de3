//! `allpairs-1000`: all-pairs softened gravity among 1000 bodies
//! (`docs/WORKLOADS.md`), through the engine's built-in `NBodyGravity`, beside a
//! plain hand-written loop over every (i, j).

use animats_engine::{DVec3, IntegratorKind, NBodyGravity, ParticleDef, Targets, World};

/// Bodies.
pub const N: usize = 1000;
/// Softening length.
pub const SOFTENING: f64 = 0.01;
/// Step.
pub const DT: f64 = 1e-3;
/// Steps per run (quick mode: 20).
pub const STEPS: usize = 100;

/// Reference: E(0), E(100 steps), relative drift, com_x, rms radius.
pub const REFERENCE: (f64, f64, f64, f64, f64) = (
    -0.9282706899967,
    -0.9284587864034,
    -2.026e-4,
    -0.000157,
    0.4906507582,
);

/// Initial positions: the R3 low-discrepancy sequence in [-0.5, 0.5)³.
pub fn positions() -> Vec<DVec3> {
    let g = 1.2207440845057596f64;
    let alpha = [1.0 / g, 1.0 / (g * g), 1.0 / (g * g * g)];
    (0..N)
        .map(|i| {
            let c = |k: usize| {
                let x = 0.5 + alpha[k] * (i + 1) as f64;
                x - x.floor() - 0.5
            };
            DVec3::new(c(0), c(1), c(2))
        })
        .collect()
}

/// The workload as a world: equal masses 1/N, `NBodyGravity` with G = 1 and
/// softening, kick-drift symplectic Euler.
pub fn engine_world() -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    for x in positions() {
        w.add_particle(ParticleDef::new(1.0 / N as f64).at(x))
            .expect("valid body");
    }
    w.add_nbody(NBodyGravity::new(1.0, SOFTENING, Targets::All))
        .expect("valid n-body force");
    w
}

/// The plain loop: for each i, sum over every j, then kick and drift.
pub struct Baseline {
    /// Positions.
    pub x: Vec<DVec3>,
    /// Velocities.
    pub v: Vec<DVec3>,
    a: Vec<DVec3>,
}

impl Baseline {
    /// The initial state.
    pub fn new() -> Self {
        Baseline {
            x: positions(),
            v: vec![DVec3::ZERO; N],
            a: vec![DVec3::ZERO; N],
        }
    }

    /// One kick-drift step.
    pub fn step(&mut self) {
        let m = 1.0 / N as f64;
        let eps2 = SOFTENING * SOFTENING;
        for i in 0..N {
            let xi = self.x[i];
            let mut a = DVec3::ZERO;
            for xj in &self.x {
                let d = *xj - xi;
                let r2 = d.length_squared() + eps2;
                a += d * (m / (r2 * r2.sqrt()));
            }
            self.a[i] = a;
        }
        self.kick_drift();
    }

    /// One kick-drift step summing each pair once (i < j) and applying it to
    /// both bodies: half the square roots of [`step`](Baseline::step).
    pub fn step_pairs(&mut self) {
        let m = 1.0 / N as f64;
        let eps2 = SOFTENING * SOFTENING;
        self.a.fill(DVec3::ZERO);
        for i in 0..N {
            let xi = self.x[i];
            let mut ai = DVec3::ZERO;
            for j in i + 1..N {
                let d = self.x[j] - xi;
                let r2 = d.length_squared() + eps2;
                let f = d * (m / (r2 * r2.sqrt()));
                ai += f;
                self.a[j] -= f;
            }
            self.a[i] += ai;
        }
        self.kick_drift();
    }

    fn kick_drift(&mut self) {
        for i in 0..N {
            self.v[i] += DT * self.a[i];
            self.x[i] += DT * self.v[i];
        }
    }
}

impl Default for Baseline {
    fn default() -> Self {
        Self::new()
    }
}

/// E = Σ ½ m v² − Σ_{i<j} m² / √(r² + ε²).
pub fn energy(x: &[DVec3], v: &[DVec3]) -> f64 {
    let m = 1.0 / N as f64;
    let eps2 = SOFTENING * SOFTENING;
    let mut e: f64 = v.iter().map(|v| 0.5 * m * v.length_squared()).sum();
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            e -= m * m / ((x[i] - x[j]).length_squared() + eps2).sqrt();
        }
    }
    e
}

/// (com_x, rms radius about the origin).
pub fn shape(x: &[DVec3]) -> (f64, f64) {
    let n = x.len() as f64;
    let com = x.iter().map(|p| p.x).sum::<f64>() / n;
    let rms = (x.iter().map(|p| p.length_squared()).sum::<f64>() / n).sqrt();
    (com, rms)
}
