//! The floor's forces (thesis §3.1.2.7): normal reaction and friction for
//! particles resting on the plane y = 0. Collisions with the floor are a
//! discrete event, in `events/floor_collision.rs`.
//!
//! A particle is in contact when (the thesis's three conditions) it touches the
//! plane (its lowest point is within `contact_tolerance` of it), it is not
//! moving towards or away from it (not moving up at all, nor down faster
//! than `rest_speed`), and it is forced towards it (the net force of every
//! other force points down). A slow rebound is not resting: holding it up
//! for a step would feed the bounce.
//! Then the floor pushes back with `N = -F_y`, and
//! - below `static_speed` of sliding, static friction cancels the tangential
//!   force and the residual slip, up to `mu_s |N|`; past that limit, kinetic
//!   friction `mu_k |N|` opposes the slip that the force would produce;
//! - otherwise kinetic friction `mu_k |N|` opposes the sliding, capped so that
//!   it never reverses the sliding velocity within one step.
//!
//! This force reads the accumulated net force, so it runs in the
//! [`Stage::Contact`] stage, after every ordinary force.
//!
//! On other terrain ([`Terrain`]) "up" is the surface's outward normal at
//! the point nearest the sphere: the normal reaction cancels the net
//! force's component into the surface (and any residual normal speed
//! within 1 µm/s of zero, which rounding leaves on a tilted surface), and
//! friction acts in the tangent plane.

use crate::error::ModelError;
use crate::force::{Force, ForceContext, Stage, Targets};
use crate::particle::non_negative;
use crate::terrain::Terrain;
use glam::DVec3;
use std::sync::Arc;

/// On terrain, a normal speed within this of zero (m/s) is rounding: the
/// sphere is neither leaving nor hitting the surface.
const ROUNDING_SPEED: f64 = 1e-6;

/// Normal reaction and friction of the plane y = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct FloorContact {
    /// Sliding slower than this (m/s) is held by static friction.
    pub static_speed: f64,
    /// A particle moving towards or away from the plane faster than this (m/s)
    /// is not resting on it.
    pub rest_speed: f64,
    /// How close (m) the lowest point must be to the plane to touch it.
    pub contact_tolerance: f64,
    /// The particles the floor supports.
    pub targets: Targets,
    /// The ground's shape.
    pub terrain: Arc<Terrain>,
}

impl Default for FloorContact {
    fn default() -> Self {
        FloorContact {
            static_speed: 0.01,
            rest_speed: 0.05,
            contact_tolerance: 1e-6,
            targets: Targets::All,
            terrain: Arc::new(Terrain::Flat),
        }
    }
}

impl FloorContact {
    /// Checks the thresholds.
    pub fn validate(&self) -> Result<(), ModelError> {
        non_negative("static_speed", self.static_speed)?;
        non_negative("rest_speed", self.rest_speed)?;
        non_negative("contact_tolerance", self.contact_tolerance)?;
        Ok(())
    }

    /// On the plane y = 0. Always inlined into the loop over particles, so
    /// that `f` stays in registers (about 1 % of a roobot evaluation); the
    /// loop is chosen once per evaluation, flat or terrain.
    #[inline(always)]
    fn contact(&self, ctx: &ForceContext, i: usize, f: &mut DVec3) {
        let p = &ctx.particles;
        if p.inv_mass[i] == 0.0 || ctx.pos[i].y - p.radius[i] > self.contact_tolerance {
            return;
        }
        let v = ctx.vel[i];
        // Leaving the plane (a rebound, however slow) or hitting it: not
        // resting. A resting sphere's normal velocity is exactly zero: the
        // collision event sets it so, and this force keeps it so.
        if v.y > 0.0 || v.y < -self.rest_speed || f.y >= 0.0 {
            return;
        }
        let normal = -f.y;
        f.y = 0.0;
        let vt = DVec3::new(v.x, 0.0, v.z);
        let ft = DVec3::new(f.x, 0.0, f.z);
        *f += self.friction(ctx, i, vt, ft, normal);
    }
}

impl FloorContact {
    /// [`FloorContact::contact`] on terrain other than the plane y = 0:
    /// the same, along the surface's normal.
    #[inline(never)]
    fn on_terrain(&self, ctx: &ForceContext, i: usize, f: &mut DVec3) {
        let p = &ctx.particles;
        if p.inv_mass[i] == 0.0 {
            return;
        }
        let reach = p.radius[i] + self.contact_tolerance;
        let Some((d, n)) = self.terrain.probe(ctx.pos[i], reach) else {
            return;
        };
        if d - p.radius[i] > self.contact_tolerance {
            return;
        }
        let v = ctx.vel[i];
        let (vn, fn_) = (v.dot(n), f.dot(n));
        if vn > ROUNDING_SPEED || vn < -self.rest_speed || fn_ >= 0.0 {
            return;
        }
        let m = p.mass[i];
        // Cancel the push into the surface, and the residual normal speed.
        let normal = -fn_;
        let ft = *f - n * fn_;
        // Rounding's normal speed is cancelled too; a real approach is the
        // collision's to resolve.
        let residual = if vn.abs() <= ROUNDING_SPEED { vn } else { 0.0 };
        *f = ft - n * (residual * m / ctx.dt);
        let vt = v - n * vn;
        *f += self.friction(ctx, i, vt, ft, normal);
    }

    /// The friction on resting sphere `i` sliding at `vt` under the
    /// tangential force `ft`, pressed with `normal` (thesis §3.1.2.7):
    /// below `static_speed` static friction holds it (cancels the applied
    /// tangential force and the residual slip) up to `μs N`, and past that
    /// kinetic friction `μk N` opposes the slip the applied force produces
    /// (the direction of the hold, not a residual velocity that may be
    /// roundoff); otherwise kinetic friction against the sliding, capped
    /// so that it never reverses the sliding within one step.
    #[inline(always)]
    fn friction(&self, ctx: &ForceContext, i: usize, vt: DVec3, ft: DVec3, normal: f64) -> DVec3 {
        let p = &ctx.particles;
        let m = p.mass[i];
        let speed = vt.length();
        if speed < self.static_speed {
            let hold = -ft - vt * (m / ctx.dt);
            let needed = hold.length();
            if needed <= p.mu_s[i] * normal {
                return hold;
            }
            return hold * ((p.mu_k[i] * normal).min(needed) / needed);
        }
        let dir = vt / speed;
        let stop = m * speed / ctx.dt + ft.dot(dir); // friction that would just stop it
        let kinetic = (p.mu_k[i] * normal).min(stop.max(0.0));
        -(dir * kinetic)
    }

    /// [`Force::apply`], split like the world's per-particle loops when
    /// `split` (a large world's particles on many threads): each particle's
    /// contact is its own, so the pieces give the same bits, and each
    /// thread reads the particles it has just summed forces for.
    pub(crate) fn apply_split(&self, ctx: &ForceContext, forces: &mut [DVec3], split: bool) {
        if self.targets != Targets::All || !split {
            return self.apply_all(ctx, forces);
        }
        let flat = self.terrain.is_flat();
        // (A loop for each ground, not a test of it for each particle: the
        // flat floor's loop is the commonest, and tight.)
        crate::parallel::by_pieces(true, [forces], |first, [piece]| {
            if flat {
                for (k, f) in piece.iter_mut().enumerate() {
                    self.contact(ctx, first + k, f);
                }
            } else {
                for (k, f) in piece.iter_mut().enumerate() {
                    self.on_terrain(ctx, first + k, f);
                }
            }
        });
    }

    fn apply_all(&self, ctx: &ForceContext, forces: &mut [DVec3]) {
        if self.terrain.is_flat() {
            self.each(forces, |i, f| self.contact(ctx, i, f));
        } else {
            self.each(forces, |i, f| self.on_terrain(ctx, i, f));
        }
    }

    /// `one` on each target's force.
    #[inline(always)]
    fn each(&self, forces: &mut [DVec3], mut one: impl FnMut(usize, &mut DVec3)) {
        match &self.targets {
            Targets::All => {
                for (i, f) in forces.iter_mut().enumerate() {
                    one(i, f);
                }
            }
            Targets::Only(ids) => {
                for id in ids {
                    one(id.index(), &mut forces[id.index()]);
                }
            }
        }
    }
}

impl Force for FloorContact {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        self.apply_all(ctx, forces);
    }

    fn stage(&self) -> Stage {
        Stage::Contact
    }

    fn is_passive(&self) -> bool {
        true // the normal reaction does no work; friction removes energy
    }

    fn name(&self) -> &str {
        "floor contact"
    }
}
