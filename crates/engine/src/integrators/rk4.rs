//! Classic fourth-order Runge–Kutta on the state (x, v) with derivative
//! (v, a(x, v)): four trial states, forces re-evaluated at each,
//! `x₁ = x₀ + h/6 (v₁ + 2v₂ + 2v₃ + v₄)`, `v₁ = v₀ + h/6 (a₁ + 2a₂ + 2a₃ + a₄)`.
//! The thesis's default integrator.

use super::{flat, flat_mut, Dynamics};
use crate::parallel::by_pieces;
use crate::particle::State;
use glam::DVec3;

/// One RK4 step of size `h` from time `t`; true if it knows every new
/// coordinate to be finite (see [`super::integrate`]).
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) -> bool {
    if from.pos.len() < super::symplectic::SMALL {
        return small(d, t, h, from, to);
    }
    let w = &d.particles.inv_mass3;
    let s = &mut *d.scratch;
    let (x0, v0) = (&from.pos, &from.vel);
    let half = 0.5 * h;

    // Stage 1 at (x0, v0). Trial states live in `to`; `dx`, `dv` accumulate
    // the weighted derivatives.
    d.forces.evaluate(t, h, x0, v0, d.particles, &mut s.force);
    let start = Start { x0, v0, w };
    let f = &s.force;
    by_pieces(
        [&mut to.pos, &mut to.vel, &mut s.dx, &mut s.dv],
        |first, [x, v, dx, dv]| {
            let (n, [x0, v0, f], w) = start.piece(first, x.len(), f);
            let (x, v) = (&mut flat_mut(x)[..n], &mut flat_mut(v)[..n]);
            let (dx, dv) = (&mut flat_mut(dx)[..n], &mut flat_mut(dv)[..n]);
            for i in 0..n {
                let a = w[i] * f[i];
                dx[i] = v0[i];
                dv[i] = a;
                x[i] = x0[i] + half * v0[i];
                v[i] = v0[i] + half * a;
            }
        },
    );
    // Stages 2 and 3 at the midpoint.
    for step_to in [half, h] {
        d.forces
            .evaluate(t + half, h, &to.pos, &to.vel, d.particles, &mut s.force);
        let f = &s.force;
        by_pieces(
            [&mut to.pos, &mut to.vel, &mut s.dx, &mut s.dv],
            |first, [x, v, dx, dv]| {
                let (n, [x0, v0, f], w) = start.piece(first, x.len(), f);
                let (x, v) = (&mut flat_mut(x)[..n], &mut flat_mut(v)[..n]);
                let (dx, dv) = (&mut flat_mut(dx)[..n], &mut flat_mut(dv)[..n]);
                for i in 0..n {
                    let a = w[i] * f[i];
                    let vi = v[i];
                    dx[i] += 2.0 * vi;
                    dv[i] += 2.0 * a;
                    x[i] = x0[i] + step_to * vi;
                    v[i] = v0[i] + step_to * a;
                }
            },
        );
    }
    // Stage 4 at the end of the step, then the weighted sum.
    d.forces
        .evaluate(t + h, h, &to.pos, &to.vel, d.particles, &mut s.force);
    let sixth = h / 6.0;
    let f = &s.force;
    by_pieces(
        [&mut to.pos, &mut to.vel, &mut s.dx, &mut s.dv],
        |first, [x, v, dx, dv]| {
            let (n, [x0, v0, f], w) = start.piece(first, x.len(), f);
            let (x, v) = (&mut flat_mut(x)[..n], &mut flat_mut(v)[..n]);
            let (dx, dv) = (&mut flat_mut(dx)[..n], &mut flat_mut(dv)[..n]);
            for i in 0..n {
                let a = w[i] * f[i];
                let vi = v[i];
                x[i] = x0[i] + sixth * (dx[i] + vi);
                v[i] = v0[i] + sixth * (dv[i] + a);
            }
        },
    );
    false
}

/// [`step`] for a small world: particle by particle, as vectors (see
/// `symplectic::SMALL`), the same operations on each coordinate, so the
/// same bits; the last stage checks finiteness as it writes.
fn small(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) -> bool {
    let s = &mut *d.scratch;
    let n = from.pos.len();
    let (x0, v0, w) = (&from.pos[..n], &from.vel[..n], &d.particles.inv_mass[..n]);
    let half = 0.5 * h;
    d.forces.evaluate(t, h, x0, v0, d.particles, &mut s.force);
    {
        let (f, x, v) = (&s.force[..n], &mut to.pos[..n], &mut to.vel[..n]);
        let (dx, dv) = (&mut s.dx[..n], &mut s.dv[..n]);
        for i in 0..n {
            let a = f[i] * w[i];
            dx[i] = v0[i];
            dv[i] = a;
            x[i] = x0[i] + v0[i] * half;
            v[i] = v0[i] + a * half;
        }
    }
    for step_to in [half, h] {
        d.forces
            .evaluate(t + half, h, &to.pos, &to.vel, d.particles, &mut s.force);
        let (f, x, v) = (&s.force[..n], &mut to.pos[..n], &mut to.vel[..n]);
        let (dx, dv) = (&mut s.dx[..n], &mut s.dv[..n]);
        for i in 0..n {
            let a = f[i] * w[i];
            let vi = v[i];
            dx[i] += vi * 2.0;
            dv[i] += a * 2.0;
            x[i] = x0[i] + vi * step_to;
            v[i] = v0[i] + a * step_to;
        }
    }
    d.forces
        .evaluate(t + h, h, &to.pos, &to.vel, d.particles, &mut s.force);
    let sixth = h / 6.0;
    let (f, x, v) = (&s.force[..n], &mut to.pos[..n], &mut to.vel[..n]);
    let (dx, dv) = (&s.dx[..n], &s.dv[..n]);
    let mut finite = true;
    for i in 0..n {
        let a = f[i] * w[i];
        let x1 = x0[i] + (dx[i] + v[i]) * sixth;
        let v1 = v0[i] + (dv[i] + a) * sixth;
        x[i] = x1;
        v[i] = v1;
        finite &= x1.is_finite() & v1.is_finite();
    }
    finite
}

/// The start of the step and the inverse masses (one per coordinate), read
/// by every stage; each stage's loop runs over every coordinate of every
/// particle as one flat array, the same operations on each coordinate as on
/// the vector.
#[derive(Clone, Copy)]
struct Start<'a> {
    x0: &'a [DVec3],
    v0: &'a [DVec3],
    w: &'a [f64],
}

impl<'a> Start<'a> {
    /// Particles `first..first + n` of the start, the forces `f` and the
    /// inverse masses, as flat arrays of each coordinate in turn, each
    /// exactly `3n` long (so the loops need no bounds checks).
    #[inline(always)]
    fn piece<'f>(
        &self,
        first: usize,
        n: usize,
        f: &'f [DVec3],
    ) -> (usize, [&'f [f64]; 3], &'f [f64])
    where
        'a: 'f,
    {
        let r = first..first + n;
        (
            3 * n,
            [
                flat(&self.x0[r.clone()]),
                flat(&self.v0[r.clone()]),
                flat(&f[r]),
            ],
            &self.w[3 * first..3 * (first + n)],
        )
    }
}
