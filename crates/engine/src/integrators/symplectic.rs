//! Semi-implicit (symplectic) Euler: `v₁ = v₀ + h a(x₀, v₀)`, then
//! `x₁ = x₀ + h v₁`. First order, but symplectic: on a conservative system its
//! energy error oscillates and stays bounded instead of drifting.

use super::{flat, flat_mut, Dynamics};
use crate::parallel::by_pieces;
use crate::particle::State;

/// One symplectic Euler step of size `h` from time `t`.
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) {
    let f = &mut d.scratch.force;
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let (w3, f) = (&d.particles.inv_mass3, &*f);
    // Each coordinate on its own, as one flat loop the compiler vectorises:
    // the same operations on each as on the vector (v + (h w) f).
    by_pieces([&mut to.pos, &mut to.vel], |first, [x1, v1]| {
        let r = first..first + x1.len();
        let (x0, v0, f) = (
            flat(&from.pos[r.clone()]),
            flat(&from.vel[r.clone()]),
            flat(&f[r]),
        );
        let w = &w3[3 * first..3 * first + x0.len()];
        let (x1, v1) = (flat_mut(x1), flat_mut(v1));
        let new = x1.iter_mut().zip(v1.iter_mut());
        let old = x0.iter().zip(v0).zip(w.iter().zip(f));
        for ((x1, v1), ((x0, v0), (w, f))) in new.zip(old) {
            let v = *v0 + (h * w) * *f;
            *v1 = v;
            *x1 = *x0 + h * v;
        }
    });
}
