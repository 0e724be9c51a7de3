//! What a world can say about itself: the step its springs allow, its
//! energy, momentum and centre of mass.

use super::World;
use crate::force::ForceContext;
use crate::forces::spring::SpringId;
use crate::integrators::IntegratorKind;
use crate::particle::ParticleId;
use glam::DVec3;

/// The largest step an explicit integrator can take with a world's springs
/// ([`World::step_limit`]), and where the stiffest mode is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepLimit {
    /// The step, s.
    pub dt: f64,
    /// The bound on the fastest spring mode, rad/s.
    pub omega: f64,
    /// The particle where that bound is reached.
    pub particle: ParticleId,
    /// The stiffest spring at that particle.
    pub spring: SpringId,
}

/// Kinetic and potential energy of a world, J.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Energy {
    /// Σ ½ m v² over the moving particles.
    pub kinetic: f64,
    /// Sum of every conservative force's potential energy.
    pub potential: f64,
}

impl Energy {
    /// Kinetic plus potential.
    pub fn total(&self) -> f64 {
        self.kinetic + self.potential
    }
}

impl World {
    /// The largest step at which `kind` keeps every spring mode of this
    /// world bounded, by a conservative bound: the fastest mode's ω² is at
    /// most `2 Σ k / m` over the springs meeting at one particle
    /// (Gershgorin's theorem on `M⁻¹K`; a nail takes none), so `kind` is
    /// stable while `h ≤` [`IntegratorKind::stable_omega_h`]` / ω`. Exact
    /// for two equal masses on one spring; damping, joints and contact are
    /// not counted. `None` without springs between moving particles, and for
    /// the implicit integrator.
    pub fn step_limit(&self, kind: IntegratorKind) -> Option<StepLimit> {
        if !kind.is_explicit() {
            return None; // springs do not limit an implicit step
        }
        let p = &self.particles;
        let n = self.len();
        let mut load = vec![0.0f64; n];
        let mut stiffest: Vec<Option<(f64, usize)>> = vec![None; n];
        for (k, sp) in self.forces.springs.iter().enumerate() {
            let (a, b) = sp.ends();
            for i in [a.index(), b.index()] {
                load[i] += sp.stiffness;
                if stiffest[i].is_none_or(|(kk, _)| sp.stiffness > kk) {
                    stiffest[i] = Some((sp.stiffness, k));
                }
            }
        }
        let (w2, i) = (0..n)
            .map(|i| (2.0 * load[i] * p.inv_mass[i], i))
            .max_by(|x, y| x.0.total_cmp(&y.0))
            .filter(|w| w.0 > 0.0 && w.0.is_finite())?;
        let (_, k) = stiffest[i]?;
        let omega = w2.sqrt();
        Some(StepLimit {
            dt: kind.stable_omega_h() / omega,
            omega,
            particle: ParticleId(i as u32),
            spring: SpringId(k as u32),
        })
    }

    /// The step [`step_limit`](World::step_limit) allows `kind`, s (`None`
    /// when no spring limits it).
    pub fn recommended_dt(&self, kind: IntegratorKind) -> Option<f64> {
        self.step_limit(kind).map(|l| l.dt)
    }

    /// Kinetic and potential energy of the current state.
    pub fn energy(&self) -> Energy {
        let p = &self.particles;
        let kinetic = (0..self.len())
            .filter(|&i| !p.fixed[i])
            .map(|i| 0.5 * p.mass[i] * self.state.vel[i].length_squared())
            .sum();
        let ctx = ForceContext {
            t: self.time,
            dt: 0.0,
            pos: &self.state.pos,
            vel: &self.state.vel,
            particles: p,
            gravity: self.forces.g(),
        };
        let mut potential = 0.0;
        self.forces
            .for_each(|f| potential += f.potential_energy(&ctx));
        Energy { kinetic, potential }
    }

    /// True when every force is conservative and there are no events, so the
    /// total energy should stay constant (up to integration error).
    pub fn is_conservative(&self) -> bool {
        let mut conservative = self.events.iter().all(|e| e.conserves_energy());
        self.forces
            .for_each(|f| conservative &= f.is_conservative());
        conservative
    }

    /// True when nothing in the world can add mechanical energy (see
    /// [`Force::is_passive`]).
    pub fn is_passive(&self) -> bool {
        let mut passive = self.events.iter().all(|e| e.is_passive());
        self.forces.for_each(|f| passive &= f.is_passive());
        passive
    }

    /// Total linear momentum of the moving particles, kg m/s.
    pub fn momentum(&self) -> DVec3 {
        let p = &self.particles;
        (0..self.len())
            .filter(|&i| !p.fixed[i])
            .map(|i| p.mass[i] * self.state.vel[i])
            .sum()
    }

    /// Centre of mass of every particle, m.
    pub fn centre_of_mass(&self) -> DVec3 {
        let p = &self.particles;
        let m: f64 = p.mass.iter().sum();
        let s: DVec3 = (0..self.len()).map(|i| p.mass[i] * self.state.pos[i]).sum();
        s / m
    }
}
