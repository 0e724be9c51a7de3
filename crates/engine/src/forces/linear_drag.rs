//! Linear (viscous) drag, `F = −b v` on each target: the "linear damping" of
//! rigid-body engines (Box2D's and Rapier's `linear_damping`), and Stokes's
//! law for slow motion in a viscous fluid (`b = 6π μ r`). Unlike a spring's
//! damping, which acts only along the spring, it slows every motion — a
//! swing as much as a stretch — at the rate `b/m`. Its Jacobian is `−b I`.

use crate::error::ModelError;
use crate::force::{Force, ForceContext, Targets};
use crate::particle::non_negative;
use glam::{DMat3, DVec3};

/// Linear drag on some particles.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearDrag {
    /// `b`, N s/m, on each target.
    pub coefficient: f64,
    /// The particles it slows.
    pub targets: Targets,
}

impl LinearDrag {
    /// Checks the coefficient.
    pub fn validate(&self) -> Result<(), ModelError> {
        non_negative("coefficient", self.coefficient)
    }
}

impl Force for LinearDrag {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        let b = self.coefficient;
        self.targets
            .for_each(forces.len(), |i| forces[i] -= ctx.vel[i] * b);
    }

    fn jacobian(&self, ctx: &ForceContext, jac: &mut crate::Jacobian) -> bool {
        let dfdv = DMat3::from_diagonal(DVec3::splat(-self.coefficient));
        self.targets
            .for_each(ctx.pos.len(), |i| jac.single(i, DMat3::ZERO, dfdv));
        true
    }

    fn is_passive(&self) -> bool {
        true // it only removes energy
    }

    fn name(&self) -> &str {
        "linear drag"
    }
}
