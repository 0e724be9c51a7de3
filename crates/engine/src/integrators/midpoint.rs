//! Explicit midpoint method: a half Euler step to the midpoint, forces
//! re-evaluated there, and the full step taken with the midpoint derivative.
//! Second order.

use super::Dynamics;
use crate::parallel::by_pieces;
use crate::particle::State;

/// One midpoint step of size `h` from time `t`.
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) -> bool {
    let split = !d.forces.one_piece;
    let f = &mut d.scratch.force;
    let w = &d.particles.inv_mass;
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let half = 0.5 * h;
    // The trial (midpoint) state lives in `to` until the final update.
    let fr = &*f;
    by_pieces(split, [&mut to.pos, &mut to.vel], |first, [x, v]| {
        for (k, (x, v)) in x.iter_mut().zip(v.iter_mut()).enumerate() {
            let i = first + k;
            *x = from.pos[i] + half * from.vel[i];
            *v = from.vel[i] + (half * w[i]) * fr[i];
        }
    });
    d.forces
        .evaluate(t + half, h, &to.pos, &to.vel, d.particles, f);
    let fr = &*f;
    by_pieces(split, [&mut to.pos, &mut to.vel], |first, [x, v]| {
        for (k, (x, v)) in x.iter_mut().zip(v.iter_mut()).enumerate() {
            let i = first + k;
            let vm = *v;
            *x = from.pos[i] + h * vm;
            *v = from.vel[i] + (h * w[i]) * fr[i];
        }
    });
    false
}
