//! Semi-implicit (symplectic) Euler: `v₁ = v₀ + h a(x₀, v₀)`, then
//! `x₁ = x₀ + h v₁`. First order, but symplectic: on a conservative system its
//! energy error oscillates and stays bounded instead of drifting.

use super::{flat, flat_mut, Dynamics};
use crate::parallel::by_pieces;
use crate::particle::State;

/// Worlds with fewer particles take the particle-by-particle loops (here
/// and in RK4); from about this size the flat loops, which the compiler
/// vectorises, are faster (chain-64: 0.55-0.59 ms flat, 0.65 ms by particle).
pub(crate) const SMALL: usize = 16;

/// One symplectic Euler step of size `h` from time `t`; true if it knows
/// every new coordinate to be finite (see [`super::integrate`]).
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) -> bool {
    let f = &mut d.scratch.force;
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let (w3, f) = (&d.particles.inv_mass3, &*f);
    if from.pos.len() < SMALL {
        // A small world: particle by particle, as vectors, so that the
        // positions are stored as the force loops read them (x and y
        // together, then z) and each read is served from the store just
        // made instead of waiting for it to reach the cache; and checked
        // for finiteness here, where the values are in registers. The
        // same operations on each coordinate as below, so the same bits.
        let w = &d.particles.inv_mass;
        let n = from.pos.len();
        let (x0, v0, f, w) = (&from.pos[..n], &from.vel[..n], &f[..n], &w[..n]);
        let (x1, v1) = (&mut to.pos[..n], &mut to.vel[..n]);
        let mut finite = true;
        for i in 0..n {
            let v = v0[i] + f[i] * (h * w[i]);
            let x = x0[i] + v * h;
            v1[i] = v;
            x1[i] = x;
            finite &= v.is_finite() & x.is_finite();
        }
        return finite;
    }
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
    false
}
