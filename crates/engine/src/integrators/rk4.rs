//! Classic fourth-order Runge–Kutta on the state (x, v) with derivative
//! (v, a(x, v)): four trial states, forces re-evaluated at each,
//! `x₁ = x₀ + h/6 (v₁ + 2v₂ + 2v₃ + v₄)`, `v₁ = v₀ + h/6 (a₁ + 2a₂ + 2a₃ + a₄)`.
//! The thesis's default integrator.

use super::Dynamics;
use crate::particle::State;

/// One RK4 step of size `h` from time `t`.
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) {
    let n = from.pos.len();
    let w = &d.particles.inv_mass;
    let s = &mut *d.scratch;
    let (x0, v0) = (&from.pos, &from.vel);
    let half = 0.5 * h;

    // Stage 1 at (x0, v0). Trial states live in `to`; `dx`, `dv` accumulate
    // the weighted derivatives.
    d.forces.evaluate(t, h, x0, v0, d.particles, &mut s.force);
    for i in 0..n {
        let a = w[i] * s.force[i];
        s.dx[i] = v0[i];
        s.dv[i] = a;
        to.pos[i] = x0[i] + half * v0[i];
        to.vel[i] = v0[i] + half * a;
    }
    // Stages 2 and 3 at the midpoint.
    for step_to in [half, h] {
        d.forces
            .evaluate(t + half, h, &to.pos, &to.vel, d.particles, &mut s.force);
        for i in 0..n {
            let a = w[i] * s.force[i];
            let v = to.vel[i];
            s.dx[i] += 2.0 * v;
            s.dv[i] += 2.0 * a;
            to.pos[i] = x0[i] + step_to * v;
            to.vel[i] = v0[i] + step_to * a;
        }
    }
    // Stage 4 at the end of the step, then the weighted sum.
    d.forces
        .evaluate(t + h, h, &to.pos, &to.vel, d.particles, &mut s.force);
    let sixth = h / 6.0;
    for i in 0..n {
        let a = w[i] * s.force[i];
        let v = to.vel[i];
        to.pos[i] = x0[i] + sixth * (s.dx[i] + v);
        to.vel[i] = v0[i] + sixth * (s.dv[i] + a);
    }
}
