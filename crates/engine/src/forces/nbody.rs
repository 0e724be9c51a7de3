//! Mutual gravitation among a set of bodies (the thesis's tutorial force,
//! §4.1.2), with optional Plummer softening: every pair `i < j` attracts with
//! `F = G mᵢ mⱼ d / (|d|² + ε²)^{3/2}`, equal and opposite. The tutorial
//! version written outside the engine is `examples/nbody.rs`; this one is what
//! scene files get as `[[nbody]]`.

use crate::error::ModelError;
use crate::force::{Force, ForceContext, Targets};
use crate::particle::non_negative;
use glam::DVec3;

/// Newtonian gravity between every pair of its bodies.
#[derive(Clone, Debug, PartialEq)]
pub struct NBodyGravity {
    /// Gravitational constant, N m²/kg².
    pub g: f64,
    /// Softening length ε, m.
    pub softening: f64,
    targets: Targets,
    /// The bodies' indices, resolved once (and again if `All` grows).
    indices: Vec<u32>,
}

impl NBodyGravity {
    /// The SI gravitational constant, N m²/kg².
    pub const G_SI: f64 = 6.674e-11;

    /// Gravity with constant `g` and softening `softening` among `targets`.
    pub fn new(g: f64, softening: f64, targets: Targets) -> Self {
        let indices = match &targets {
            Targets::All => Vec::new(),
            Targets::Only(ids) => ids.iter().map(|id| id.index() as u32).collect(),
        };
        NBodyGravity {
            g,
            softening,
            targets,
            indices,
        }
    }

    /// The bodies.
    pub fn targets(&self) -> &Targets {
        &self.targets
    }

    /// Checks the constants.
    pub fn validate(&self) -> Result<(), ModelError> {
        non_negative("G", self.g)?;
        non_negative("softening", self.softening)?;
        Ok(())
    }

    fn resolve(&mut self, n: usize) {
        if self.targets == Targets::All && self.indices.len() != n {
            self.indices = (0..n as u32).collect();
        }
    }
}

impl Force for NBodyGravity {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        self.resolve(ctx.pos.len());
        let eps2 = self.softening * self.softening;
        let (pos, mass) = (ctx.pos, &ctx.particles.mass);
        for (k, &i) in self.indices.iter().enumerate() {
            let i = i as usize;
            let (pi, gmi) = (pos[i], self.g * mass[i]);
            let mut fi = DVec3::ZERO;
            for &j in &self.indices[k + 1..] {
                let j = j as usize;
                let d = pos[j] - pi;
                let r2 = d.length_squared() + eps2;
                let f = d * (gmi * mass[j] / (r2 * r2.sqrt()));
                fi += f;
                forces[j] -= f;
            }
            forces[i] += fi;
        }
    }

    fn potential_energy(&self, ctx: &ForceContext) -> f64 {
        let mut ids = Vec::new();
        self.targets.for_each(ctx.pos.len(), |i| ids.push(i));
        let eps2 = self.softening * self.softening;
        let mut e = 0.0;
        for (k, &i) in ids.iter().enumerate() {
            for &j in &ids[k + 1..] {
                let r = ((ctx.pos[j] - ctx.pos[i]).length_squared() + eps2).sqrt();
                e -= self.g * ctx.particles.mass[i] * ctx.particles.mass[j] / r;
            }
        }
        e
    }

    fn is_conservative(&self) -> bool {
        true
    }

    fn name(&self) -> &str {
        "n-body gravity"
    }
}
