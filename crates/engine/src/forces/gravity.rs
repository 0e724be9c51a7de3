//! Gravity (thesis §3.1.2.1, Eq. 10): `F = m g` on every particle it acts on.

use crate::force::{Force, ForceContext, Targets};
use glam::DVec3;

/// Uniform gravitational field. The thesis's default `g` is 9.8 m/s² down.
#[derive(Clone, Debug, PartialEq)]
pub struct Gravity {
    /// Gravitational acceleration, m/s².
    pub g: DVec3,
    /// The particles it pulls.
    pub targets: Targets,
}

impl Gravity {
    /// The thesis's default: 9.8 m/s² along -y.
    pub const STANDARD: DVec3 = DVec3::new(0.0, -9.8, 0.0);

    /// Gravity `g` on every particle.
    pub fn new(g: DVec3) -> Self {
        Gravity {
            g,
            targets: Targets::All,
        }
    }
}

/// Sets each force of `out` to its particle's weight `m g` (`mass` the
/// masses of the same particles): gravity on all of them starting the
/// accumulator, instead of adding to zeros.
#[inline]
pub(crate) fn start_with_weights(g: DVec3, mass: &[f64], out: &mut [DVec3]) {
    for (f, &m) in out.iter_mut().zip(mass) {
        *f = m * g;
    }
}

impl Default for Gravity {
    fn default() -> Self {
        Gravity::new(Gravity::STANDARD)
    }
}

impl Force for Gravity {
    fn jacobian(&self, _ctx: &ForceContext, _jac: &mut crate::Jacobian) -> bool {
        true // constant: its derivatives are zero
    }

    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        let g = self.g;
        match &self.targets {
            Targets::All => {
                for (f, &m) in forces.iter_mut().zip(&ctx.particles.mass) {
                    *f += m * g;
                }
            }
            Targets::Only(ids) => {
                for id in ids {
                    let i = id.index();
                    forces[i] += ctx.particles.mass[i] * g;
                }
            }
        }
    }

    fn potential_energy(&self, ctx: &ForceContext) -> f64 {
        let mut e = 0.0;
        self.targets.for_each(ctx.pos.len(), |i| {
            e -= ctx.particles.mass[i] * self.g.dot(ctx.pos[i]);
        });
        e
    }

    fn is_conservative(&self) -> bool {
        true
    }

    fn name(&self) -> &str {
        "gravity"
    }
}
