//! Collision of spheres with the floor, the plane y = 0 (thesis §3.1.3.1).
//!
//! After a trial step, a sphere whose lowest point is below the plane is
//! `Occurring`; one more than `envelope` below it was `Missed` (it hit the
//! plane somewhere inside the step and the step must be retaken in shorter
//! pieces). Handling moves the sphere up to touch the plane and, if it is
//! moving into the plane, reflects its normal velocity with its restitution,
//! `v_y ← -r v_y` (Eq. 16).
//!
//! Two refinements of the thesis's response keep an impact from adding
//! energy and let a bouncing sphere come to rest (docs/DESIGN.md, "The
//! floor"):
//! - The velocity reflected is the one the sphere had *at the plane*, not
//!   at the end of the trial, which includes the acceleration of the part of
//!   the step spent below the plane. Under the trial's mean normal
//!   acceleration `a` (from its start and end velocities), a sphere `d` below
//!   the plane moving at `v` crossed it at `v_c² = v² + 2 a d`. Moving the
//!   sphere up by `d` then costs exactly the energy that `v → v_c` returns,
//!   so with `r ≤ 1` the impact never adds mechanical energy (`r = 1`
//!   conserves it under a constant force).
//! - Explicit Euler gains ½ a² h² of kinetic energy in every step of free
//!   flight, which would feed each bounce and keep a small one going for
//!   ever; the rebound is also computed from the velocity its flight
//!   conserves ([`IntegratorKind::free_flight_shift`](crate::IntegratorKind::free_flight_shift)) and the smaller of the
//!   two is used, so that neither energy rises.
//! - A rebound too slow to leave the plane for a whole step (flight time
//!   `2 r v_c / |a|` at most the step) cannot be resolved at this step size,
//!   and neither can an impact slower than `rest_speed`: the sphere rests,
//!   and the floor's contact force holds it. The rebound speeds fall
//!   geometrically, so the bounces end after finitely many impacts.
//!
//! A sphere below the plane but already moving up is moved up with the
//! speed it would have at the plane.
//!
//! On other terrain ([`Terrain`]) all of this happens along the surface's
//! outward normal at the point nearest the sphere's centre: the sphere is
//! moved out along it, and the velocity's component along it is the one
//! resolved; the tangential velocity is kept.

use crate::error::ModelError;
use crate::event::{ByPieces, DiscreteEvent, EventContext, EventState, TrialPiece};
use crate::force::Targets;
use crate::particle::{non_negative, ParticleId, Properties};
use crate::terrain::Terrain;
use glam::DVec3;
use std::ops::Range;
use std::sync::Arc;
use std::sync::{Mutex, MutexGuard};

/// One bounce recorded during the last step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Collision {
    /// Which sphere.
    pub particle: ParticleId,
    /// When, s.
    pub t: f64,
    /// Its speed into the plane just before the impact, m/s.
    pub impact_speed: f64,
}

/// The floor's collision event.
#[derive(Clone, Debug, PartialEq)]
pub struct FloorCollision {
    /// Penetration (m) beyond which the collision counts as missed.
    pub envelope: f64,
    /// Impacts slower than this (m/s) do not bounce.
    pub rest_speed: f64,
    /// The particles that collide with the floor.
    pub targets: Targets,
    /// The ground's shape (the plane y = 0 unless set).
    terrain: Arc<Terrain>,
    hits: Vec<Hit>,
    /// The step of the last check's trial, s, and the integrator's
    /// free-flight shift: the same for every hit.
    step: f64,
    /// The world's gravity at the last check, m/s².
    gravity: DVec3,
    shift: f64,
    collisions: Vec<Collision>,
    /// The bounces of the pieces of a trial settled on many threads, until
    /// the world says whether it keeps the trial.
    pending: Pending,
}

/// Bounces behind a lock (the pieces of a trial settle at once); a copy of
/// the event copies them, and events compare equal with equal ones.
#[derive(Default)]
struct Pending(Mutex<Vec<Collision>>);

impl Pending {
    /// The bounces (a thread that panicked holding the lock left whole
    /// records: each is pushed whole).
    fn lock(&self) -> MutexGuard<'_, Vec<Collision>> {
        self.0
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// The bounces, to a holder of the only reference: no lock taken (a
    /// lock and an unlock are two atomic exchanges: taken at the end of
    /// every step, about 4 % of a land run of random bodies).
    fn get_mut(&mut self) -> &mut Vec<Collision> {
        self.0
            .get_mut()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

impl Clone for Pending {
    fn clone(&self) -> Self {
        Pending(Mutex::new(self.lock().clone()))
    }
}

impl PartialEq for Pending {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other) || *self.lock() == *other.lock()
    }
}

impl std::fmt::Debug for Pending {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.lock().fmt(f)
    }
}

/// A sphere found below the plane by the last check.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Hit {
    index: u32,
    /// The trial's mean acceleration along the normal, m/s².
    accel: f64,
    /// The surface's outward normal (`+y` on the flat floor).
    normal: DVec3,
    /// The gap between the sphere and the surface, < 0 (used on terrain;
    /// the flat floor reads it from the position).
    gap: f64,
}

impl Default for FloorCollision {
    fn default() -> Self {
        FloorCollision::new(0.01, 0.05, Targets::All)
    }
}

impl FloorCollision {
    /// A floor with the given envelope and resting speed.
    pub fn new(envelope: f64, rest_speed: f64, targets: Targets) -> Self {
        FloorCollision {
            envelope,
            rest_speed,
            targets,
            terrain: Arc::new(Terrain::Flat),
            hits: Vec::new(),
            step: 0.0,
            gravity: DVec3::ZERO,
            shift: 0.0,
            collisions: Vec::new(),
            pending: Pending::default(),
        }
    }

    /// The same floor shaped as `terrain`.
    pub fn with_terrain(mut self, terrain: Arc<Terrain>) -> Self {
        self.terrain = terrain;
        self
    }

    /// The ground's shape.
    pub fn terrain(&self) -> &Terrain {
        &self.terrain
    }

    /// The ground's shape, shared (the floor's contact force holds the same).
    pub fn shared_terrain(&self) -> &Arc<Terrain> {
        &self.terrain
    }

    /// Checks the thresholds (an infinite envelope never backtracks).
    pub fn validate(&self) -> Result<(), ModelError> {
        if self.envelope.is_nan() || self.envelope < 0.0 {
            return Err(ModelError::new(
                "envelope",
                format!("must be >= 0, got {}", self.envelope),
            ));
        }
        non_negative("rest_speed", self.rest_speed)?;
        Ok(())
    }

    /// What a trial's deepest moving sphere below the plane (its gap, if
    /// there is one) makes of this event.
    fn state(&self, deepest: Option<f64>) -> EventState {
        match deepest {
            None => EventState::None,
            Some(d) if d < -self.envelope => EventState::Missed,
            Some(_) => EventState::Occurring,
        }
    }

    /// Moves the sphere of `hit` (at `x`, moving at `v`) up to the plane
    /// (out of the terrain along its normal) and resolves its impact, for a
    /// trial of the step `step` ending at `t`, `shift` the integrator's
    /// free-flight shift times the hit's acceleration and the step; the
    /// bounce, if it moved into the plane.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn resolve(
        &self,
        hit: Hit,
        step: f64,
        shift: f64,
        t: f64,
        gravity: DVec3,
        x: &mut DVec3,
        v: &mut DVec3,
        particles: &Properties,
    ) -> Option<Collision> {
        let i = hit.index as usize;
        let e = particles.restitution[i];
        if self.terrain.is_flat() {
            let depth = particles.radius[i] - x.y;
            x.y = particles.radius[i];
            let (vy, impact) = self.normal_speed(v.y, hit.accel, depth, step, shift, e);
            v.y = vy;
            return impact.map(|impact_speed| Collision {
                particle: ParticleId(i as u32),
                t,
                impact_speed,
            });
        }
        let (n, depth) = (hit.normal, -hit.gap);
        *x += n * depth;
        let vn = v.dot(n);
        let (after, impact) = self.normal_speed(vn, hit.accel, depth, step, shift, e);
        *v += n * (after - vn);
        // Moved out further than its normal speed could have carried it
        // against gravity (a sphere sliding into a crease of the ground,
        // onto a steeper face, while the contact force of the face it left
        // held it up): the climb is paid from the sliding speed, so that
        // the move never adds energy.
        let climb = -2.0 * gravity.dot(n) * depth;
        let excess = after * after - vn * vn + climb;
        if excess > 0.0 {
            let slide = *v - n * after;
            let slide2 = slide.length_squared();
            if slide2 > 0.0 {
                *v -= slide * (1.0 - ((slide2 - excess).max(0.0) / slide2).sqrt());
            }
        }
        impact.map(|impact_speed| Collision {
            particle: ParticleId(i as u32),
            t,
            impact_speed,
        })
    }

    /// The normal speed after moving a sphere `depth` out of the plane,
    /// which moved along its normal at `vn` under the trial's mean normal
    /// acceleration `a`, with restitution `e`; and its impact speed, if it
    /// was moving into the plane.
    #[inline]
    fn normal_speed(
        &self,
        vn: f64,
        a: f64,
        depth: f64,
        step: f64,
        shift: f64,
        e: f64,
    ) -> (f64, Option<f64>) {
        // The normal speed at the plane under the trial's mean
        // acceleration; below zero the sphere could not have got this
        // deep this fast, and it is simply put on the plane.
        let at_plane = (vn * vn + 2.0 * a * depth).max(0.0).sqrt();
        if vn >= 0.0 {
            return (at_plane, None);
        }
        // The rebound, in the plain velocity and in the one the
        // integrator's free flight conserves (`w = v + s a h`); the
        // smaller raises neither energy. For explicit Euler the second is
        // smaller: it keeps the ½ a² h² that each step of flight gains
        // out of the next bounce, without which a bounce never ends.
        let w = vn + shift;
        let w_at_plane = (w * w + 2.0 * a * depth).max(0.0).sqrt();
        let rebound = (e * at_plane).min(e * w_at_plane - shift);
        // A rebound that cannot keep the sphere off the plane for a
        // whole step is not resolvable at this step: it rests.
        let flight = if a < 0.0 {
            2.0 * rebound / -a
        } else {
            f64::INFINITY
        };
        let after = if at_plane < self.rest_speed || flight <= step {
            0.0
        } else {
            rebound
        };
        (after, Some(at_plane))
    }

    /// Sphere `i` at `x` under the terrain: its gap (< 0) and the
    /// surface's outward normal.
    #[inline]
    fn under_terrain(&self, x: DVec3, radius: f64) -> Option<(f64, DVec3)> {
        let (d, n) = self.terrain.probe(x, radius)?;
        let gap = d - radius;
        (gap < 0.0).then_some((gap, n))
    }

    /// The bounces of the last step.
    pub fn collisions(&self) -> &[Collision] {
        &self.collisions
    }
}

/// As `check` finds it: the gap of the deepest moving sphere below the
/// plane (radii `radius`, inverse masses `inv_mass`), if any is.
///
/// Without branches, in four lanes: which feet are down changes from step
/// to step, and a branch on it was mispredicted. (The least of a set of
/// numbers is the same in any order.)
fn deepest(pos: &[DVec3], radius: &[f64], inv_mass: &[f64]) -> Option<f64> {
    #[inline(always)]
    fn below(x: &DVec3, r: f64, w: f64, deepest: f64) -> f64 {
        let gap = x.y - r;
        // A NaN gap, or a pinned sphere, is none.
        let gap = if gap < 0.0 && w != 0.0 { gap } else { 0.0 };
        if gap < deepest {
            gap
        } else {
            deepest
        }
    }
    let n = pos.len().min(radius.len()).min(inv_mass.len());
    let (pos, radius, inv_mass) = (&pos[..n], &radius[..n], &inv_mass[..n]);
    let mut lanes = [0.0f64; 4];
    let whole = n - n % 4;
    for i in (0..whole).step_by(4) {
        for k in 0..4 {
            lanes[k] = below(&pos[i + k], radius[i + k], inv_mass[i + k], lanes[k]);
        }
    }
    // The rest apart from the lanes (as `all_finite` does, so that they
    // stay in registers).
    let mut rest = 0.0f64;
    for i in whole..n {
        rest = below(&pos[i], radius[i], inv_mass[i], rest);
    }
    let deepest = lanes.iter().fold(rest, |d, &l| if l < d { l } else { d });
    (deepest < 0.0).then_some(deepest)
}

impl FloorCollision {
    /// [`deepest`] on this floor's terrain.
    fn deepest(&self, pos: &[DVec3], radius: &[f64], inv_mass: &[f64]) -> Option<f64> {
        if self.terrain.is_flat() {
            return deepest(pos, radius, inv_mass);
        }
        let mut deepest = 0.0f64;
        for ((x, &r), &w) in pos.iter().zip(radius).zip(inv_mass) {
            if w != 0.0 {
                if let Some((gap, _)) = self.under_terrain(*x, r) {
                    deepest = deepest.min(gap);
                }
            }
        }
        (deepest < 0.0).then_some(deepest)
    }

    /// `check` on terrain other than the plane y = 0.
    fn check_terrain(&mut self, ctx: &EventContext) -> EventState {
        let (pos, p) = (ctx.pos, ctx.particles);
        let mut deepest = 0.0f64;
        let mut hits = std::mem::take(&mut self.hits);
        let mut hit = |i: usize| {
            if p.inv_mass[i] == 0.0 {
                return;
            }
            if let Some((gap, normal)) = self.under_terrain(pos[i], p.radius[i]) {
                hits.push(Hit {
                    index: i as u32,
                    accel: (ctx.vel[i] - ctx.start_vel[i]).dot(normal) / ctx.h,
                    normal,
                    gap,
                });
                deepest = deepest.min(gap);
            }
        };
        match &self.targets {
            Targets::All => (0..pos.len()).for_each(&mut hit),
            Targets::Only(ids) => ids.iter().for_each(|id| hit(id.index())),
        }
        self.hits = hits;
        self.state((!self.hits.is_empty()).then_some(deepest))
    }
}

impl DiscreteEvent for FloorCollision {
    fn check(&mut self, ctx: &EventContext) -> EventState {
        self.hits.clear();
        (self.step, self.shift, self.gravity) = (ctx.step, ctx.flight_shift, ctx.gravity);
        if !self.terrain.is_flat() {
            return self.check_terrain(ctx);
        }
        let (pos, p) = (ctx.pos, ctx.particles);
        // The deepest penetration among the spheres below the plane.
        let mut deepest = 0.0f64;
        let mut hit = |i: usize, gap: f64| {
            if p.inv_mass[i] != 0.0 {
                self.hits.push(Hit {
                    index: i as u32,
                    accel: (ctx.vel[i].y - ctx.start_vel[i].y) / ctx.h,
                    normal: DVec3::Y,
                    gap,
                });
                deepest = deepest.min(gap);
            }
        };
        match &self.targets {
            Targets::All => {
                for (i, (x, r)) in pos.iter().zip(&p.radius).enumerate() {
                    let gap = x.y - r;
                    if gap < 0.0 {
                        hit(i, gap);
                    }
                }
            }
            Targets::Only(ids) => {
                for id in ids {
                    let i = id.index();
                    let gap = pos[i].y - p.radius[i];
                    if gap < 0.0 {
                        hit(i, gap);
                    }
                }
            }
        }
        self.state((!self.hits.is_empty()).then_some(deepest))
    }

    fn handle(&mut self, t: f64, pos: &mut [DVec3], vel: &mut [DVec3], particles: &Properties) {
        for k in 0..self.hits.len() {
            let hit = self.hits[k];
            let i = hit.index as usize;
            let shift = self.shift * hit.accel * self.step;
            if let Some(c) = self.resolve(
                hit,
                self.step,
                shift,
                t,
                self.gravity,
                &mut pos[i],
                &mut vel[i],
                particles,
            ) {
                self.collisions.push(c);
            }
        }
    }

    fn begin_step(&mut self) {
        self.collisions.clear();
    }

    fn is_passive(&self) -> bool {
        true // an impact never adds energy (module documentation)
    }

    fn name(&self) -> &str {
        "floor collision"
    }

    fn by_pieces(&self) -> Option<&dyn ByPieces> {
        Some(self)
    }

    fn by_pieces_mut(&mut self) -> Option<&mut dyn ByPieces> {
        Some(self)
    }
}

/// Each sphere meets the floor on its own: a large world checks, handles
/// and settles it piece by piece.
impl ByPieces for FloorCollision {
    fn check_piece(&self, ctx: &EventContext, range: Range<usize>) -> Option<EventState> {
        if self.targets != Targets::All {
            return None;
        }
        let p = ctx.particles;
        let (r, w) = (&p.radius[range.clone()], &p.inv_mass[range.clone()]);
        Some(self.state(self.deepest(&ctx.pos[range], r, w)))
    }

    fn settles_pieces(&self) -> bool {
        self.targets == Targets::All
    }

    fn settle_piece(&self, piece: &mut TrialPiece) -> EventState {
        let p = piece.particles;
        let r = piece.first..piece.first + piece.pos.len();
        let (radius, inv_mass) = (&p.radius[r.clone()], &p.inv_mass[r]);
        // Read only first: most pieces of most steps have nothing below.
        let state = self.state(self.deepest(piece.pos, radius, inv_mass));
        if state == EventState::None || (state == EventState::Missed && !piece.finest) {
            return state;
        }
        // As `handle`, for the spheres `check` would have recorded.
        let mut bounces = Vec::new();
        for k in 0..piece.pos.len() {
            // A hit as in `check` (a NaN gap is none).
            if inv_mass[k] == 0.0 {
                continue;
            }
            let (gap, normal) = if self.terrain.is_flat() {
                (piece.pos[k].y - radius[k], DVec3::Y)
            } else {
                match self.under_terrain(piece.pos[k], radius[k]) {
                    Some(below) => below,
                    None => continue,
                }
            };
            if gap.is_nan() || gap >= 0.0 {
                continue;
            }
            let accel = if self.terrain.is_flat() {
                (piece.vel[k].y - piece.start_vel[k].y) / piece.h
            } else {
                (piece.vel[k] - piece.start_vel[k]).dot(normal) / piece.h
            };
            let hit = Hit {
                index: (piece.first + k) as u32,
                accel,
                normal,
                gap,
            };
            let (x, v) = (&mut piece.pos[k], &mut piece.vel[k]);
            let shift = piece.flight_shift * accel * piece.step;
            if let Some(c) = self.resolve(hit, piece.step, shift, piece.t, piece.gravity, x, v, p) {
                bounces.push(c);
            }
        }
        if !bounces.is_empty() {
            self.pending.lock().extend(bounces);
        }
        state
    }

    fn settled(&mut self, kept: bool) {
        let pending = self.pending.get_mut();
        if pending.is_empty() {
            return;
        }
        if kept {
            // Pieces finish in any order: the bounces in particle order,
            // as `handle` records them.
            pending.sort_by_key(|c| c.particle.0);
            self.collisions.append(pending);
        } else {
            pending.clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::deepest;
    use glam::DVec3;

    /// The lanes find what a plain loop over the spheres finds, whatever
    /// the count (within the lanes, in the rest, both) and wherever the
    /// deepest is; NaN heights, pinned spheres, −0 and spheres exactly on
    /// the floor count as none.
    #[test]
    fn the_deepest_sphere_is_the_plain_loop_s() {
        let plain = |pos: &[DVec3], radius: &[f64], inv_mass: &[f64]| {
            let mut d = 0.0f64;
            for ((x, r), &w) in pos.iter().zip(radius).zip(inv_mass) {
                let gap = x.y - r;
                if gap < 0.0 && w != 0.0 {
                    d = d.min(gap);
                }
            }
            (d < 0.0).then_some(d)
        };
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let heights = [
            0.5,
            0.1,
            0.1 - 1e-17,
            0.099,
            -0.3,
            0.0,
            -0.0,
            f64::NAN,
            1e300,
            -1e300,
        ];
        let mut below = 0;
        for n in 0..14 {
            for _ in 0..400 {
                let pos: Vec<DVec3> = (0..n)
                    .map(|_| DVec3::new(0.0, heights[next() as usize % heights.len()], 0.0))
                    .collect();
                let radius: Vec<f64> = (0..n).map(|_| [0.1, 0.0][next() as usize % 2]).collect();
                let inv_mass: Vec<f64> = (0..n)
                    .map(|_| [1.0, 0.0, 2.0][next() as usize % 3])
                    .collect();
                let want = plain(&pos, &radius, &inv_mass);
                let got = deepest(&pos, &radius, &inv_mass);
                assert_eq!(
                    got.map(f64::to_bits),
                    want.map(f64::to_bits),
                    "{n} spheres {pos:?} {radius:?} {inv_mass:?}"
                );
                below += usize::from(want.is_some());
            }
        }
        // Both answers are common.
        assert!(
            (1_000..4_600).contains(&below),
            "{below} of 5,600 with a sphere below"
        );
    }
}
