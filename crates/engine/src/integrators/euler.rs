//! Explicit Euler (thesis Eq. 9): `x₁ = x₀ + h v₀`, `v₁ = v₀ + h a(x₀, v₀)`.
//! First order; its energy error grows without bound on oscillators.

use super::Dynamics;
use crate::particle::State;

/// One explicit Euler step of size `h` from time `t`.
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) {
    let f = &mut d.scratch.force;
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let w = &d.particles.inv_mass;
    for i in 0..from.pos.len() {
        to.pos[i] = from.pos[i] + h * from.vel[i];
        to.vel[i] = from.vel[i] + (h * w[i]) * f[i];
    }
}
