//! Collision of spheres with the floor, the plane y = 0 (thesis §3.1.3.1).
//!
//! After a trial step, a sphere whose lowest point is below the plane is
//! `Occurring`; one more than `envelope` below it was `Missed` (it hit the
//! plane somewhere inside the step and the step must be retaken in shorter
//! pieces). Handling moves the sphere up to touch the plane and, if it is
//! moving into the plane, reflects its normal velocity with its restitution,
//! `v_y ← -r v_y` (Eq. 16). Impacts slower than `rest_speed` do not bounce:
//! the sphere comes to rest, and the floor's contact force holds it (without
//! this, a resting sphere would bounce a little on every step forever).
//! A sphere below the plane but already moving up is only moved up.

use crate::error::ModelError;
use crate::event::{DiscreteEvent, EventContext, EventState};
use crate::force::Targets;
use crate::particle::{non_negative, ParticleId, Properties};
use glam::DVec3;

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
    hits: Vec<u32>,
    collisions: Vec<Collision>,
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
            hits: Vec::new(),
            collisions: Vec::new(),
        }
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

    /// The bounces of the last step.
    pub fn collisions(&self) -> &[Collision] {
        &self.collisions
    }
}

impl DiscreteEvent for FloorCollision {
    fn check(&mut self, ctx: &EventContext) -> EventState {
        self.hits.clear();
        let (pos, p) = (ctx.pos, ctx.particles);
        // The deepest penetration among the spheres below the plane.
        let mut deepest = 0.0f64;
        let mut hit = |i: usize, gap: f64| {
            if p.inv_mass[i] != 0.0 {
                self.hits.push(i as u32);
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
        if self.hits.is_empty() {
            EventState::None
        } else if deepest < -self.envelope {
            EventState::Missed
        } else {
            EventState::Occurring
        }
    }

    fn handle(&mut self, t: f64, pos: &mut [DVec3], vel: &mut [DVec3], particles: &Properties) {
        for &i in &self.hits {
            let i = i as usize;
            pos[i].y = particles.radius[i];
            let vy = vel[i].y;
            if vy < 0.0 {
                vel[i].y = if -vy < self.rest_speed {
                    0.0
                } else {
                    -particles.restitution[i] * vy
                };
                self.collisions.push(Collision {
                    particle: ParticleId(i as u32),
                    t,
                    impact_speed: -vy,
                });
            }
        }
    }

    fn begin_step(&mut self) {
        self.collisions.clear();
    }

    fn name(&self) -> &str {
        "floor collision"
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}
