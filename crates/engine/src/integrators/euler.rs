//! Explicit Euler (thesis Eq. 9): `x₁ = x₀ + h v₀`, `v₁ = v₀ + h a(x₀, v₀)`.
//! First order; its energy error grows without bound on oscillators.

use super::Dynamics;
use crate::parallel::by_pieces;
use crate::particle::State;

/// One explicit Euler step of size `h` from time `t`.
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) -> bool {
    let split = !d.forces.one_piece;
    let f = &mut d.scratch.force;
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let (w, f) = (&d.particles.inv_mass, &*f);
    by_pieces(split, [&mut to.pos, &mut to.vel], |first, [x1, v1]| {
        for (k, (x1, v1)) in x1.iter_mut().zip(v1.iter_mut()).enumerate() {
            let i = first + k;
            *x1 = from.pos[i] + h * from.vel[i];
            *v1 = from.vel[i] + (h * w[i]) * f[i];
        }
    });
    false
}
