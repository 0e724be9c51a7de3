//! Fluid medium (thesis §3.1.2.8): turbulent drag on the velocity relative to
//! the fluid (Eq. 14), `F = -½ C ρ A |v_r| v_r`, and Archimedes' buoyancy
//! (Eq. 15), `F = -V ρ g`. `A` is the sphere's cross-section `π r²`, `V` its
//! volume and `g` the world's gravity.

use crate::error::ModelError;
use crate::force::{Force, ForceContext, Targets};
use crate::forces::current::Current;
use crate::particle::non_negative;
use glam::DVec3;
use std::f64::consts::PI;

/// Water, air, or any fluid the particles move through.
#[derive(Clone, Debug, PartialEq)]
pub struct FluidMedium {
    /// kg/m³.
    pub density: f64,
    /// Drag coefficient `C` (0.47 for a sphere).
    pub drag_coefficient: f64,
    /// The fluid's velocity field.
    pub current: Current,
    /// The particles immersed in it.
    pub targets: Targets,
}

impl FluidMedium {
    /// Fresh water at rest (1000 kg/m³, sphere drag 0.47) around every particle.
    pub fn water() -> Self {
        FluidMedium {
            density: 1000.0,
            drag_coefficient: 0.47,
            current: Current::Still,
            targets: Targets::All,
        }
    }

    /// Still air at sea level (1.2 kg/m³) around every particle.
    pub fn air() -> Self {
        FluidMedium {
            density: 1.2,
            ..FluidMedium::water()
        }
    }

    /// Checks density and drag coefficient.
    pub fn validate(&self) -> Result<(), ModelError> {
        non_negative("density", self.density)?;
        non_negative("drag_coefficient", self.drag_coefficient)?;
        Ok(())
    }

    /// The force on particle `i`; `drag` is `-½ C ρ π` (the same product,
    /// in the same order, for every particle) and `still` says there is no
    /// current (then `v − 0` is `v` to the bit, and the lookup is skipped).
    #[inline(always)]
    fn force_on(&self, ctx: &ForceContext, i: usize, drag: f64, still: bool) -> DVec3 {
        let r = ctx.particles.radius[i];
        let vr = if still {
            ctx.vel[i]
        } else {
            ctx.vel[i] - self.current.velocity(ctx.pos[i], ctx.t)
        };
        let drag = vr * (drag * r * r * vr.length());
        let buoyancy = ctx.gravity * (-ctx.particles.volume[i] * self.density);
        drag + buoyancy
    }
}

impl FluidMedium {
    /// The fluid's force on each particle it surrounds, added into
    /// `forces` in particle order; `still` as for `force_on`.
    #[inline(always)]
    fn apply_all(&self, ctx: &ForceContext, forces: &mut [DVec3], drag: f64, still: bool) {
        match &self.targets {
            Targets::All => {
                for (i, f) in forces.iter_mut().enumerate() {
                    *f += self.force_on(ctx, i, drag, still);
                }
            }
            Targets::Only(ids) => {
                for id in ids {
                    forces[id.index()] += self.force_on(ctx, id.index(), drag, still);
                }
            }
        }
    }
}

impl Force for FluidMedium {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        let drag = -0.5 * self.drag_coefficient * self.density * PI;
        // Two copies of the loop, one per kind of water: with one loop the
        // compiler computes the current's loop-invariant parts (a square
        // root and a division) on every call, still water or not.
        if matches!(self.current, Current::Still) {
            self.apply_all(ctx, forces, drag, true);
        } else {
            self.apply_all(ctx, forces, drag, false);
        }
    }

    /// The drag's `∂f/∂v = −½ C ρ π r² (|v| I + v vᵀ/|v|)` for the
    /// relative velocity `v`; buoyancy is constant. The current's
    /// dependence on position is left out (it would not be symmetric).
    fn jacobian(&self, ctx: &ForceContext, jac: &mut crate::Jacobian) -> bool {
        let drag = -0.5 * self.drag_coefficient * self.density * PI;
        let still = matches!(self.current, Current::Still);
        let mut add = |i: usize| {
            let vr = if still {
                ctx.vel[i]
            } else {
                ctx.vel[i] - self.current.velocity(ctx.pos[i], ctx.t)
            };
            let speed = vr.length();
            if speed > 0.0 {
                let r = ctx.particles.radius[i];
                let u = vr / speed;
                let uu = glam::DMat3::from_cols(u * u.x, u * u.y, u * u.z);
                let dfdv = (uu + glam::DMat3::IDENTITY) * (drag * r * r * speed);
                jac.single(i, glam::DMat3::ZERO, dfdv);
            }
        };
        self.targets.for_each(ctx.pos.len(), &mut add);
        true
    }

    fn is_passive(&self) -> bool {
        // Drag in still fluid removes energy and buoyancy is conservative;
        // a current pushes.
        matches!(self.current, crate::forces::current::Current::Still)
    }

    fn name(&self) -> &str {
        "fluid"
    }
}
