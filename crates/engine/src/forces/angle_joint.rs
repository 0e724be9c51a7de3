//! Angle joint (thesis §3.1.2.3): a springy hinge between two arms that meet at
//! a joint mass. With `a` and `b` the arms from the joint to the ends and
//! `θ` the angle between them, the torque `T = k (θ - θ₀) + k_d dθ/dt` becomes
//! forces on the ends perpendicular to their arms,
//! `F_a = T/|a| (ĵ × â)`, `F_b = -T/|b| (ĵ × b̂)` with `ĵ` the unit normal
//! `a × b / |a × b|` (the thesis's `|j × a|` notation means the unit vector).
//! The joint mass takes the reaction `-(F_a + F_b)`, so the joint's forces sum
//! to zero and its torques about the joint cancel: linear and angular momentum
//! are conserved. These forces are exactly `-∇` of `½ k (θ - θ₀)²`.
//!
//! When the arms are collinear the plane of bending is undefined; the joint
//! then applies no force (its restoring torque vanishes there anyway when the
//! rest angle is 0 or π).

use crate::error::ModelError;
use crate::force::{Force, ForceContext};
use crate::particle::{non_negative, ParticleId};
use glam::DVec3;
use std::f64::consts::PI;

/// Handle to one angle joint of a world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct AngleJointId(pub(crate) u32);

impl AngleJointId {
    /// Index in the world's angle-joint collection.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Description of an angle joint to add to a world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleJointDef {
    /// End of the first arm.
    pub a: ParticleId,
    /// The joint mass, where the arms meet.
    pub joint: ParticleId,
    /// End of the second arm.
    pub b: ParticleId,
    /// Angular stiffness, N m/rad, >= 0.
    pub stiffness: f64,
    /// Angular damping, N m s/rad, >= 0.
    pub damping: f64,
    /// Rest angle in [0, π], rad; `None` means the angle when it is added.
    pub rest_angle: Option<f64>,
}

impl AngleJointDef {
    /// A joint at rest at its initial angle.
    pub fn new(
        a: ParticleId,
        joint: ParticleId,
        b: ParticleId,
        stiffness: f64,
        damping: f64,
    ) -> Self {
        AngleJointDef {
            a,
            joint,
            b,
            stiffness,
            damping,
            rest_angle: None,
        }
    }
    /// Sets the rest angle.
    pub fn with_rest_angle(mut self, rest_angle: f64) -> Self {
        self.rest_angle = Some(rest_angle);
        self
    }
}

/// One angle joint as the world stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleJoint {
    a: u32,
    joint: u32,
    b: u32,
    /// N m/rad.
    pub stiffness: f64,
    /// N m s/rad.
    pub damping: f64,
    /// rad.
    pub rest_angle: f64,
}

/// The angle at `j` between the arms to `a` and `b`, in [0, π].
pub fn angle_at(a: DVec3, j: DVec3, b: DVec3) -> f64 {
    let (ra, rb) = (a - j, b - j);
    // atan2 of |a×b| and a·b is accurate at every angle, unlike acos near 0 and π.
    crate::math::atan2(ra.cross(rb).length(), ra.dot(rb))
}

impl AngleJoint {
    /// The three particles: (end a, joint, end b).
    pub fn particles(&self) -> (ParticleId, ParticleId, ParticleId) {
        (
            ParticleId(self.a),
            ParticleId(self.joint),
            ParticleId(self.b),
        )
    }
    /// The current angle at the joint, rad.
    pub fn angle(&self, pos: &[DVec3]) -> f64 {
        angle_at(
            pos[self.a as usize],
            pos[self.joint as usize],
            pos[self.b as usize],
        )
    }
}

/// A joint's arms and their plane of bending at some positions.
#[derive(Clone, Copy)]
struct Bend {
    /// The arms, from the joint to each end.
    ra: DVec3,
    rb: DVec3,
    /// Their squared lengths.
    la2: f64,
    lb2: f64,
    /// `ra × rb` and its length.
    normal: DVec3,
    nl: f64,
}

impl AngleJoint {
    /// The arms and their plane, or `None` when the arms are collinear or
    /// one has no length (no plane of bending: no force, no derivative).
    /// Always inlined: called, it returned the `Bend` through memory, and
    /// the caller's wide loads of the fields waited for the narrow stores
    /// to land (about a sixth of a roobot evaluation).
    #[inline(always)]
    fn bend(&self, pos: &[DVec3]) -> Option<Bend> {
        let j = pos[self.joint as usize];
        let (ra, rb) = (pos[self.a as usize] - j, pos[self.b as usize] - j);
        let (la2, lb2) = (ra.length_squared(), rb.length_squared());
        let normal = ra.cross(rb);
        let n2 = normal.length_squared();
        if n2 <= 1e-24 * la2 * lb2 || la2 == 0.0 || lb2 == 0.0 {
            return None;
        }
        Some(Bend {
            ra,
            rb,
            la2,
            lb2,
            normal,
            nl: n2.sqrt(),
        })
    }
}

/// Every angle joint of a world.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AngleJoints {
    joints: Vec<AngleJoint>,
}

impl AngleJoints {
    /// Number of joints.
    pub fn len(&self) -> usize {
        self.joints.len()
    }
    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }
    /// The joint `id`.
    pub fn get(&self, id: AngleJointId) -> &AngleJoint {
        &self.joints[id.index()]
    }
    /// The joint `id`, to change its parameters (its rest angle is an actuator).
    pub fn get_mut(&mut self, id: AngleJointId) -> &mut AngleJoint {
        &mut self.joints[id.index()]
    }
    /// All joints, in the order they were added.
    pub fn iter(&self) -> impl Iterator<Item = &AngleJoint> {
        self.joints.iter()
    }

    pub(crate) fn add(
        &mut self,
        def: &AngleJointDef,
        pos: &[DVec3],
    ) -> Result<AngleJointId, ModelError> {
        if def.a == def.joint || def.b == def.joint || def.a == def.b {
            return Err(ModelError::new(
                "joint",
                "an angle joint needs three different particles",
            ));
        }
        non_negative("stiffness", def.stiffness)?;
        non_negative("damping", def.damping)?;
        let (pa, pj, pb) = (
            pos[def.a.index()],
            pos[def.joint.index()],
            pos[def.b.index()],
        );
        if pa == pj || pb == pj {
            return Err(ModelError::new(
                "joint",
                "an arm of the joint has zero length",
            ));
        }
        let rest_angle = match def.rest_angle {
            Some(r) => {
                non_negative("rest_angle", r)?;
                if r > PI {
                    return Err(ModelError::new(
                        "rest_angle",
                        format!("must be in [0, π], got {r}"),
                    ));
                }
                r
            }
            None => angle_at(pa, pj, pb),
        };
        self.joints.push(AngleJoint {
            a: def.a.0,
            joint: def.joint.0,
            b: def.b.0,
            stiffness: def.stiffness,
            damping: def.damping,
            rest_angle,
        });
        Ok(AngleJointId(self.joints.len() as u32 - 1))
    }
}

impl Force for AngleJoints {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        let (pos, vel) = (ctx.pos, ctx.vel);
        for jt in &self.joints {
            let Some(Bend {
                ra,
                rb,
                la2,
                lb2,
                normal,
                nl,
            }) = jt.bend(pos)
            else {
                continue; // collinear or degenerate: no plane of bending
            };
            let (a, j, b) = (jt.a as usize, jt.joint as usize, jt.b as usize);
            let theta = crate::math::atan2(nl, ra.dot(rb));
            // With ĵ = n/|n|: ĵ × â = (n × a)/(|n||a|), since n ⊥ a. The
            // force on an end is T/|arm| along that unit vector, so
            // F_a = (n × a) T / (|n| |a|²): one square root per joint.
            // `pa` turns a towards b (closing), `pb` turns b away from a.
            let (pa, pb) = (normal.cross(ra), normal.cross(rb));
            let (wa, wb) = (1.0 / (nl * la2), 1.0 / (nl * lb2));
            let theta_dot = pb.dot(vel[b] - vel[j]) * wb - pa.dot(vel[a] - vel[j]) * wa;
            let torque = jt.stiffness * (theta - jt.rest_angle) + jt.damping * theta_dot;
            let fa = pa * (torque * wa);
            let fb = pb * (-torque * wb);
            forces[a] += fa;
            forces[b] += fb;
            forces[j] -= fa + fb;
        }
    }

    /// Gauss–Newton: with `g = ∂θ/∂x` over the three particles,
    /// `∂f/∂x ≈ −k g gᵀ` (the Hessian of `½ k (θ − θ₀)²` without its
    /// `(θ − θ₀) ∂²θ/∂x²` term, which is not definite) and `∂f/∂v = −c g gᵀ`
    /// (exact: the damping torque is `c θ̇ = c g·v`).
    fn jacobian(&self, ctx: &ForceContext, jac: &mut crate::Jacobian) -> bool {
        let pos = ctx.pos;
        for jt in &self.joints {
            let Some(Bend {
                ra,
                rb,
                la2,
                lb2,
                normal,
                nl,
            }) = jt.bend(pos)
            else {
                continue; // as in `apply`: no force, no derivative
            };
            let (a, j, b) = (jt.a as usize, jt.joint as usize, jt.b as usize);
            let ga = normal.cross(ra) * (-1.0 / (nl * la2));
            let gb = normal.cross(rb) * (1.0 / (nl * lb2));
            let g = [(a, ga), (j, -(ga + gb)), (b, gb)];
            for (p, gp) in g {
                for (q, gq) in g {
                    let outer = glam::DMat3::from_cols(gp * gq.x, gp * gq.y, gp * gq.z);
                    jac.block(p, q, outer * -jt.stiffness, outer * -jt.damping);
                }
            }
        }
        true
    }

    fn potential_energy(&self, ctx: &ForceContext) -> f64 {
        self.joints
            .iter()
            .map(|jt| {
                let x = jt.angle(ctx.pos) - jt.rest_angle;
                0.5 * jt.stiffness * x * x
            })
            .sum()
    }

    fn is_conservative(&self) -> bool {
        self.joints.iter().all(|j| j.damping == 0.0)
    }

    fn is_passive(&self) -> bool {
        true // damping only removes energy
    }

    fn name(&self) -> &str {
        "angle joints"
    }
}
