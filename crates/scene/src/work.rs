//! The positive work of a scene's actuators (`[evolve] energy_weight`, the
//! archive's `energy` measure), J, summed step by step:
//!
//! - a muscle (a spring's rest length) or an angle joint's rest angle
//!   stores `½ k (l − r)²`; changing `r` to `r'` before a step, with the
//!   body where it is, does the work `½ k [(l − r')² − (l − r)²]`;
//! - a motor (a torque joint) does `τ ω h` over a step of `h`, `ω` the end's
//!   angular velocity about the axis, averaged over the step's ends;
//! - a driven constant force does `F · v h` on each particle it pushes, `v`
//!   averaged likewise.
//!
//! Each actuator's work in each step counts only when positive: what a
//! muscle puts in is spent, what it takes back (a spring relaxing) is not
//! returned (the usual cost of transport's convention).

use crate::Scene;
use animats_creatures::actuators::AnyActuator;
use animats_engine::{DVec3, World};

/// What an actuator's target held before a step.
#[derive(Clone, Copy, Debug)]
enum Before {
    /// Length or angle now, and the rest value.
    Elastic { now: f64, rest: f64 },
    /// The ends' axis-perpendicular geometry's rate (ω) at the start.
    Motor { omega: f64 },
    /// Σ v over the pushed particles at the start.
    Push { velocity: DVec3 },
}

/// Sums the actuators' positive work.
#[derive(Clone, Debug, Default)]
pub struct Work {
    before: Vec<Before>,
    /// J so far.
    pub positive: f64,
}

/// The angular velocity of `end` about `joint` around `axis`.
fn omega(world: &World, end: usize, joint: usize, axis: DVec3) -> f64 {
    let s = world.state();
    let r = s.pos[end] - s.pos[joint];
    let r_perp = r - axis * r.dot(axis);
    let l2 = r_perp.length_squared();
    if l2 == 0.0 {
        return 0.0;
    }
    axis.cross(r_perp).dot(s.vel[end] - s.vel[joint]) / l2
}

/// Σ v over `ids`.
fn velocity_sum(world: &World, ids: &[animats_engine::ParticleId]) -> DVec3 {
    ids.iter().map(|p| world.velocity(*p)).sum()
}

impl Work {
    /// Records every actuator's target before a step.
    pub fn before(&mut self, scene: &Scene) {
        let w = &scene.world;
        let f = w.forces();
        let pos = &w.state().pos;
        self.before.clear();
        for (_, a) in &scene.nervous.actuators {
            self.before.push(match a {
                AnyActuator::Spring(a) => {
                    let s = f.springs.get(a.target().0);
                    let (p, q) = s.ends();
                    Before::Elastic {
                        now: (pos[p.index()] - pos[q.index()]).length(),
                        rest: s.rest_length,
                    }
                }
                AnyActuator::AngleJoint(a) => {
                    let j = f.angle_joints.get(a.target().0);
                    Before::Elastic {
                        now: j.angle(pos),
                        rest: j.rest_angle,
                    }
                }
                AnyActuator::TorqueJoint(a) => {
                    let j = f.torque_joints.get(a.target().0);
                    let (e, p) = j.particles();
                    Before::Motor {
                        omega: omega(w, e.index(), p.index(), j.axis()),
                    }
                }
                AnyActuator::ConstantForce(a) => {
                    let c = f.constant_forces.get(a.target().force);
                    Before::Push {
                        velocity: velocity_sum(w, c.particles()),
                    }
                }
            });
        }
    }

    /// Adds each actuator's positive work over the step of `h` just taken.
    pub fn after(&mut self, scene: &Scene, h: f64) {
        let w = &scene.world;
        let f = w.forces();
        for ((_, a), before) in scene.nervous.actuators.iter().zip(&self.before) {
            let done = match (a, *before) {
                (AnyActuator::Spring(a), Before::Elastic { now, rest }) => {
                    let s = f.springs.get(a.target().0);
                    let (r, k) = (s.rest_length, s.stiffness);
                    0.5 * k * ((now - r) * (now - r) - (now - rest) * (now - rest))
                }
                (AnyActuator::AngleJoint(a), Before::Elastic { now, rest }) => {
                    let j = f.angle_joints.get(a.target().0);
                    let (r, k) = (j.rest_angle, j.stiffness);
                    0.5 * k * ((now - r) * (now - r) - (now - rest) * (now - rest))
                }
                (AnyActuator::TorqueJoint(a), Before::Motor { omega: start }) => {
                    let j = f.torque_joints.get(a.target().0);
                    let (e, p) = j.particles();
                    let end = omega(w, e.index(), p.index(), j.axis());
                    j.torque * 0.5 * (start + end) * h
                }
                (AnyActuator::ConstantForce(a), Before::Push { velocity }) => {
                    let c = f.constant_forces.get(a.target().force);
                    c.force
                        .dot(0.5 * (velocity + velocity_sum(w, c.particles())))
                        * h
                }
                _ => 0.0,
            };
            if done > 0.0 {
                self.positive += done;
            }
        }
    }
}
