//! Mutual gravitation among a set of bodies (the thesis's tutorial force,
//! §4.1.2), with optional Plummer softening: every pair attracts with
//! `F = G mᵢ mⱼ d / (|d|² + ε²)^{3/2}`, equal and opposite.
//!
//! Evaluated pair by pair once (`nbody/pairs.rs`): each body adds the pull of
//! every body after it and gives that body the reaction, vectorised over
//! the others and, for large sets, in ranges of rows split among threads.
//! Each body's sum is the same bits on any thread and any CPU (see
//! `nbody/pairs.rs`); Newton's third law holds to rounding. The tutorial
//! version written outside the engine is `examples/nbody/gravity.rs`; this one is what
//! scene files get as `[[nbody]]`.

use crate::error::ModelError;
use crate::force::{Force, ForceContext, Targets};
use crate::particle::non_negative;
use glam::DVec3;

mod pairs;
use pairs::Pairs;

/// Newtonian gravity between every pair of its bodies.
#[derive(Clone, Debug)]
pub struct NBodyGravity {
    /// Gravitational constant, N m²/kg².
    pub g: f64,
    /// Softening length ε, m.
    pub softening: f64,
    targets: Targets,
    /// The bodies' indices, resolved once (and again if `All` grows).
    indices: Vec<u32>,
    scratch: Pairs,
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
            scratch: Pairs::default(),
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

    /// The ranges of rows its pairs are summed in for a set of `bodies`:
    /// each range's first row, then `bodies` (one range below 256
    /// bodies). Body `k`'s sum is its own row's, then, range by range,
    /// the reactions the rows of each range that begins before `k` give
    /// it, each range's summed from +0 in row order (`nbody/pairs.rs`):
    /// what a second implementation of the sum (the GPU's C) needs to
    /// give the same bits.
    pub fn row_ranges(bodies: usize) -> Vec<usize> {
        pairs::bounds(bodies)
    }

    /// Whether its evaluation splits over the current rayon pool's threads
    /// in a world of `n` particles.
    pub(crate) fn on_threads(&self, n: usize) -> bool {
        let bodies = if self.targets == Targets::All {
            n
        } else {
            self.indices.len()
        };
        pairs::splits(bodies) && rayon::current_num_threads() > 1
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
        let g = self.g;
        // A set that fills no more than one block of lanes is summed
        // straight from the particles into the forces (the same bits,
        // none of the kernel's copying and padding); a larger one by the
        // kernel.
        let indices = &self.indices;
        if pairs::for_small(indices, pos, mass, eps2, &mut |k, a| {
            let i = indices[k] as usize;
            forces[i] += DVec3::from_array(a) * (g * mass[i]);
        }) {
            return;
        }
        let s = &mut self.scratch;
        s.sum_small(&self.indices, pos, mass, eps2);
        for (k, &i) in self.indices.iter().enumerate() {
            let i = i as usize;
            let a = DVec3::new(s.ax[k], s.ay[k], s.az[k]);
            forces[i] += a * (self.g * mass[i]);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ParticleDef, ParticleId, World};

    /// Sets of 1 to 9 bodies, out of order, two of them at one place: what
    /// `apply` adds to each body's force is the kernel's sum (copied into
    /// padded lanes, `Pairs::load` and `Pairs::sum`) times G mᵢ, bit for
    /// bit, softened or not; the other particles' forces are untouched.
    #[test]
    fn small_sets_add_the_kernel_s_forces() {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut u = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut world = World::new();
        for _ in 0..12 {
            let def = ParticleDef::new(1.0 + u()).at(DVec3::new(u(), u(), u()));
            world.add_particle(def).expect("a valid particle");
        }
        let mut pos: Vec<DVec3> = world.state().pos.clone();
        pos[3] = pos[7];
        let vel = vec![DVec3::ZERO; pos.len()];
        let start: Vec<DVec3> = (0..pos.len()).map(|_| DVec3::new(u(), u(), u())).collect();
        let ctx = ForceContext {
            t: 0.0,
            dt: 1e-3,
            pos: &pos,
            vel: &vel,
            particles: world.particles(),
            gravity: DVec3::ZERO,
        };
        let mass = &world.particles().mass;
        for n in 1..=9 {
            for softening in [0.0, 0.03] {
                let idx = [7u32, 3, 11, 0, 5, 9, 1, 10, 4][..n].to_vec();
                let ids = idx.iter().map(|&i| ParticleId(i));
                let mut force = NBodyGravity::new(0.7, softening, Targets::only(ids));
                let mut got = start.clone();
                force.apply(&ctx, &mut got);
                let mut kernel = Pairs::default();
                kernel.load(&idx, &pos, mass);
                kernel.sum(softening * softening);
                let mut want = start.clone();
                for (k, &i) in idx.iter().enumerate() {
                    let a = DVec3::new(kernel.ax[k], kernel.ay[k], kernel.az[k]);
                    want[i as usize] += a * (0.7 * mass[i as usize]);
                }
                let bits = |f: &[DVec3]| -> Vec<[u64; 3]> {
                    f.iter().map(|v| v.to_array().map(f64::to_bits)).collect()
                };
                assert_eq!(bits(&got), bits(&want), "{n} bodies, softening {softening}");
                // (The first two are at one place.)
                if n > 2 {
                    assert_ne!(bits(&got), bits(&start), "{n} bodies pull");
                }
            }
        }
    }
}
