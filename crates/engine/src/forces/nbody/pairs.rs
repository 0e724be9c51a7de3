//! The n-body force with each pair visited once: row `i` adds to body `i`
//! the pull `mⱼ dᵢⱼ / (|dᵢⱼ|² + ε²)^{3/2}` of every body `j > i` and
//! subtracts the reaction `mᵢ dᵢⱼ / (…)^{3/2}` from body `j`, one square
//! root and one division a pair: half the divider's work of summing every
//! ordered pair, and the divider is what bounds this loop. The bodies'
//! positions and masses are laid out as separate x, y, z, m arrays, and
//! vectorised over `j`.
//!
//! Reproducibility, on any number of threads and any CPU:
//! - the rows are cut into [`RANGES`] ranges of about equal work (a fixed
//!   function of the number of bodies, never of the threads; one range
//!   below two tasks' worth of bodies);
//! - a row sums its pulls into [`LANES`] accumulators (accumulator `l` takes
//!   `j ≡ l mod LANES`), reduced in a fixed tree; each range subtracts its
//!   rows' reactions, in row order, from a buffer of its own;
//! - body `k`'s sum is its row's, then the buffers of the ranges that begin
//!   before `k`, in range order;
//! - nothing is fused (no FMA) and each element gets the same operations
//!   whatever the vector width, so AVX-512, AVX2 and plain SSE2 give the
//!   same bits; the ranges may run on any thread.

use crate::parallel::take_front;
use crate::simd::{width, Use, Width};
use glam::DVec3;
use rayon::prelude::*;

/// Accumulators per body (8 f64: one AVX-512 register, two AVX2, four SSE2).
pub const LANES: usize = 8;

/// Below two tasks' worth of bodies the rows stay in one range on the
/// calling thread (waking a thread costs more than a small set's pairs).
const ROWS_PER_TASK: usize = 128;

/// Ranges of rows of a large set, each with its own buffer of reactions:
/// enough to keep 2, 4 or 8 threads evenly busy.
const RANGES: usize = 8;

/// The arrays, kept between steps (no per-step allocation).
#[derive(Clone, Debug, Default)]
pub struct Pairs {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    m: Vec<f64>,
    /// Each body's Σ mⱼ dᵢⱼ / r³ (the acceleration over G), x, y, z.
    pub ax: Vec<f64>,
    pub ay: Vec<f64>,
    pub az: Vec<f64>,
    /// Each range's reactions (`ranges × padded` a coordinate).
    rx: Vec<f64>,
    ry: Vec<f64>,
    rz: Vec<f64>,
    /// The ranges' first rows, and the number of bodies after them.
    bounds: Vec<usize>,
}

impl Pairs {
    /// Copies the bodies `indices` into the arrays, padded to a multiple of
    /// [`LANES`] with massless bodies at the origin.
    pub fn load(&mut self, indices: &[u32], pos: &[DVec3], mass: &[f64]) {
        let n = indices.len();
        let padded = n.div_ceil(LANES) * LANES;
        for v in [&mut self.x, &mut self.y, &mut self.z, &mut self.m] {
            v.clear();
            v.resize(padded, 0.0);
        }
        for (k, &i) in indices.iter().enumerate() {
            let p = pos[i as usize];
            self.x[k] = p.x;
            self.y[k] = p.y;
            self.z[k] = p.z;
            self.m[k] = mass[i as usize];
        }
        for v in [&mut self.ax, &mut self.ay, &mut self.az] {
            v.clear();
            v.resize(n, 0.0);
        }
        if self.bounds.last() != Some(&n) {
            self.bounds = bounds(n);
        }
        // (Zeroed by each range's task, on its thread.)
        let buffers = (self.bounds.len() - 1) * padded;
        for v in [&mut self.rx, &mut self.ry, &mut self.rz] {
            v.resize(buffers, 0.0);
        }
    }

    /// Fills `ax`, `ay`, `az` with softening² `eps2`; in parallel on the
    /// current rayon pool for large sets.
    pub fn sum(&mut self, eps2: f64) {
        self.sum_on(eps2, width(Use::Arithmetic));
    }

    /// [`Pairs::sum`] with the vectors of `width`.
    fn sum_on(&mut self, eps2: f64, width: Width) {
        let n = self.ax.len();
        let padded = self.x.len();
        let src = Bodies {
            x: &self.x,
            y: &self.y,
            z: &self.z,
            m: &self.m,
            eps2,
        };
        // Each range's rows and buffer.
        let mut tasks = Vec::with_capacity(self.bounds.len() - 1);
        let mut own: Out = [&mut self.ax, &mut self.ay, &mut self.az];
        let mut react: Out = [&mut self.rx, &mut self.ry, &mut self.rz];
        for w in self.bounds.windows(2) {
            let rows = w[1] - w[0];
            let own = own.each_mut().map(|a| take_front(a, rows));
            let react = react.each_mut().map(|r| take_front(r, padded));
            tasks.push((w[0], own, react));
        }
        if splits(n) {
            crate::parallel::fork(|| {
                tasks
                    .into_par_iter()
                    .for_each(|(first, own, react)| src.rows(width, first, own, react))
            });
        } else {
            for (first, own, react) in tasks {
                src.rows(width, first, own, react);
            }
        }
        // Each body's reactions, range by range (the ranges that begin
        // before it: the others hold none of its), in pieces of bodies.
        let bounds = &self.bounds[..self.bounds.len() - 1];
        let react = [&self.rx[..], &self.ry[..], &self.rz[..]];
        let add = |first: usize, mut own: [&mut [f64]; 3]| {
            for (c, &b) in bounds.iter().enumerate() {
                let from = c * padded + first;
                for (a, r) in own.iter_mut().zip(react) {
                    let r = &r[from..from + a.len()];
                    let skip = (b + 1).saturating_sub(first);
                    for (a, r) in a.iter_mut().zip(r).skip(skip) {
                        *a += r;
                    }
                }
            }
        };
        if splits(n) {
            crate::parallel::fork(|| {
                self.ax
                    .par_chunks_mut(ROWS_PER_TASK)
                    .zip(self.ay.par_chunks_mut(ROWS_PER_TASK))
                    .zip(self.az.par_chunks_mut(ROWS_PER_TASK))
                    .enumerate()
                    .for_each(|(k, ((ax, ay), az))| add(k * ROWS_PER_TASK, [ax, ay, az]))
            });
        } else {
            add(0, [&mut self.ax, &mut self.ay, &mut self.az]);
        }
    }
}

impl Pairs {
    /// [`Pairs::sum`] for a set of at most [`LANES`] bodies, read straight
    /// from the particles' arrays: no copy into padded lanes, no vectors,
    /// the pairs that pull visited once each. The same operations in the
    /// same order as the kernel, so the same bits: the pairs it leaves out
    /// are those the kernel weighs 0 (a body on itself or one before it,
    /// padding, two at one place unsoftened), whose terms (±0) leave an
    /// accumulator as it was, since one never holds −0 (it starts at +0,
    /// and a sum that cancels to zero is +0). Each size from 2 to
    /// [`LANES`] has its own code (`small::<N>`); a larger set is loaded
    /// and summed by the kernel.
    pub fn sum_small(&mut self, indices: &[u32], pos: &[DVec3], mass: &[f64], eps2: f64) {
        let n = indices.len();
        for v in [&mut self.ax, &mut self.ay, &mut self.az] {
            if v.len() != n {
                v.clear();
                v.resize(n, 0.0);
            }
        }
        let mut out = |k: usize, a: [f64; 3]| {
            (self.ax[k], self.ay[k], self.az[k]) = (a[0], a[1], a[2]);
        };
        if n == 1 {
            out(0, [0.0; 3]);
        } else if !for_small(indices, pos, mass, eps2, &mut out) && n > 0 {
            // More than a block of lanes: the kernel (the same bits).
            self.load(indices, pos, mass);
            self.sum(eps2);
            return;
        }
        // The kernel's buffers are sized again by its next `load`.
        self.bounds.clear();
    }
}

/// For a set of 2 to [`LANES`] bodies, hands `out` each body's Σ mⱼ dᵢⱼ /
/// r³ (x, y, z; by its place in `indices`), summed straight from the
/// particles by code of the set's size ([`small`]), and returns true;
/// returns false, having done nothing, for any other size.
#[inline(always)]
pub(super) fn for_small(
    indices: &[u32],
    pos: &[DVec3],
    mass: &[f64],
    eps2: f64,
    out: &mut impl FnMut(usize, [f64; 3]),
) -> bool {
    const { assert!(LANES == 8, "one arm of `for_small` a size") };
    fn each<const N: usize>(a: [[f64; 3]; N], out: &mut impl FnMut(usize, [f64; 3])) -> bool {
        a.into_iter().enumerate().for_each(|(k, a)| out(k, a));
        true
    }
    match indices.len() {
        2 => each(small::<2>(indices, pos, mass, eps2), out),
        3 => each(small::<3>(indices, pos, mass, eps2), out),
        4 => each(small::<4>(indices, pos, mass, eps2), out),
        5 => each(small::<5>(indices, pos, mass, eps2), out),
        6 => each(small::<6>(indices, pos, mass, eps2), out),
        7 => each(small::<7>(indices, pos, mass, eps2), out),
        8 => each(small::<8>(indices, pos, mass, eps2), out),
        _ => false,
    }
}

/// [`Pairs::sum_small`] for `N` bodies: each body's Σ mⱼ dᵢⱼ / r³ (x, y,
/// z). Every array a fixed size, so the loops unroll and the lanes no pair
/// writes (the row's own and those before it, and padding) are constants.
/// Those lanes hold −0 and a pair's lane its term as it is, where the
/// kernel's hold +0 and `+0 + term`:
/// `x + (−0) = x` for every `x`, so the compiler drops those additions,
/// and the two trees differ at most in the sign of a zero (a sum is
/// changed by a ±0 operand only when it is itself zero), which the final
/// `+ 0.0` makes the kernel's +0.
#[inline(always)]
fn small<const N: usize>(indices: &[u32], pos: &[DVec3], mass: &[f64], eps2: f64) -> [[f64; 3]; N] {
    let (mut p, mut m) = ([DVec3::ZERO; N], [0.0f64; N]);
    for q in 0..N {
        let i = indices[q] as usize;
        (p[q], m[q]) = (pos[i], mass[i]);
    }
    // Row k's lanes, and the reactions on each body (rows before it, in
    // row order, from +0 as in the kernel).
    let mut lanes = [[[-0.0f64; LANES]; 3]; N];
    let mut react = [[0.0f64; 3]; N];
    for k in 0..N {
        for q in k + 1..N {
            let (dx, dy, dz) = (p[q].x - p[k].x, p[q].y - p[k].y, p[q].z - p[k].z);
            let r2 = dx * dx + dy * dy + dz * dz + eps2;
            // (Not `r2 <= 0.0`: a NaN pulls nowhere too, as in the kernel.)
            if r2.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let inv = 1.0 / (r2 * r2.sqrt());
            let (wj, wi) = (m[q] * inv, m[k] * inv);
            lanes[k][0][q] = dx * wj;
            lanes[k][1][q] = dy * wj;
            lanes[k][2][q] = dz * wj;
            react[q][0] -= dx * wi;
            react[q][1] -= dy * wi;
            react[q][2] -= dz * wi;
        }
    }
    let mut a = [[0.0f64; 3]; N];
    for k in 0..N {
        for c in 0..3 {
            let own = tree(&lanes[k][c]) + 0.0;
            // The reactions of the rows before it (none for the first).
            a[k][c] = if k > 0 { own + react[k][c] } else { own };
        }
    }
    a
}

/// Whether `n` bodies are summed in parallel (more than one task's rows).
pub(super) fn splits(n: usize) -> bool {
    n >= 2 * ROWS_PER_TASK
}

/// The first row of each range for `n` bodies, then `n`: [`RANGES`] ranges
/// of about equal work (row `i` visits the `n − i − 1` bodies after it),
/// or one for a set that does not split.
pub(super) fn bounds(n: usize) -> Vec<usize> {
    if !splits(n) {
        return vec![0, n];
    }
    let total = (n as u128) * (n as u128 + 1) / 2;
    let mut out = vec![0];
    let mut done = 0u128;
    for i in 0..n {
        let c = out.len() as u128;
        if c < RANGES as u128 && done * RANGES as u128 >= c * total {
            out.push(i);
        }
        done += (n - i) as u128;
    }
    out.push(n);
    out
}

/// The bodies, read-only, shared by the threads.
struct Bodies<'a> {
    x: &'a [f64],
    y: &'a [f64],
    z: &'a [f64],
    m: &'a [f64],
    eps2: f64,
}

/// A range's own sums (one per row) or its buffer of reactions (one per
/// body, padded), x, y, z.
type Out<'a> = [&'a mut [f64]; 3];

impl Bodies<'_> {
    /// Rows `first..first + own[0].len()`, with the vectors of `width`,
    /// which this CPU must have.
    fn rows(&self, width: Width, first: usize, own: Out, mut react: Out) {
        for r in &mut react {
            r.fill(0.0);
        }
        #[cfg(target_arch = "x86_64")]
        {
            if width == Width::Avx512 {
                // SAFETY: the CPU has AVX-512F (the callers' widths are
                // `simd::width`'s or `Width::available`'s).
                return unsafe { self.rows_avx512(first, own, react) };
            }
            if width == Width::Avx2 {
                // SAFETY: the CPU has AVX2 (as above).
                return unsafe { self.rows_avx2(first, own, react) };
            }
        }
        self.rows_any(first, own, react)
    }

    /// The kernel, portable: row `i` visits the blocks of [`LANES`] bodies
    /// from the one holding `i + 1`, where the bodies up to `i` get weight
    /// 0. The vector versions below do exactly these operations in this
    /// order.
    #[allow(clippy::needless_range_loop)] // l is the lane and, with b, the body
    fn rows_any(&self, first: usize, own: Out, react: Out) {
        let blocks = self.x.len() / LANES;
        let [ox, oy, oz] = own;
        let [rx, ry, rz] = react;
        for k in 0..ox.len() {
            let i = first + k;
            let (xi, yi, zi, mi) = (self.x[i], self.y[i], self.z[i], self.m[i]);
            let mut s = [[0.0f64; LANES]; 3];
            for b in (i + 1) / LANES..blocks {
                for l in 0..LANES {
                    let j = b * LANES + l;
                    let (dx, dy, dz) = (self.x[j] - xi, self.y[j] - yi, self.z[j] - zi);
                    let r2 = dx * dx + dy * dy + dz * dz + self.eps2;
                    let inv = 1.0 / (r2 * r2.sqrt());
                    // A body on itself or before it, or on another at the
                    // same place unsoftened, pulls nowhere: 0, not 0 × ∞.
                    let pulls = r2 > 0.0 && j > i;
                    let wj = if pulls { self.m[j] * inv } else { 0.0 };
                    let wi = if pulls { mi * inv } else { 0.0 };
                    s[0][l] += dx * wj;
                    s[1][l] += dy * wj;
                    s[2][l] += dz * wj;
                    rx[j] -= dx * wi;
                    ry[j] -= dy * wi;
                    rz[j] -= dz * wi;
                }
            }
            ox[k] = tree(&s[0]);
            oy[k] = tree(&s[1]);
            oz[k] = tree(&s[2]);
        }
    }

    /// [`Bodies::rows_any`] with AVX-512: lane `l` of each register is
    /// accumulator `l`, the same operations in the same order.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn rows_avx512(&self, first: usize, own: Out, react: Out) {
        use std::arch::x86_64::*;
        let blocks = self.x.len() / LANES;
        let [ox, oy, oz] = own;
        let [rx, ry, rz] = react;
        assert!(rx.len() >= blocks * LANES && ry.len() == rx.len() && rz.len() == rx.len());
        let (px, py, pz, pm) = (
            self.x.as_ptr(),
            self.y.as_ptr(),
            self.z.as_ptr(),
            self.m.as_ptr(),
        );
        let (qx, qy, qz) = (rx.as_mut_ptr(), ry.as_mut_ptr(), rz.as_mut_ptr());
        let eps2 = _mm512_set1_pd(self.eps2);
        let zero = _mm512_setzero_pd();
        let one = _mm512_set1_pd(1.0);
        let lane = _mm512_setr_pd(0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0);
        for k in 0..ox.len() {
            let i = first + k;
            let (xi, yi, zi, mi) = (
                _mm512_set1_pd(self.x[i]),
                _mm512_set1_pd(self.y[i]),
                _mm512_set1_pd(self.z[i]),
                _mm512_set1_pd(self.m[i]),
            );
            let (mut sx, mut sy, mut sz) = (zero, zero, zero);
            let b0 = (i + 1) / LANES;
            let after = _mm512_set1_pd(i as f64);
            for b in b0..blocks {
                let o = b * LANES;
                // SAFETY: o + LANES <= len (the arrays are padded to LANES,
                // the buffers to at least as many, asserted above).
                let dx = _mm512_sub_pd(_mm512_loadu_pd(px.add(o)), xi);
                let dy = _mm512_sub_pd(_mm512_loadu_pd(py.add(o)), yi);
                let dz = _mm512_sub_pd(_mm512_loadu_pd(pz.add(o)), zi);
                let r2 = _mm512_add_pd(
                    _mm512_add_pd(
                        _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                        _mm512_mul_pd(dz, dz),
                    ),
                    eps2,
                );
                let inv = _mm512_div_pd(one, _mm512_mul_pd(r2, _mm512_sqrt_pd(r2)));
                let mut pulls = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2, zero);
                if b == b0 {
                    let j = _mm512_add_pd(_mm512_set1_pd(o as f64), lane);
                    pulls &= _mm512_cmp_pd_mask::<_CMP_GT_OQ>(j, after);
                }
                let wj = _mm512_maskz_mov_pd(pulls, _mm512_mul_pd(_mm512_loadu_pd(pm.add(o)), inv));
                let wi = _mm512_maskz_mov_pd(pulls, _mm512_mul_pd(mi, inv));
                sx = _mm512_add_pd(sx, _mm512_mul_pd(dx, wj));
                sy = _mm512_add_pd(sy, _mm512_mul_pd(dy, wj));
                sz = _mm512_add_pd(sz, _mm512_mul_pd(dz, wj));
                for (q, d) in [(qx, dx), (qy, dy), (qz, dz)] {
                    let r = _mm512_loadu_pd(q.add(o));
                    _mm512_storeu_pd(q.add(o), _mm512_sub_pd(r, _mm512_mul_pd(d, wi)));
                }
            }
            let mut l = [0.0f64; LANES];
            _mm512_storeu_pd(l.as_mut_ptr(), sx);
            ox[k] = tree(&l);
            _mm512_storeu_pd(l.as_mut_ptr(), sy);
            oy[k] = tree(&l);
            _mm512_storeu_pd(l.as_mut_ptr(), sz);
            oz[k] = tree(&l);
        }
    }

    /// [`Bodies::rows_any`] with AVX2: lanes 0–3 in one register, 4–7 in
    /// another.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::needless_range_loop)] // h is the half of the block, not only s's index
    unsafe fn rows_avx2(&self, first: usize, own: Out, react: Out) {
        use std::arch::x86_64::*;
        let blocks = self.x.len() / LANES;
        let [ox, oy, oz] = own;
        let [rx, ry, rz] = react;
        assert!(rx.len() >= blocks * LANES && ry.len() == rx.len() && rz.len() == rx.len());
        let (px, py, pz, pm) = (
            self.x.as_ptr(),
            self.y.as_ptr(),
            self.z.as_ptr(),
            self.m.as_ptr(),
        );
        let (qx, qy, qz) = (rx.as_mut_ptr(), ry.as_mut_ptr(), rz.as_mut_ptr());
        let eps2 = _mm256_set1_pd(self.eps2);
        let zero = _mm256_setzero_pd();
        let one = _mm256_set1_pd(1.0);
        let lane = _mm256_setr_pd(0.0, 1.0, 2.0, 3.0);
        for k in 0..ox.len() {
            let i = first + k;
            let (xi, yi, zi, mi) = (
                _mm256_set1_pd(self.x[i]),
                _mm256_set1_pd(self.y[i]),
                _mm256_set1_pd(self.z[i]),
                _mm256_set1_pd(self.m[i]),
            );
            let mut s = [[zero; 2]; 3];
            let b0 = (i + 1) / LANES;
            let after = _mm256_set1_pd(i as f64);
            for b in b0..blocks {
                for h in 0..2 {
                    let o = b * LANES + h * 4;
                    // SAFETY: o + 4 <= len (the arrays are padded to LANES,
                    // the buffers to at least as many, asserted above).
                    let dx = _mm256_sub_pd(_mm256_loadu_pd(px.add(o)), xi);
                    let dy = _mm256_sub_pd(_mm256_loadu_pd(py.add(o)), yi);
                    let dz = _mm256_sub_pd(_mm256_loadu_pd(pz.add(o)), zi);
                    let r2 = _mm256_add_pd(
                        _mm256_add_pd(
                            _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
                            _mm256_mul_pd(dz, dz),
                        ),
                        eps2,
                    );
                    let inv = _mm256_div_pd(one, _mm256_mul_pd(r2, _mm256_sqrt_pd(r2)));
                    let mut pulls = _mm256_cmp_pd::<_CMP_GT_OQ>(r2, zero);
                    if b == b0 {
                        let j = _mm256_add_pd(_mm256_set1_pd(o as f64), lane);
                        pulls = _mm256_and_pd(pulls, _mm256_cmp_pd::<_CMP_GT_OQ>(j, after));
                    }
                    let wj = _mm256_and_pd(_mm256_mul_pd(_mm256_loadu_pd(pm.add(o)), inv), pulls);
                    let wi = _mm256_and_pd(_mm256_mul_pd(mi, inv), pulls);
                    s[0][h] = _mm256_add_pd(s[0][h], _mm256_mul_pd(dx, wj));
                    s[1][h] = _mm256_add_pd(s[1][h], _mm256_mul_pd(dy, wj));
                    s[2][h] = _mm256_add_pd(s[2][h], _mm256_mul_pd(dz, wj));
                    for (q, d) in [(qx, dx), (qy, dy), (qz, dz)] {
                        let r = _mm256_loadu_pd(q.add(o));
                        _mm256_storeu_pd(q.add(o), _mm256_sub_pd(r, _mm256_mul_pd(d, wi)));
                    }
                }
            }
            let mut l = [0.0f64; LANES];
            for (c, out) in [&mut ox[k], &mut oy[k], &mut oz[k]].into_iter().enumerate() {
                _mm256_storeu_pd(l.as_mut_ptr(), s[c][0]);
                _mm256_storeu_pd(l.as_mut_ptr().add(4), s[c][1]);
                *out = tree(&l);
            }
        }
    }
}

/// The lanes' sum in a fixed tree: ((0+1)+(2+3))+((4+5)+(6+7)).
#[inline(always)]
fn tree(s: &[f64; LANES]) -> f64 {
    ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::Width;

    /// `n` bodies of unequal masses in a unit cube, with a pair at the
    /// same place.
    fn bodies(n: usize) -> Pairs {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut u = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut pos: Vec<DVec3> = (0..n).map(|_| DVec3::new(u(), u(), u())).collect();
        pos[7] = pos[100];
        let mass: Vec<f64> = (0..n).map(|_| 1.0 + u()).collect();
        let idx: Vec<u32> = (0..n as u32).collect();
        let mut g = Pairs::default();
        g.load(&idx, &pos, &mass);
        g
    }

    fn bits(g: &Pairs) -> Vec<u64> {
        g.ax.iter()
            .chain(&g.ay)
            .chain(&g.az)
            .map(|v| v.to_bits())
            .collect()
    }

    /// Every instruction set gives the same bits, with one range (203
    /// bodies, not a multiple of LANES) and with several (300).
    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        for n in [203, 300] {
            for eps2 in [0.0, 1e-4] {
                let mut g = bodies(n);
                g.sum_on(eps2, Width::Base);
                let want = bits(&g);
                assert!(want.iter().all(|b| f64::from_bits(*b).is_finite()));
                for width in Width::available() {
                    g.sum_on(eps2, width);
                    assert_eq!(bits(&g), want, "{width:?}, {n} bodies, eps² {eps2}");
                }
            }
        }
    }

    /// Each body's sum is the plain sum over every other body to within
    /// the rounding of its terms: `4 n ε Σ|term|` bounds the difference of
    /// two summation orders of `n` terms each off by a few ulps, while one
    /// pair left out or counted twice would be a whole term (~Σ|term|/n).
    #[test]
    fn the_pairs_once_sum_is_every_pull_on_every_body() {
        for (n, eps2) in [(203, 0.0), (300, 0.0), (300, 1e-4), (1001, 1e-4)] {
            let mut g = bodies(n);
            g.sum(eps2);
            for i in 0..n {
                let (mut sum, mut size) = (DVec3::ZERO, DVec3::ZERO);
                for j in 0..n {
                    let d = DVec3::new(g.x[j] - g.x[i], g.y[j] - g.y[i], g.z[j] - g.z[i]);
                    let r2 = d.length_squared() + eps2;
                    if r2 > 0.0 {
                        let t = d * (g.m[j] / (r2 * r2.sqrt()));
                        sum += t;
                        size += t.abs();
                    }
                }
                let got = DVec3::new(g.ax[i], g.ay[i], g.az[i]);
                let tol = size * (4.0 * n as f64 * f64::EPSILON);
                assert!(
                    (got - sum).abs().cmple(tol).all(),
                    "{n} bodies, body {i}: {got} against {sum} (tolerance {tol})"
                );
            }
        }
    }

    /// A set of up to LANES bodies summed straight from the particles gives
    /// the kernel's bits, with and without softening, with two bodies at
    /// one place, in any order of indices.
    #[test]
    fn small_sets_summed_straight_from_the_particles_give_the_kernel_s_bits() {
        let all = bodies(203);
        let pos: Vec<DVec3> = (0..203)
            .map(|i| DVec3::new(all.x[i], all.y[i], all.z[i]))
            .collect();
        let mass = all.m[..203].to_vec();
        // (LANES + 1 bodies too: handed on to the kernel's code.)
        for n in 2..=LANES + 1 {
            for eps2 in [0.0, 1e-4] {
                // Out of order; 100 and 7 share a place.
                let idx = [100u32, 7, 50, 3, 150, 20, 199, 60, 11][..n].to_vec();
                let mut kernel = Pairs::default();
                kernel.load(&idx, &pos, &mass);
                kernel.sum_on(eps2, Width::Base);
                let mut small = Pairs::default();
                small.sum_small(&idx, &pos, &mass, eps2);
                assert_eq!(bits(&small), bits(&kernel), "{n} bodies, eps² {eps2}");
                if n > 2 {
                    assert!(bits(&small).iter().any(|&b| f64::from_bits(b).abs() > 0.0));
                }
            }
        }
    }

    /// The ranges cover every row once, and each holds an eighth of the
    /// pairs to within one row's.
    #[test]
    fn the_ranges_share_the_pairs_evenly() {
        assert_eq!(bounds(255), vec![0, 255]);
        for n in [256, 300, 1000, 4099] {
            let b = bounds(n);
            assert_eq!(b.len(), RANGES + 1);
            assert_eq!((b[0], b[RANGES]), (0, n));
            let total = n * (n + 1) / 2;
            for w in b.windows(2) {
                assert!(w[0] < w[1], "{b:?}");
                let work: usize = (w[0]..w[1]).map(|i| n - i).sum();
                assert!(work.abs_diff(total / RANGES) <= n, "{n}: {b:?}");
            }
        }
    }
}
