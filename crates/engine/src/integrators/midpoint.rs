//! Explicit midpoint method: a half Euler step to the midpoint, forces
//! re-evaluated there, and the full step taken with the midpoint derivative.
//! Second order.

use super::Dynamics;
use crate::particle::State;

/// One midpoint step of size `h` from time `t`.
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) {
    let f = &mut d.scratch.force;
    let w = &d.particles.inv_mass;
    let n = from.pos.len();
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let half = 0.5 * h;
    // The trial (midpoint) state lives in `to` until the final update.
    for i in 0..n {
        to.pos[i] = from.pos[i] + half * from.vel[i];
        to.vel[i] = from.vel[i] + (half * w[i]) * f[i];
    }
    d.forces
        .evaluate(t + half, h, &to.pos, &to.vel, d.particles, f);
    for i in 0..n {
        let vm = to.vel[i];
        to.pos[i] = from.pos[i] + h * vm;
        to.vel[i] = from.vel[i] + (h * w[i]) * f[i];
    }
}
