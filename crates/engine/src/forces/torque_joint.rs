//! Torque joint (thesis §3.1.2.4): a motor. A torque of magnitude `τ` about a
//! given axis is applied to an end mass about a joint mass: with `r` the arm
//! from the joint to the end projected onto the plane normal to the axis, the
//! end feels `F = τ (n̂ × r) / |r|²` (whose moment about the joint is `τ n̂`)
//! and the joint mass the reaction `-F`, so linear momentum is conserved.

use crate::error::ModelError;
use crate::force::{Force, ForceContext};
use crate::particle::{finite, ParticleId};
use glam::DVec3;

/// Handle to one torque joint of a world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TorqueJointId(pub(crate) u32);

impl TorqueJointId {
    /// Index in the world's torque-joint collection.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Description of a torque joint to add to a world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueJointDef {
    /// The mass the torque turns.
    pub end: ParticleId,
    /// The mass it turns about (takes the reaction).
    pub joint: ParticleId,
    /// Torque axis (normalised when added), non-zero.
    pub axis: DVec3,
    /// Torque, N m (right-hand rule about `axis`).
    pub torque: f64,
}

/// One torque joint as the world stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueJoint {
    end: u32,
    joint: u32,
    pub(crate) axis: DVec3,
    /// N m; set it each step to drive the motor.
    pub torque: f64,
}

impl TorqueJoint {
    /// (end, joint).
    pub fn particles(&self) -> (ParticleId, ParticleId) {
        (ParticleId(self.end), ParticleId(self.joint))
    }
    /// The unit torque axis.
    pub fn axis(&self) -> DVec3 {
        self.axis
    }
    /// Sets the torque axis (normalised; a zero axis turns the motor off).
    pub fn set_axis(&mut self, axis: DVec3) {
        self.axis = axis.normalize_or_zero();
    }
}

/// Every torque joint of a world.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TorqueJoints {
    joints: Vec<TorqueJoint>,
}

impl TorqueJoints {
    /// Number of joints.
    pub fn len(&self) -> usize {
        self.joints.len()
    }
    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }
    /// The joint `id`.
    pub fn get(&self, id: TorqueJointId) -> &TorqueJoint {
        &self.joints[id.index()]
    }
    /// The joint `id`, to set its torque.
    pub fn get_mut(&mut self, id: TorqueJointId) -> &mut TorqueJoint {
        &mut self.joints[id.index()]
    }
    /// Sets the torque of joint `id`, N m.
    pub fn set_torque(&mut self, id: TorqueJointId, torque: f64) {
        self.joints[id.index()].torque = torque;
    }
    /// All joints, in the order they were added.
    pub fn iter(&self) -> impl Iterator<Item = &TorqueJoint> {
        self.joints.iter()
    }

    pub(crate) fn add(&mut self, def: &TorqueJointDef) -> Result<TorqueJointId, ModelError> {
        if def.end == def.joint {
            return Err(ModelError::new(
                "joint",
                "a torque joint needs two different particles",
            ));
        }
        if !def.axis.is_finite() || def.axis.length_squared() == 0.0 {
            return Err(ModelError::new("axis", "must be a finite, non-zero vector"));
        }
        finite("torque", def.torque)?;
        self.joints.push(TorqueJoint {
            end: def.end.0,
            joint: def.joint.0,
            axis: def.axis.normalize(),
            torque: def.torque,
        });
        Ok(TorqueJointId(self.joints.len() as u32 - 1))
    }
}

impl Force for TorqueJoints {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        for jt in &self.joints {
            if jt.torque == 0.0 {
                continue;
            }
            let (e, j) = (jt.end as usize, jt.joint as usize);
            let r = ctx.pos[e] - ctx.pos[j];
            let r_perp = r - jt.axis * r.dot(jt.axis);
            let l2 = r_perp.length_squared();
            if l2 == 0.0 {
                continue; // the end sits on the axis: no lever arm
            }
            let f = jt.axis.cross(r_perp) * (jt.torque / l2);
            forces[e] += f;
            forces[j] -= f;
        }
    }

    fn is_conservative(&self) -> bool {
        self.joints.iter().all(|j| j.torque == 0.0)
    }

    fn name(&self) -> &str {
        "torque joints"
    }
}
