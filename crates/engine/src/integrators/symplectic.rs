//! Semi-implicit (symplectic) Euler: `v₁ = v₀ + h a(x₀, v₀)`, then
//! `x₁ = x₀ + h v₁`. First order, but symplectic: on a conservative system its
//! energy error oscillates and stays bounded instead of drifting.

use super::{all_finite, flat, flat_mut, Coord, Dynamics, Finish, Settled, Written, SMALL};
use crate::parallel::{by_pieces, fold_by_pieces};
use crate::particle::State;
use crate::simd::{chosen, Use};
use glam::DVec3;

/// One symplectic Euler step of size `h` from time `t`; true if it knows
/// every new coordinate to be finite: [`super::integrate`] with
/// symplectic Euler (which also takes properties filled in by hand).
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) -> bool {
    super::integrate(super::IntegratorKind::Symplectic, d, t, h, from, to)
}

/// [`step`], then `finish` on each piece it wrote (see
/// [`super::integrate_then`]).
pub(crate) fn step_then(
    d: &mut Dynamics,
    t: f64,
    h: f64,
    from: &State,
    to: &mut State,
    finish: Option<Finish>,
) -> Written {
    let split = !d.forces.one_piece;
    let f = &mut d.scratch.force;
    let n = from.pos.len();
    if n >= SMALL && d.forces.can_evaluate_then(n) {
        // Each run of particles is updated (and finished) as soon as its
        // forces are complete, while they are in the cache, in no pass of
        // its own (on each thread, its own particles).
        let w3 = &d.particles.inv_mass3;
        let settled = d.forces.evaluate_then(
            t,
            h,
            &from.pos,
            &from.vel,
            d.particles,
            f,
            [&mut to.pos[..], &mut to.vel[..]],
            |first, f, [x1, v1]| {
                update_piece(first, from, f, w3, h, [&mut *x1, &mut *v1]);
                finish.map_or(Settled::FINE, |finish| finish(first, x1, v1))
            },
            Settled::and,
        );
        return match finish {
            Some(_) => Written::Settled(settled.unwrap_or(Settled::FINE)),
            None => Written::Known(false),
        };
    }
    if from.pos.len() < SMALL {
        let finite = step_small(d, t, h, from, to);
        return match finish {
            Some(finish) => Written::Settled(finish(0, &mut to.pos, &mut to.vel)),
            None => Written::Known(finite),
        };
    }
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let f = &*f;
    let w3 = &d.particles.inv_mass3;
    let piece = |first: usize, out: [&mut [DVec3]; 2]| {
        let r = first..first + out[0].len();
        update_piece(first, from, &f[r], w3, h, out);
    };
    let slices = [&mut to.pos[..], &mut to.vel[..]];
    match finish {
        Some(finish) => Written::Settled(fold_by_pieces(
            split,
            slices,
            |first, [x1, v1]| {
                piece(first, [&mut *x1, &mut *v1]);
                finish(first, x1, v1)
            },
            Settled::and,
        )),
        None => {
            by_pieces(split, slices, piece);
            Written::Known(false)
        }
    }
}

/// [`step`] of a world of fewer than [`SMALL`] particles, over the flat
/// coordinates (as a large world's pieces, in one loop); true if every new
/// coordinate is finite. Particle by particle (`DVec3`, one inverse mass
/// each) LLVM vectorised the loop with shuffles across the components:
/// nbody5's step took 72 more instructions, and, alternated on an Intel
/// Xeon (2 cores, 2026-11-30), 2 M steps with the built-in n-body force
/// 0.236 against 0.208 s (medians of 21) and with the tutorial's user
/// force 0.211 against 0.163 s (of 15); only a force that adds nothing
/// (the `step_floor` example) stepped faster particle by particle, 41
/// against 48 ns a step (medians of 10).
#[inline(always)]
pub(crate) fn step_small(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) -> bool {
    let f = &mut d.scratch.force;
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let w3 = &d.particles.inv_mass3;
    update(
        flat(&from.pos),
        flat(&from.vel),
        flat(f),
        w3,
        h,
        flat_mut(&mut to.pos),
        flat_mut(&mut to.vel),
    )
}

/// [`update`] of the particles `first..first + x1.len()` from `from`, with
/// their forces `f` and the per-coordinate inverse masses `w3` of every
/// particle, into `x1`, `v1`: each coordinate on its own, as one flat loop
/// the compiler vectorises.
#[inline(always)]
fn update_piece(
    first: usize,
    from: &State,
    f: &[DVec3],
    w3: &[f64],
    h: f64,
    [x1, v1]: [&mut [DVec3]; 2],
) {
    let r = first..first + x1.len();
    let (x0, v0) = (flat(&from.pos[r.clone()]), flat(&from.vel[r]));
    let w = &w3[3 * first..3 * first + x0.len()];
    chosen(
        Use::Updates,
        #[inline(always)]
        || update(x0, v0, flat(f), w, h, flat_mut(x1), flat_mut(v1)),
    );
}

/// `v₁ = v₀ + f (h w)`, `x₁ = x₀ + v₁ h` for each element (`w` the inverse
/// mass of each); true if everything written is finite (the flat loops
/// drop the answer, and with it the test).
#[inline(always)]
fn update<T: Coord>(
    x0: &[T],
    v0: &[T],
    f: &[T],
    w: &[f64],
    h: f64,
    x1: &mut [T],
    v1: &mut [T],
) -> bool {
    let n = x1.len();
    let (x0, v0, f, w, v1) = (&x0[..n], &v0[..n], &f[..n], &w[..n], &mut v1[..n]);
    let mut not_finite = 0;
    for i in 0..n {
        let v = v0[i] + f[i] * (h * w[i]);
        let x = x0[i] + v * h;
        v1[i] = v;
        x1[i] = x;
        not_finite |= v.not_finite() | x.not_finite();
    }
    all_finite(not_finite)
}

#[cfg(test)]
mod tests {
    use super::super::{assert_same_on_every_width, bits, on, test_numbers};
    use super::update;

    /// The flat update gives the same bits compiled for every instruction
    /// set this CPU has (a length that is no multiple of any vector).
    #[test]
    fn every_width_updates_to_the_same_bits() {
        let n = 3 * 37;
        let (x0, v0, f) = (test_numbers(n, 1), test_numbers(n, 2), test_numbers(n, 3));
        let w: Vec<f64> = test_numbers(n, 4).iter().map(|w| w.abs()).collect();
        assert_same_on_every_width(|width| {
            let (mut x1, mut v1) = (vec![0.0; n], vec![0.0; n]);
            on(
                width,
                #[inline(always)]
                || update(&x0, &v0, &f, &w, 1e-3, &mut x1, &mut v1),
            );
            bits([x1, v1])
        });
    }
}
