//! Penalty contact between spheres: two spheres that overlap by `δ` push
//! each other apart along their line of centres with
//! `F = k δ − c u_n` (never pulling: `F ≥ 0`), `u_n` the rate at which
//! their centres separate. The elastic part is the force of the
//! potential `½ k δ²`, so a body made of springs and soft contacts keeps its
//! energy under a symplectic integrator, as its springs alone do; the
//! damping only takes energy away.
//!
//! Why a force and not the event ([`crate::SphereContact`]): the event
//! removes an overlap by moving the spheres apart, a displacement no force
//! pays for. A soft body whose muscles press two of its spheres together
//! gets that displacement every step, stored in its springs and released:
//! evolution found it at once (a body pumped itself to 28 m/s; the same
//! body without contacts went nowhere; docs/BODIES.md). A force does only
//! the work its potential gives back.
//!
//! Every pair of the targets is tested (the bodies it is meant for have
//! tens of spheres), but for the pairs a spring or joint joins, given as
//! excluded.

use crate::error::ModelError;
use crate::force::{Force, ForceContext};
use crate::particle::ParticleId;
use glam::DVec3;
use std::collections::HashSet;

/// The most spheres one soft contact may test (all pairs: a million).
pub const MAX_SPHERES: usize = 1415;

/// Penalty contact among a set of spheres.
#[derive(Clone, Debug)]
pub struct SoftContact {
    /// N/m.
    pub stiffness: f64,
    /// N s/m.
    pub damping: f64,
    /// The pairs tested, as particle indices.
    pairs: Vec<(u32, u32)>,
}

impl SoftContact {
    /// Contact among `spheres` (each once) but for the `excluded` pairs.
    pub fn new(
        stiffness: f64,
        damping: f64,
        spheres: &[ParticleId],
        excluded: &[(ParticleId, ParticleId)],
    ) -> Result<SoftContact, ModelError> {
        if !(stiffness.is_finite() && stiffness > 0.0) {
            return Err(ModelError::new(
                "stiffness",
                format!("must be > 0, got {stiffness}"),
            ));
        }
        if !(damping.is_finite() && damping >= 0.0) {
            return Err(ModelError::new(
                "damping",
                format!("must be >= 0, got {damping}"),
            ));
        }
        if spheres.len() > MAX_SPHERES {
            return Err(ModelError::new(
                "particles",
                format!(
                    "{} spheres: soft contact tests every pair, at most {MAX_SPHERES} spheres",
                    spheres.len()
                ),
            ));
        }
        let key =
            |a: ParticleId, b: ParticleId| (a.index().min(b.index()), a.index().max(b.index()));
        let skip: HashSet<(usize, usize)> = excluded.iter().map(|&(a, b)| key(a, b)).collect();
        let mut pairs = Vec::new();
        for (i, &a) in spheres.iter().enumerate() {
            for &b in &spheres[i + 1..] {
                if a != b && !skip.contains(&key(a, b)) {
                    pairs.push((a.index() as u32, b.index() as u32));
                }
            }
        }
        Ok(SoftContact {
            stiffness,
            damping,
            pairs,
        })
    }

    /// The pairs tested.
    pub fn pairs(&self) -> usize {
        self.pairs.len()
    }
}

impl Force for SoftContact {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        let r = &ctx.particles.radius;
        for &(a, b) in &self.pairs {
            let (a, b) = (a as usize, b as usize);
            let d = ctx.pos[b] - ctx.pos[a];
            let dist = d.length();
            let overlap = r[a] + r[b] - dist;
            if overlap <= 0.0 || dist <= 0.0 {
                continue;
            }
            let n = d / dist;
            let separating = (ctx.vel[b] - ctx.vel[a]).dot(n);
            let push = (self.stiffness * overlap - self.damping * separating).max(0.0);
            forces[a] -= n * push;
            forces[b] += n * push;
        }
    }

    fn potential_energy(&self, ctx: &ForceContext) -> f64 {
        let r = &ctx.particles.radius;
        self.pairs
            .iter()
            .map(|&(a, b)| {
                let (a, b) = (a as usize, b as usize);
                let overlap = (r[a] + r[b] - (ctx.pos[b] - ctx.pos[a]).length()).max(0.0);
                0.5 * self.stiffness * overlap * overlap
            })
            .sum()
    }

    fn is_passive(&self) -> bool {
        true
    }

    fn name(&self) -> &str {
        "soft contact"
    }
}
