//! Blow-ups that stay finite. A stiff system stepped past its stability
//! limit need not overflow: it can tangle at 100 m/s with many times its
//! energy, or grow for a long time before it reaches infinity. The guard
//! calls such a run a blow-up, by two criteria (docs/DESIGN.md, "Blow-ups
//! and the recommended step"):
//!
//! - **Energy, for passive worlds.** With nothing to drive it (no motors,
//!   constant forces, currents, user forces or events that may add energy)
//!   a world's total mechanical energy can only fall: the floor's impacts
//!   never add any, springs and fluids dissipate. A total energy that rises
//!   by more than [`DivergenceGuard::ENERGY_FACTOR`] times everything the
//!   world started with (its kinetic energy, the magnitude of its potential
//!   energy, and the work gravity can do bringing every particle down to the
//!   lowest of them) is the integrator's doing, not physics.
//! - **Speed, for every world.** No particle of an animat world moves at
//!   [`DivergenceGuard::MAX_SPEED`]; one that does has been thrown by a
//!   numerical instability.

use crate::error::SimError;
use crate::particle::ParticleId;
use crate::world::World;

/// Watches a world for a run-away; see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct DivergenceGuard {
    /// Total energy at the start, J (for passive worlds).
    start: f64,
    /// Everything the world started with, J.
    budget: f64,
    /// Whether the energy criterion applies.
    passive: bool,
}

impl DivergenceGuard {
    /// A rise of the total energy past this multiple of the world's starting
    /// energy is a blow-up (passive worlds).
    pub const ENERGY_FACTOR: f64 = 10.0;
    /// A particle faster than this, m/s, is a blow-up (every world).
    pub const MAX_SPEED: f64 = 1000.0;

    /// A guard for `world` as it is now; `driven` says that something outside
    /// the world's forces (controllers, actuators) may feed it energy.
    pub fn new(world: &World, driven: bool) -> Self {
        let e = world.energy();
        let p = world.particles();
        let s = world.state();
        let lowest = (0..world.len())
            .map(|i| s.pos[i].y - p.radius[i])
            .fold(f64::INFINITY, f64::min);
        let g = world.forces().g().length();
        let fall: f64 = (0..world.len())
            .filter(|&i| !p.fixed[i])
            .map(|i| p.mass[i] * g * (s.pos[i].y - p.radius[i] - lowest))
            .sum();
        DivergenceGuard {
            start: e.total(),
            budget: e.kinetic + e.potential.abs() + fall + 1e-3,
            passive: !driven && world.is_passive(),
        }
    }

    /// An error if the world has run away.
    pub fn check(&self, world: &World) -> Result<(), SimError> {
        let (p, s) = (world.particles(), world.state());
        let mut fastest = (0usize, 0.0f64);
        let mut hottest = (0usize, 0.0f64);
        for i in (0..world.len()).filter(|&i| !p.fixed[i]) {
            let v2 = s.vel[i].length_squared();
            if v2 > fastest.1 {
                fastest = (i, v2);
            }
            if p.mass[i] * v2 > hottest.1 {
                hottest = (i, p.mass[i] * v2);
            }
        }
        if fastest.1 > Self::MAX_SPEED * Self::MAX_SPEED {
            return Err(SimError::Diverged {
                particle: ParticleId::from_index(fastest.0),
                time: world.time(),
                why: format!(
                    "it moves at {:.4e} m/s, faster than {} m/s",
                    fastest.1.sqrt(),
                    Self::MAX_SPEED
                ),
            });
        }
        if self.passive {
            let now = world.energy().total();
            if now - self.start > Self::ENERGY_FACTOR * self.budget {
                return Err(SimError::Diverged {
                    particle: ParticleId::from_index(hottest.0),
                    time: world.time(),
                    why: format!(
                        "the world's total energy rose from {:.4e} J to {:.4e} J, more than {} times the {:.4e} J it started with, though nothing drives it",
                        self.start,
                        now,
                        Self::ENERGY_FACTOR,
                        self.budget
                    ),
                });
            }
        }
        Ok(())
    }
}
