//! Keeps particles in a plane: the thesis's planar roobot (§3.2.1.1, "confined
//! to a 2-dimensional plane"), placed in 3-D by the plane's orientation.
//!
//! Forces that act within the plane keep a body in it only up to rounding;
//! for a plane not aligned with the axes that rounding has out-of-plane
//! components, and a laterally unstable body (a hopper is an inverted
//! pendulum sideways) amplifies them until it falls over. After each step
//! this event projects the positions and velocities of its particles back
//! onto the plane. It reports `Occurring` whenever one has left it (by any
//! amount), never `Missed`, so it never causes a backtrack.

use crate::event::{DiscreteEvent, EventContext, EventState};
use crate::particle::{ParticleId, Properties};
use glam::DVec3;

/// Holds particles in the plane through `point` with normal `normal`.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneConstraint {
    point: DVec3,
    normal: DVec3,
    particles: Vec<ParticleId>,
}

impl PlaneConstraint {
    /// The plane through `point` normal to `normal` (normalised; a zero
    /// normal leaves the particles free), holding `particles`.
    pub fn new(point: DVec3, normal: DVec3, particles: Vec<ParticleId>) -> Self {
        PlaneConstraint {
            point,
            normal: normal.normalize_or_zero(),
            particles,
        }
    }

    /// The unit normal.
    pub fn normal(&self) -> DVec3 {
        self.normal
    }

    /// The point the plane passes through.
    pub fn point(&self) -> DVec3 {
        self.point
    }

    /// The particles it holds, in its order.
    pub fn particles(&self) -> &[ParticleId] {
        &self.particles
    }
}

impl DiscreteEvent for PlaneConstraint {
    fn check(&mut self, ctx: &EventContext) -> EventState {
        let off = self.particles.iter().any(|p| {
            let i = p.index();
            (ctx.pos[i] - self.point).dot(self.normal) != 0.0 || ctx.vel[i].dot(self.normal) != 0.0
        });
        if off {
            EventState::Occurring
        } else {
            EventState::None
        }
    }

    fn handle(&mut self, _t: f64, pos: &mut [DVec3], vel: &mut [DVec3], _particles: &Properties) {
        for p in &self.particles {
            let i = p.index();
            pos[i] -= self.normal * (pos[i] - self.point).dot(self.normal);
            vel[i] -= self.normal * vel[i].dot(self.normal);
        }
    }

    fn conserves_energy(&self) -> bool {
        // Removing out-of-plane velocity only ever removes rounding-level energy.
        true
    }

    fn is_passive(&self) -> bool {
        true // projecting onto the plane only removes velocity
    }

    fn name(&self) -> &str {
        "plane constraint"
    }
}
