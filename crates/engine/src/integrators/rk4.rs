//! Classic fourth-order Runge–Kutta on the state (x, v) with derivative
//! (v, a(x, v)): four trial states, forces re-evaluated at each,
//! `x₁ = x₀ + h/6 (v₁ + 2v₂ + 2v₃ + v₄)`, `v₁ = v₀ + h/6 (a₁ + 2a₂ + 2a₃ + a₄)`.
//! The thesis's default integrator.

use super::{all_finite, flat, flat_mut, Coord, Dynamics, Finish, Settled, Written, SMALL};
use crate::parallel::{by_pieces, fold_by_pieces};
use crate::particle::State;
use crate::simd::{chosen, Use};
use glam::DVec3;

/// One RK4 step of size `h` from time `t`; true if it knows every new
/// coordinate to be finite: [`super::integrate`] with RK4 (which also
/// takes properties filled in by hand).
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) -> bool {
    super::integrate(super::IntegratorKind::Rk4, d, t, h, from, to)
}

/// [`step`], then `finish` on each piece of the last stage (see
/// [`super::integrate_then`]).
pub(crate) fn step_then(
    d: &mut Dynamics,
    t: f64,
    h: f64,
    from: &State,
    to: &mut State,
    finish: Option<Finish>,
) -> Written {
    let s = &mut *d.scratch;
    let (x0, v0) = (&from.pos, &from.vel);
    let half = 0.5 * h;
    let start = Start {
        x0,
        v0,
        w: &d.particles.inv_mass,
        w3: &d.particles.inv_mass3,
        split: !d.forces.one_piece,
    };
    // Stage 1 at (x0, v0). Trial states live in `to`; `dx`, `dv` accumulate
    // the weighted derivatives.
    d.forces.evaluate(t, h, x0, v0, d.particles, &mut s.force);
    let mut trial = [&mut to.pos, &mut to.vel, &mut s.dx, &mut s.dv];
    start.run::<FIRST>(half, &s.force, &mut trial, None);
    // Stages 2 and 3 at the midpoint.
    for step_to in [half, h] {
        let [x, v, ..] = &trial;
        d.forces
            .evaluate(t + half, h, x, v, d.particles, &mut s.force);
        start.run::<MIDDLE>(step_to, &s.force, &mut trial, None);
    }
    // Stage 4 at the end of the step, then the weighted sum.
    let [x, v, ..] = &trial;
    d.forces.evaluate(t + h, h, x, v, d.particles, &mut s.force);
    start.run::<LAST>(h / 6.0, &s.force, &mut trial, finish)
}

/// The stages' updates (a constant parameter, so that each is compiled on
/// its own): the first and middle stages set the trial state to `x0 + v·s`
/// with their step `s`, the last takes the weighted sum with `s = h/6`.
const FIRST: u8 = 0;
const MIDDLE: u8 = 1;
const LAST: u8 = 2;

/// One stage's update of the trial state `x`, `v` and the sums `dx`, `dv`
/// from the start `x0`, `v0`, the forces `f` and each element's inverse
/// mass `w`; the last stage answers whether everything it wrote is finite
/// (the flat loops drop the answer, and with it the test).
#[inline(always)]
fn stage<T: Coord, const STAGE: u8>(
    s: f64,
    [x0, v0, f]: [&[T]; 3],
    w: &[f64],
    [x, v, dx, dv]: [&mut [T]; 4],
) -> bool {
    let n = x.len();
    let (x0, v0, f, w) = (&x0[..n], &v0[..n], &f[..n], &w[..n]);
    let (v, dx, dv) = (&mut v[..n], &mut dx[..n], &mut dv[..n]);
    match STAGE {
        FIRST => {
            let half = s;
            for i in 0..n {
                let a = f[i] * w[i];
                dx[i] = v0[i];
                dv[i] = a;
                x[i] = x0[i] + v0[i] * half;
                v[i] = v0[i] + a * half;
            }
            false
        }
        MIDDLE => {
            let step_to = s;
            for i in 0..n {
                let a = f[i] * w[i];
                let vi = v[i];
                dx[i] += vi * 2.0;
                dv[i] += a * 2.0;
                x[i] = x0[i] + vi * step_to;
                v[i] = v0[i] + a * step_to;
            }
            false
        }
        _ => {
            let sixth = s;
            let mut not_finite = 0;
            for i in 0..n {
                let a = f[i] * w[i];
                let x1 = x0[i] + (dx[i] + v[i]) * sixth;
                let v1 = v0[i] + (dv[i] + a) * sixth;
                x[i] = x1;
                v[i] = v1;
                not_finite |= x1.not_finite() | v1.not_finite();
            }
            all_finite(not_finite)
        }
    }
}

/// The start of the step and the inverse masses (one per particle, and
/// one per coordinate), read by every stage.
#[derive(Clone, Copy)]
struct Start<'a> {
    x0: &'a [DVec3],
    v0: &'a [DVec3],
    w: &'a [f64],
    w3: &'a [f64],
    /// Split a large world's loops over the pool's threads.
    split: bool,
}

impl Start<'_> {
    /// Runs stage `STAGE` with its step `s` over the `trial` state (x, v,
    /// dx, dv) with the forces `f`: particle by particle in a small world,
    /// else as flat arrays of every coordinate of every particle in turn,
    /// in pieces (one per thread for a large world), then `finish` on each
    /// piece (the last stage only).
    #[inline(always)]
    fn run<const STAGE: u8>(
        &self,
        s: f64,
        f: &[DVec3],
        trial: &mut [&mut Vec<DVec3>; 4],
        finish: Option<Finish>,
    ) -> Written {
        let [x, v, dx, dv] = trial;
        if self.x0.len() < SMALL {
            let finite = stage::<_, STAGE>(s, [self.x0, self.v0, f], self.w, [x, v, dx, dv]);
            return match finish {
                Some(finish) => Written::Settled(finish(0, x, v)),
                None => Written::Known(finite),
            };
        }
        let piece = |first: usize, [x, v, dx, dv]: [&mut [DVec3]; 4]| {
            let r = first..first + x.len();
            let start = [
                flat(&self.x0[r.clone()]),
                flat(&self.v0[r.clone()]),
                flat(&f[r]),
            ];
            let w = &self.w3[3 * first..3 * first + 3 * x.len()];
            let trial = [flat_mut(x), flat_mut(v), flat_mut(dx), flat_mut(dv)];
            chosen(
                Use::Updates,
                #[inline(always)]
                || stage::<_, STAGE>(s, start, w, trial),
            );
        };
        let slices = [&mut x[..], &mut v[..], &mut dx[..], &mut dv[..]];
        match finish {
            Some(finish) => Written::Settled(fold_by_pieces(
                self.split,
                slices,
                |first, [x, v, dx, dv]| {
                    piece(first, [&mut *x, &mut *v, dx, dv]);
                    finish(first, x, v)
                },
                Settled::and,
            )),
            None => {
                by_pieces(self.split, slices, piece);
                Written::Known(false)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{assert_same_on_every_width, bits, on, test_numbers};
    use super::{stage, FIRST, LAST, MIDDLE};

    /// Every stage's flat update gives the same bits compiled for every
    /// instruction set this CPU has.
    #[test]
    fn every_width_updates_to_the_same_bits() {
        let n = 3 * 37;
        let (x0, v0, f) = (test_numbers(n, 5), test_numbers(n, 6), test_numbers(n, 7));
        let w: Vec<f64> = test_numbers(n, 8).iter().map(|w| w.abs()).collect();
        assert_same_on_every_width(|width| {
            let mut t = [9, 10, 11, 12].map(|seed| test_numbers(n, seed));
            let [x, v, dx, dv] = &mut t;
            on(
                width,
                #[inline(always)]
                || {
                    stage::<f64, FIRST>(5e-4, [&x0, &v0, &f], &w, [x, v, dx, dv]);
                    stage::<f64, MIDDLE>(1e-3, [&x0, &v0, &f], &w, [x, v, dx, dv]);
                    stage::<f64, LAST>(1e-3 / 6.0, [&x0, &v0, &f], &w, [x, v, dx, dv]);
                },
            );
            bits(t)
        });
    }
}
