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
    let new = to.pos.iter_mut().zip(to.vel.iter_mut());
    let old = from.pos.iter().zip(&from.vel).zip(w.iter().zip(f.iter()));
    for ((x1, v1), ((x0, v0), (w, f))) in new.zip(old) {
        let v = *v0 + (h * w) * *f;
        *v1 = v;
        *x1 = *x0 + h * v;
    }
}
