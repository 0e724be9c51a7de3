//! Semi-implicit (symplectic) Euler: `v₁ = v₀ + h a(x₀, v₀)`, then
//! `x₁ = x₀ + h v₁`. First order, but symplectic: on a conservative system its
//! energy error oscillates and stays bounded instead of drifting.

use super::Dynamics;
use crate::particle::State;

/// One symplectic Euler step of size `h` from time `t`.
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) {
    let f = &mut d.scratch.force;
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let w = &d.particles.inv_mass;
    for i in 0..from.pos.len() {
        let v = from.vel[i] + (h * w[i]) * f[i];
        to.vel[i] = v;
        to.pos[i] = from.pos[i] + h * v;
    }
}
