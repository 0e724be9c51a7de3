//! Constant force (thesis §3.1.2.5): one vector applied to each of a set of
//! masses. Actuators change its magnitude (the jellyfish's pulse and steering).

use crate::error::ModelError;
use crate::force::{Force, ForceContext};
use crate::particle::{finite_vec, ParticleId};
use glam::DVec3;

/// Handle to one constant force of a world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ConstantForceId(pub(crate) u32);

impl ConstantForceId {
    /// Index in the world's constant-force collection.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A force vector applied to each of its particles.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstantForce {
    /// N, on each particle.
    pub force: DVec3,
    particles: Vec<ParticleId>,
}

impl ConstantForce {
    /// The particles it pushes.
    pub fn particles(&self) -> &[ParticleId] {
        &self.particles
    }
}

/// Every constant force of a world.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConstantForces {
    forces: Vec<ConstantForce>,
}

impl ConstantForces {
    /// Number of constant forces.
    pub fn len(&self) -> usize {
        self.forces.len()
    }
    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.forces.is_empty()
    }
    /// The force `id`.
    pub fn get(&self, id: ConstantForceId) -> &ConstantForce {
        &self.forces[id.index()]
    }
    /// Sets the force vector of `id`, N.
    pub fn set(&mut self, id: ConstantForceId, force: DVec3) {
        self.forces[id.index()].force = force;
    }
    /// All constant forces, in the order they were added.
    pub fn iter(&self) -> impl Iterator<Item = &ConstantForce> {
        self.forces.iter()
    }

    pub(crate) fn add(
        &mut self,
        particles: Vec<ParticleId>,
        force: DVec3,
    ) -> Result<ConstantForceId, ModelError> {
        finite_vec("force", force)?;
        self.forces.push(ConstantForce { force, particles });
        Ok(ConstantForceId(self.forces.len() as u32 - 1))
    }
}

impl Force for ConstantForces {
    fn jacobian(&self, _ctx: &ForceContext, _jac: &mut crate::Jacobian) -> bool {
        true // constant: its derivatives are zero
    }

    fn apply(&mut self, _ctx: &ForceContext, forces: &mut [DVec3]) {
        for cf in &self.forces {
            for p in &cf.particles {
                forces[p.index()] += cf.force;
            }
        }
    }

    fn potential_energy(&self, ctx: &ForceContext) -> f64 {
        self.forces
            .iter()
            .flat_map(|cf| {
                cf.particles
                    .iter()
                    .map(move |p| -cf.force.dot(ctx.pos[p.index()]))
            })
            .sum()
    }

    fn is_conservative(&self) -> bool {
        true
    }

    fn name(&self) -> &str {
        "constant forces"
    }
}
