//! Drag on springs as thin rods: the water pushes on a spring across its
//! length, as Karl Sims's water pushed on each exposed face of his
//! creatures ("Evolving Virtual Creatures", 1994: a force against the
//! normal component of the surface's velocity). The thesis's fluid (Eq. 14,
//! [`crate::FluidMedium`]) acts on each sphere alone, by its own velocity,
//! the same in every direction; a rod's drag depends on its direction, so a
//! stroke across a limb pushes and a stroke along it slips: what paddles,
//! fins and undulation swim by.
//!
//! A rod from `a` to `b`, of length `L` and diameter `D`, in a fluid of
//! density `ρ`: a point of it at `x(ξ) = a + ξ (b − a)` moves with
//! `v(ξ) = v_a + ξ (v_b − v_a)` (a spring's points move as its ends do,
//! linearly), less the current there; its velocity across the rod is
//! `v_n = v − (v·u) u`, `u` the rod's direction; and each length `ds`
//! feels `dF = −½ C ρ D |v_n| v_n ds` (a cylinder across a flow; `C`
//! about 1.2). Along the rod it feels nothing (a thin rod's skin friction
//! is left out). The integral over the rod is taken by two-point Gauss
//! quadrature (`ξ = ½ ∓ 1/(2√3)`, each point carrying half the length),
//! each point's force shared by the ends as a lever would, `1 − ξ` to `a`
//! and `ξ` to `b`. A rod moving without turning is then exact (`F = −½ C ρ
//! D L |v_n| v_n`); one turning about its middle feels a torque 0.77 times
//! the integral's (`crates/engine/tests/rod_drag.rs` checks both).
//!
//! In still water the force takes energy away, never adds it: its power at
//! a point is `F·v = −c |v_n| v_n·v = −c |v_n|³`. The implicit integrator
//! takes it explicitly (no Jacobian).

use crate::error::ModelError;
use crate::force::{Force, ForceContext};
use crate::forces::current::Current;
use crate::particle::{non_negative, positive, ParticleId};
use glam::DVec3;

/// The two Gauss points on `[0, 1]`: `½ ∓ 1/(2√3)`.
const GAUSS: [f64; 2] = [0.211_324_865_405_187_08, 0.788_675_134_594_812_9];

/// Drag across a set of rods (the springs of a body).
#[derive(Clone, Debug, PartialEq)]
pub struct RodDrag {
    /// The fluid's density, kg/m³.
    pub density: f64,
    /// `C` of a cylinder across the flow (about 1.2).
    pub drag_coefficient: f64,
    /// Every rod's diameter, m.
    pub diameter: f64,
    /// The fluid's velocity field.
    pub current: Current,
    /// The rods' ends, as particle indices.
    rods: Vec<(u32, u32)>,
}

impl RodDrag {
    /// Drag on the rods `rods` (their ends, which must differ).
    pub fn new(
        density: f64,
        drag_coefficient: f64,
        diameter: f64,
        current: Current,
        rods: &[(ParticleId, ParticleId)],
    ) -> Result<Self, ModelError> {
        non_negative("density", density)?;
        non_negative("drag_coefficient", drag_coefficient)?;
        positive("diameter", diameter)?;
        let mut ends = Vec::with_capacity(rods.len());
        for &(a, b) in rods {
            if a == b {
                return Err(ModelError::new(
                    "rods",
                    format!("a rod joins particle {} to itself", a.index()),
                ));
            }
            let index = |p: ParticleId| {
                u32::try_from(p.index())
                    .map_err(|_| ModelError::new("rods", "more than 2³² particles"))
            };
            ends.push((index(a)?, index(b)?));
        }
        Ok(RodDrag {
            density,
            drag_coefficient,
            diameter,
            current,
            rods: ends,
        })
    }

    /// The rods' ends, as particle indices, in the order they are dragged
    /// (the GPU's packer reads them).
    pub fn rods(&self) -> &[(u32, u32)] {
        &self.rods
    }
}

impl Force for RodDrag {
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        // −½ C ρ D: with half the length it is each Gauss point's factor.
        let drag = -0.5 * self.drag_coefficient * self.density * self.diameter;
        let still = matches!(self.current, Current::Still);
        for &(a, b) in &self.rods {
            let (a, b) = (a as usize, b as usize);
            let d = ctx.pos[b] - ctx.pos[a];
            let length = d.length();
            if length == 0.0 {
                continue; // no direction: a rod of no length has no drag
            }
            let u = d / length;
            let dv = ctx.vel[b] - ctx.vel[a];
            let mut fa = DVec3::ZERO;
            let mut fb = DVec3::ZERO;
            for xi in GAUSS {
                let mut v = ctx.vel[a] + dv * xi;
                if !still {
                    v -= self.current.velocity(ctx.pos[a] + d * xi, ctx.t);
                }
                let vn = v - u * v.dot(u);
                let f = vn * (drag * 0.5 * length * vn.length());
                fa += f * (1.0 - xi);
                fb += f * xi;
            }
            forces[a] += fa;
            forces[b] += fb;
        }
    }

    fn is_passive(&self) -> bool {
        matches!(self.current, Current::Still)
    }

    fn name(&self) -> &str {
        "rod drag"
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}
