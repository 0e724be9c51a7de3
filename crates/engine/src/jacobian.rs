//! The derivatives of forces with respect to positions and velocities, as the
//! implicit integrator needs them (Baraff & Witkin 1998, "Large steps in
//! cloth simulation").
//!
//! A force that can give its Jacobian implements
//! [`Force::jacobian`](crate::Force::jacobian) by calling [`Jacobian::pair`],
//! [`Jacobian::single`] or [`Jacobian::block`] with its 3×3 blocks of
//! `∂f/∂x` and `∂f/∂v`. The integrator then solves
//! `(M − h ∂f/∂v − h² ∂f/∂x) Δv = h (f₀ + h ∂f/∂x v₀)` for the change of
//! velocity over the step, by conjugate gradients, so the blocks must make
//! `−∂f/∂x` and `−∂f/∂v` symmetric and positive semi-definite. A
//! conservative force's `∂f/∂x` is minus the Hessian of its potential, so it
//! is symmetric; where it is not definite (a spring under compression) give
//! the nearest definite matrix (see the springs): the step stays stable and
//! first-order, only Newton's correction is approximate there.

use glam::{DMat3, DVec3};

/// One equal-and-opposite interaction: off-diagonal blocks `−S` at (a, b)
/// and (b, a).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pair {
    pub a: u32,
    pub b: u32,
    pub s: DMat3,
}

/// One central interaction: off-diagonal blocks `−(α n nᵀ + β I)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Central {
    pub a: u32,
    pub b: u32,
    pub n: DVec3,
    pub alpha: f64,
    pub beta: f64,
}

/// One general off-diagonal block `S` at (i, j).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Block {
    pub i: u32,
    pub j: u32,
    pub s: DMat3,
}

/// The linearised forces of one implicit step, gathered as the system matrix
/// `A = M + S` with `S = −(h² ∂f/∂x + h ∂f/∂v)`, and the right-hand side's
/// term `h² ∂f/∂x v₀`.
#[derive(Clone, Debug, Default)]
pub struct Jacobian {
    h: f64,
    vel: Vec<DVec3>,
    /// `h² (∂f/∂x) v₀` per particle.
    pub(crate) rhs: Vec<DVec3>,
    /// Each particle's own block of `S`.
    pub(crate) diag: Vec<DMat3>,
    pub(crate) central: Vec<Central>,
    pub(crate) pairs: Vec<Pair>,
    pub(crate) blocks: Vec<Block>,
}

impl Jacobian {
    /// Starts a step of `h` from the velocities `vel`.
    pub(crate) fn begin(&mut self, h: f64, vel: &[DVec3]) {
        let n = vel.len();
        self.h = h;
        self.vel.clear();
        self.vel.extend_from_slice(vel);
        self.rhs.clear();
        self.rhs.resize(n, DVec3::ZERO);
        self.diag.clear();
        self.diag.resize(n, DMat3::ZERO);
        self.central.clear();
        self.pairs.clear();
        self.blocks.clear();
    }

    /// The step, s.
    pub fn h(&self) -> f64 {
        self.h
    }

    #[inline(always)]
    fn s(&self, dfdx: DMat3, dfdv: DMat3) -> DMat3 {
        -(dfdx * (self.h * self.h) + dfdv * self.h)
    }

    /// An interaction between particles `a` and `b` whose force on `a`
    /// depends on `x_a − x_b` and `v_a − v_b` and whose force on `b` is its
    /// opposite (a spring, a contact): `dfdx = ∂f_a/∂x_a` and
    /// `dfdv = ∂f_a/∂v_a`, each symmetric. The other three blocks follow.
    #[inline]
    pub fn pair(&mut self, a: usize, b: usize, dfdx: DMat3, dfdv: DMat3) {
        let s = self.s(dfdx, dfdv);
        let kv = dfdx.mul_vec3(self.vel[a] - self.vel[b]) * (self.h * self.h);
        self.rhs[a] += kv;
        self.rhs[b] -= kv;
        self.diag[a] += s;
        self.diag[b] += s;
        self.pairs.push(Pair {
            a: a as u32,
            b: b as u32,
            s,
        });
    }

    /// A central interaction along the unit vector `n` between `a` and `b`
    /// (a spring): [`pair`](Jacobian::pair) with
    /// `∂f_a/∂x_a = −(k_along n nᵀ + k_across (I − n nᵀ))` and
    /// `∂f_a/∂v_a = −c_along n nᵀ`, stored and applied in that form (five
    /// numbers instead of two 3×3 matrices).
    #[inline]
    pub fn central(
        &mut self,
        a: usize,
        b: usize,
        n: DVec3,
        k_along: f64,
        k_across: f64,
        c_along: f64,
    ) {
        let h = self.h;
        let u = self.vel[a] - self.vel[b];
        let nu = n.dot(u);
        // −h² ∂f/∂x u = h² (k_along n (n·u) + k_across (u − n (n·u))).
        let kv = -(n * (nu * (k_along - k_across)) + u * k_across) * (h * h);
        self.rhs[a] += kv;
        self.rhs[b] -= kv;
        let alpha = h * h * (k_along - k_across) + h * c_along;
        let beta = h * h * k_across;
        let s = DMat3::from_cols(n * (n.x * alpha), n * (n.y * alpha), n * (n.z * alpha))
            + DMat3::from_diagonal(DVec3::splat(beta));
        self.diag[a] += s;
        self.diag[b] += s;
        self.central.push(Central {
            a: a as u32,
            b: b as u32,
            n,
            alpha,
            beta,
        });
    }

    /// A force on particle `i` alone (drag): `dfdx = ∂f_i/∂x_i`,
    /// `dfdv = ∂f_i/∂v_i`.
    #[inline]
    pub fn single(&mut self, i: usize, dfdx: DMat3, dfdv: DMat3) {
        let s = self.s(dfdx, dfdv);
        self.rhs[i] += dfdx.mul_vec3(self.vel[i]) * (self.h * self.h);
        self.diag[i] += s;
    }

    /// Any block: `dfdx = ∂f_i/∂x_j`, `dfdv = ∂f_i/∂v_j`. A force adding
    /// the block (i, j) must add the transposed block at (j, i) too.
    #[inline]
    pub fn block(&mut self, i: usize, j: usize, dfdx: DMat3, dfdv: DMat3) {
        if i == j {
            return self.single(i, dfdx, dfdv);
        }
        let s = self.s(dfdx, dfdv);
        self.rhs[i] += dfdx.mul_vec3(self.vel[j]) * (self.h * self.h);
        self.blocks.push(Block {
            i: i as u32,
            j: j as u32,
            s,
        });
    }

    /// `out = (M + S) p` for the particles' masses `mass`.
    pub(crate) fn apply(&self, mass: &[f64], p: &[DVec3], out: &mut [DVec3]) {
        for (((o, &m), d), &p) in out.iter_mut().zip(mass).zip(&self.diag).zip(p) {
            *o = p * m + d.mul_vec3(p);
        }
        // Springs sharing their first end come in runs (a mesh lists a
        // particle's springs together): keep that end's sum in a register
        // for the run instead of storing and reloading it every spring.
        let (mut run, mut acc) = (usize::MAX, DVec3::ZERO);
        for e in &self.central {
            let (a, b) = (e.a as usize, e.b as usize);
            if a != run {
                if run != usize::MAX {
                    out[run] = acc;
                }
                run = a;
                acc = out[a];
            }
            let (pa, pb) = (p[a], p[b]);
            acc -= e.n * (e.alpha * e.n.dot(pb)) + pb * e.beta;
            if b == run {
                acc -= e.n * (e.alpha * e.n.dot(pa)) + pa * e.beta;
            } else {
                out[b] -= e.n * (e.alpha * e.n.dot(pa)) + pa * e.beta;
            }
        }
        if run != usize::MAX {
            out[run] = acc;
        }
        for e in &self.pairs {
            let (a, b) = (e.a as usize, e.b as usize);
            out[a] -= e.s.mul_vec3(p[b]);
            out[b] -= e.s.mul_vec3(p[a]);
        }
        for e in &self.blocks {
            out[e.i as usize] += e.s.mul_vec3(p[e.j as usize]);
        }
    }
}
