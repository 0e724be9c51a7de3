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
//! Every pair of the targets may touch but for the pairs a spring or joint
//! joins, given as excluded. Up to [`SWEEP_FROM`] spheres every pair is
//! tested each step; from there a sweep along x (the spheres kept sorted by
//! their lowest x, an insertion sort of last step's order) marks the pairs
//! whose boxes overlap, and only those are tested, in the same order as
//! all pairs would be: the pairs it skips are ones the test would skip, so
//! the forces, and every bit of a run, are the same either way
//! (`crates/engine/tests/soft_contact.rs` compares them).

use crate::error::ModelError;
use crate::force::{Force, ForceContext};
use crate::particle::ParticleId;
use glam::DVec3;
use std::collections::HashSet;

/// The most spheres one soft contact may test (all pairs: a million).
pub const MAX_SPHERES: usize = 1415;

/// From this many spheres a sweep finds the pairs worth testing.
pub const SWEEP_FROM: usize = 32;

/// Penalty contact among a set of spheres.
#[derive(Clone, Debug)]
pub struct SoftContact {
    /// N/m.
    pub stiffness: f64,
    /// N s/m.
    pub damping: f64,
    /// The pairs that may touch, as particle indices, in the order their
    /// forces are added.
    pairs: Vec<(u32, u32)>,
    /// The sweep, from [`SWEEP_FROM`] spheres.
    sweep: Option<Sweep>,
}

/// What the sweep keeps between steps.
#[derive(Clone, Debug)]
struct Sweep {
    /// The spheres' particle indices.
    spheres: Vec<u32>,
    /// `pair_of[i * n + j]` (i < j, positions in `spheres`): the index in
    /// `pairs` of that pair, or `u32::MAX` if it is excluded.
    pair_of: Vec<u32>,
    /// Positions in `spheres`, sorted by lowest x (last step's order).
    order: Vec<u32>,
    /// Each sphere's lowest x this step, by position in `spheres`.
    low: Vec<f64>,
    /// One bit a pair: marked by the sweep this step.
    marked: Vec<u64>,
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
        let n = spheres.len();
        let swept = n >= SWEEP_FROM;
        let mut pair_of = if swept {
            vec![u32::MAX; n * n]
        } else {
            Vec::new()
        };
        let mut pairs = Vec::new();
        for (i, &a) in spheres.iter().enumerate() {
            for (j, &b) in spheres.iter().enumerate().skip(i + 1) {
                if a != b && !skip.contains(&key(a, b)) {
                    if swept {
                        pair_of[i * n + j] = pairs.len() as u32;
                    }
                    pairs.push((a.index() as u32, b.index() as u32));
                }
            }
        }
        let sweep = swept.then(|| Sweep {
            spheres: spheres.iter().map(|p| p.index() as u32).collect(),
            pair_of,
            order: (0..n as u32).collect(),
            low: vec![0.0; n],
            marked: vec![0; pairs.len().div_ceil(64)],
        });
        Ok(SoftContact {
            stiffness,
            damping,
            pairs,
            sweep,
        })
    }

    /// The pairs that may touch (all but the excluded).
    pub fn pairs(&self) -> usize {
        self.pairs.len()
    }

    /// Those pairs as particle indices, in the order their forces are
    /// added.
    pub fn pair_list(&self) -> &[(u32, u32)] {
        &self.pairs
    }

    /// The same contact testing every pair every step, however many
    /// spheres (the sweep's reference: the forces are the same to the bit).
    pub fn every_pair(mut self) -> SoftContact {
        self.sweep = None;
        self
    }

    /// True if a sweep picks the pairs to test.
    pub fn sweeps(&self) -> bool {
        self.sweep.is_some()
    }
}

impl SoftContact {
    /// The force of pair `(a, b)` on both, if they overlap.
    ///
    /// Most pairs are apart: a pair with `d² > s²` (both rounded) returns
    /// before the square root. That skips only pairs the full test skips:
    /// `s²` rounded to nearest has no float between it and the exact `s²`,
    /// so `d² > fl(s²)` means `d² ≥ s²`, `√d² ≥ s`, and `s − |d|` rounds
    /// to ≤ 0 (a NaN or an overflowed `s²` fails the test), so every bit
    /// is as without it.
    #[inline(always)]
    fn pair(&self, (a, b): (u32, u32), ctx: &ForceContext, forces: &mut [DVec3]) {
        let r = &ctx.particles.radius;
        let (a, b) = (a as usize, b as usize);
        let d = ctx.pos[b] - ctx.pos[a];
        let reach = r[a] + r[b];
        // (glam's `length` is `dot(self, self).sqrt()`: the same d².)
        let d2 = d.dot(d);
        if d2 > reach * reach {
            return;
        }
        let dist = d2.sqrt();
        let overlap = reach - dist;
        if overlap <= 0.0 || dist <= 0.0 {
            return;
        }
        let n = d / dist;
        let separating = (ctx.vel[b] - ctx.vel[a]).dot(n);
        let push = (self.stiffness * overlap - self.damping * separating).max(0.0);
        forces[a] -= n * push;
        forces[b] += n * push;
    }
}

impl Sweep {
    /// Marks every pair whose boxes overlap (with a margin, and any pair
    /// with a coordinate that is not a number): a superset of the pairs
    /// that touch.
    fn mark(&mut self, ctx: &ForceContext) {
        let r = &ctx.particles.radius;
        let n = self.spheres.len();
        for (k, &p) in self.spheres.iter().enumerate() {
            let p = p as usize;
            self.low[k] = ctx.pos[p].x - r[p];
        }
        // Insertion sort from last step's order: nearly sorted, so about
        // linear. Not-a-number sorts last and is swept with everything.
        let low = &self.low;
        let before = |x: f64, y: f64| x < y || (y.is_nan() && !x.is_nan());
        for i in 1..n {
            let mut j = i;
            while j > 0 && before(low[self.order[j] as usize], low[self.order[j - 1] as usize]) {
                self.order.swap(j, j - 1);
                j -= 1;
            }
        }
        const MARGIN: f64 = 1.0 + 1e-9;
        for (at, &i) in self.order.iter().enumerate() {
            let i = i as usize;
            let a = self.spheres[i] as usize;
            let (pa, ra) = (ctx.pos[a], r[a]);
            // The margin covers rounding in `low` and `high` too.
            let high = pa.x + ra * MARGIN + 1e-12 * (1.0 + pa.x.abs());
            for &j in &self.order[at + 1..] {
                let j = j as usize;
                let b = self.spheres[j] as usize;
                // Sorted by lowest x: none further on reaches back to `a`.
                if low[j] > high {
                    break;
                }
                let reach = (ra + r[b]) * MARGIN;
                let d = ctx.pos[b] - pa;
                if d.y.abs() > reach || d.z.abs() > reach {
                    continue;
                }
                let (lo, hi) = (i.min(j), i.max(j));
                let pair = self.pair_of[lo * n + hi];
                if pair != u32::MAX {
                    self.marked[pair as usize / 64] |= 1 << (pair % 64);
                }
            }
        }
    }
}

impl Force for SoftContact {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        let Some(mut sweep) = self.sweep.take() else {
            for k in 0..self.pairs.len() {
                self.pair(self.pairs[k], ctx, forces);
            }
            return;
        };
        sweep.mark(ctx);
        // The marked pairs in the order of `pairs`, each mark cleared.
        for w in 0..sweep.marked.len() {
            let mut bits = std::mem::take(&mut sweep.marked[w]);
            while bits != 0 {
                let k = w * 64 + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                self.pair(self.pairs[k], ctx, forces);
            }
        }
        self.sweep = Some(sweep);
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

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::particle::Properties;

    /// The pair's force as written before the early return: every pair's
    /// square root taken.
    fn reference(k: f64, c: f64, r: [f64; 2], pos: [DVec3; 2], vel: [DVec3; 2]) -> [DVec3; 2] {
        let d = pos[1] - pos[0];
        let dist = d.length();
        let overlap = r[0] + r[1] - dist;
        if overlap <= 0.0 || dist <= 0.0 {
            return [DVec3::ZERO; 2];
        }
        let n = d / dist;
        let push = (k * overlap - c * (vel[1] - vel[0]).dot(n)).max(0.0);
        [DVec3::ZERO - n * push, DVec3::ZERO + n * push]
    }

    fn bits(v: [DVec3; 2]) -> [u64; 6] {
        [v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z].map(f64::to_bits)
    }

    /// Spheres at, just inside and just outside touching (a few ulps and a
    /// few millionths either way), far apart, at one place, tiny (squares
    /// below the normal floats) and huge radii, and a NaN: the same force
    /// bits as the reference, and many pairs of each kind (touching or not)
    /// among them. A bound one ulp lower (`>=`) fails it.
    #[test]
    fn skipping_the_square_root_of_pairs_apart_changes_no_bit() {
        let contact = SoftContact {
            stiffness: 3000.0,
            damping: 4.0,
            pairs: vec![(0, 1)],
            sweep: None,
        };
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut touching, mut apart) = (0, 0);
        for case in 0..200_000 {
            let scale = [1e-3, 1.0, 1e3, 1e-150, 1e150, 2e-161][case % 6];
            let r = [scale * (0.01 + uniform()), scale * (0.01 + uniform())];
            let dir = DVec3::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5).normalize();
            let mut dist = (r[0] + r[1])
                * match case % 4 {
                    0 => 1.0 + (uniform() - 0.5) * 4e-6,
                    1 => 1.0 + (uniform() - 0.5) * 1e-14,
                    2 => 3.0 * uniform(),
                    _ => 1.0,
                };
            if case % 7 == 0 {
                // Step the distance by ulps across the bound.
                let ulps = (uniform() * 64.0) as i64 - 32;
                dist = f64::from_bits((dist.to_bits() as i64 + ulps) as u64);
            }
            let p0 = DVec3::new(uniform(), uniform(), uniform()) * scale;
            let mut pos = [p0, p0 + dir * dist];
            if case % 1000 == 3 {
                pos[1] = pos[0];
            }
            if case % 1000 == 5 {
                pos[1].y = f64::NAN;
            }
            let vel = [
                DVec3::new(uniform(), -uniform(), 0.5),
                DVec3::new(-uniform(), 0.0, uniform()),
            ];
            let particles = Properties {
                radius: r.to_vec(),
                ..Properties::default()
            };
            let ctx = ForceContext {
                t: 0.0,
                dt: 1e-3,
                pos: &pos,
                vel: &vel,
                particles: &particles,
                gravity: DVec3::ZERO,
            };
            let mut forces = [DVec3::ZERO; 2];
            contact.pair((0, 1), &ctx, &mut forces);
            let want = reference(3000.0, 4.0, r, pos, vel);
            assert_eq!(
                bits(forces),
                bits(want),
                "case {case}: r {r:?}, pos {pos:?}"
            );
            if want[0] != DVec3::ZERO {
                touching += 1;
            } else {
                apart += 1;
            }
        }
        assert!(
            touching > 30_000 && apart > 30_000,
            "{touching} touching, {apart} apart"
        );
    }
}
