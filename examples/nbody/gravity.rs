//! The force of the n-body tutorial, written outside the engine: mutual
//! gravitation among a list of bodies. This is the whole of what a user
//! writes to add a new force — a struct and `Force::apply`. (`animats bench
//! nbody5` runs the Computer Language Benchmarks Game's n-body through this
//! very code.)

use animats_engine::{DVec3, Force, ForceContext, ParticleId};

/// Newton's gravitation between every pair of bodies.
#[derive(Clone)]
pub struct NBodyGravity {
    /// Gravitational constant.
    g: f64,
    /// Every pair (i, j), i < j, of the bodies: listed once, here, so the
    /// force loop is one flat loop.
    pairs: Vec<(usize, usize)>,
}

impl NBodyGravity {
    /// Gravity with constant `g` among `bodies`.
    pub fn new(g: f64, bodies: &[ParticleId]) -> Self {
        let mut pairs = Vec::new();
        for (k, a) in bodies.iter().enumerate() {
            for b in &bodies[k + 1..] {
                pairs.push((a.index(), b.index()));
            }
        }
        NBodyGravity { g, pairs }
    }
}

impl Force for NBodyGravity {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        let (pos, mass): (&[DVec3], &[f64]) = (ctx.pos, &ctx.particles.mass);
        for &(i, j) in &self.pairs {
            let d = pos[j] - pos[i];
            let r2 = d.length_squared();
            // F = G mᵢ mⱼ / r², along d: pulls i towards j and j towards i.
            let f = d * (self.g * mass[i] * mass[j] / (r2 * r2.sqrt()));
            forces[i] += f;
            forces[j] -= f;
        }
    }

    /// -Σ G mᵢ mⱼ / r over the pairs.
    fn potential_energy(&self, ctx: &ForceContext) -> f64 {
        let m = &ctx.particles.mass;
        let r = |i: usize, j: usize| (ctx.pos[j] - ctx.pos[i]).length();
        self.pairs
            .iter()
            .map(|&(i, j)| -self.g * m[i] * m[j] / r(i, j))
            .sum()
    }

    fn is_conservative(&self) -> bool {
        true
    }

    fn name(&self) -> &str {
        "tutorial n-body gravity"
    }
}
