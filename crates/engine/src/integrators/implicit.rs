//! Implicit (backward) Euler with one Newton step per step (Baraff & Witkin
//! 1998): `v₁ = v₀ + h f(x₁, v₁)/m`, `x₁ = x₀ + h v₁`, with the forces
//! linearised about the start of the step,
//!
//! `(M − h ∂f/∂v − h² ∂f/∂x) Δv = h (f₀ + h ∂f/∂x v₀)`, `v₁ = v₀ + Δv`.
//!
//! The forces that give their Jacobian ([`Force::jacobian`]: gravity,
//! springs, angle joints, fluid drag, constant forces) are integrated
//! implicitly; the rest (the floor's reaction, torque motors, user forces
//! without a Jacobian) enter only through `f₀`, explicitly. The linear system
//! is solved matrix-free by conjugate gradients preconditioned with each
//! particle's 3×3 diagonal block; sums are taken in a fixed order, so a step
//! gives the same bits every time. First order; for linear springs it is
//! stable at any step, and it damps every mode by `1/√(1 + ω²h²)` a step.
//!
//! [`Force::jacobian`]: crate::Force::jacobian

use super::Dynamics;
use crate::force::ForceContext;
use crate::jacobian::Jacobian;
use crate::particle::State;
use glam::{DMat3, DVec3};

/// How the implicit step solves its linear system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solver {
    /// Conjugate gradients stop when the preconditioned residual has fallen
    /// to this fraction of the right-hand side's.
    pub tolerance: f64,
    /// And stop after this many iterations at most (the step then uses the
    /// last iterate: still a stable, slightly less accurate step).
    pub max_iterations: u32,
}

impl Default for Solver {
    fn default() -> Self {
        Solver {
            tolerance: 1e-9,
            max_iterations: 2000,
        }
    }
}

/// The implicit step's buffers.
#[derive(Clone, Debug, Default)]
pub struct Buffers {
    /// The linearised forces.
    pub jacobian: Jacobian,
    b: Vec<DVec3>,
    x: Vec<DVec3>,
    r: Vec<DVec3>,
    z: Vec<DVec3>,
    p: Vec<DVec3>,
    q: Vec<DVec3>,
    precond: Vec<DMat3>,
    /// Conjugate-gradient iterations of the last step.
    pub iterations: u32,
}

fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    // Four lanes in a fixed order: the same bits every time, and short.
    let mut s = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            s[k] += x[k].dot(y[k]);
        }
    }
    for (x, y) in ra.iter().zip(rb) {
        s[0] += x.dot(*y);
    }
    (s[0] + s[1]) + (s[2] + s[3])
}

/// One implicit Euler step of size `h` from time `t`.
pub fn step(d: &mut Dynamics, t: f64, h: f64, from: &State, to: &mut State) -> bool {
    let n = from.len();
    let f = &mut d.scratch.force;
    d.forces
        .evaluate(t, h, &from.pos, &from.vel, d.particles, f);
    let buf = &mut d.scratch.implicit;
    let ctx = ForceContext {
        t,
        dt: h,
        pos: &from.pos,
        vel: &from.vel,
        particles: d.particles,
        gravity: d.forces.g(),
    };
    buf.jacobian.begin(h, &from.vel);
    d.forces.jacobian(&ctx, &mut buf.jacobian);
    let p = d.particles;
    for v in [
        &mut buf.b, &mut buf.x, &mut buf.r, &mut buf.z, &mut buf.p, &mut buf.q,
    ] {
        v.clear();
        v.resize(n, DVec3::ZERO);
    }
    buf.precond.clear();
    buf.precond.resize(n, DMat3::ZERO);
    let jac = &buf.jacobian;
    #[allow(clippy::needless_range_loop)] // six arrays, one index
    for i in 0..n {
        if !p.fixed[i] {
            buf.b[i] = f[i] * h + jac.rhs[i];
            // A mass's own block is M + S_ii: positive definite, invertible.
            buf.precond[i] =
                (DMat3::from_diagonal(DVec3::splat(p.mass[i])) + jac.diag[i]).inverse();
        }
    }
    buf.iterations = conjugate_gradients(buf, &p.mass, &p.fixed, d.solver);
    for i in 0..n {
        let v = from.vel[i] + buf.x[i];
        to.vel[i] = v;
        to.pos[i] = from.pos[i] + h * v;
    }
    false
}

/// Solves `(M + S) x = b` for the moving particles; returns the iterations.
fn conjugate_gradients(buf: &mut Buffers, mass: &[f64], fixed: &[bool], solver: Solver) -> u32 {
    let Buffers {
        jacobian,
        b,
        x,
        r,
        z,
        p,
        q,
        precond,
        ..
    } = buf;
    let precondition = |r: &[DVec3], z: &mut [DVec3]| {
        for ((z, r), m) in z.iter_mut().zip(r).zip(precond.iter()) {
            *z = m.mul_vec3(*r);
        }
    };
    r.copy_from_slice(b);
    precondition(r, z);
    p.copy_from_slice(z);
    let mut rz = dot(r, z);
    let stop = rz * solver.tolerance * solver.tolerance;
    if rz.is_nan() || rz <= 0.0 {
        return 0;
    }
    for it in 1..=solver.max_iterations {
        jacobian.apply(mass, p, q);
        for (q, &f) in q.iter_mut().zip(fixed) {
            if f {
                *q = DVec3::ZERO;
            }
        }
        let pq = dot(p, q);
        if pq.is_nan() || pq <= 0.0 {
            return it; // not positive definite along p: keep what we have
        }
        let alpha = rz / pq;
        for i in 0..x.len() {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
        }
        precondition(r, z);
        let rz_new = dot(r, z);
        if rz_new <= stop {
            return it;
        }
        let beta = rz_new / rz;
        rz = rz_new;
        for (p, z) in p.iter_mut().zip(z.iter()) {
            *p = *z + beta * *p;
        }
    }
    solver.max_iterations
}
