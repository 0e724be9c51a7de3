//! The n-body force as a gather: for each body `i`, `Σⱼ mⱼ dᵢⱼ /
//! (|dᵢⱼ|² + ε²)^{3/2}` over every body `j` (itself included: its `d` is
//! zero, and a zero `r²` contributes nothing), from positions and masses laid
//! out as separate x, y, z, m arrays.
//!
//! Reproducibility: the sum runs over `j` in a fixed order into [`LANES`]
//! separate accumulators (accumulator `l` takes `j ≡ l mod LANES`), reduced
//! in a fixed tree at the end. The lane count is fixed, not the CPU's vector
//! width, and nothing is fused (no FMA), so AVX-512, AVX2 and plain SSE2
//! give the same bits; bodies are independent, so splitting them among
//! threads changes nothing either.

use glam::DVec3;
use rayon::prelude::*;

/// Accumulators per body (8 f64: one AVX-512 register, two AVX2, four SSE2).
pub const LANES: usize = 8;

/// Bodies per thread task; below two tasks' worth the gather stays on the
/// calling thread (waking a thread costs more than a small gather).
const ROWS_PER_TASK: usize = 128;

/// The gather's arrays, kept between steps (no per-step allocation).
#[derive(Clone, Debug, Default)]
pub struct Gather {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    m: Vec<f64>,
    /// Each body's Σ mⱼ dᵢⱼ / r³ (the acceleration over G), x, y, z.
    pub ax: Vec<f64>,
    pub ay: Vec<f64>,
    pub az: Vec<f64>,
}

impl Gather {
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
    }

    /// Fills `ax`, `ay`, `az` with softening² `eps2`; in parallel on the
    /// current rayon pool for large sets.
    pub fn gather(&mut self, eps2: f64) {
        let n = self.ax.len();
        let src = Bodies {
            x: &self.x,
            y: &self.y,
            z: &self.z,
            m: &self.m,
            eps2,
        };
        if splits(n) {
            self.ax
                .par_chunks_mut(ROWS_PER_TASK)
                .zip(self.ay.par_chunks_mut(ROWS_PER_TASK))
                .zip(self.az.par_chunks_mut(ROWS_PER_TASK))
                .enumerate()
                .for_each(|(c, ((ax, ay), az))| src.rows(c * ROWS_PER_TASK, ax, ay, az));
        } else {
            src.rows(0, &mut self.ax, &mut self.ay, &mut self.az);
        }
    }
}

/// Whether `n` bodies are gathered in parallel (more than one task's rows).
pub(super) fn splits(n: usize) -> bool {
    n >= 2 * ROWS_PER_TASK
}

/// The bodies, read-only, shared by the threads.
struct Bodies<'a> {
    x: &'a [f64],
    y: &'a [f64],
    z: &'a [f64],
    m: &'a [f64],
    eps2: f64,
}

impl Bodies<'_> {
    /// Rows `first..first + ax.len()`, with the vectors chosen for
    /// arithmetic on this CPU (`crate::simd`).
    fn rows(&self, first: usize, ax: &mut [f64], ay: &mut [f64], az: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        {
            use crate::simd::{width, Use, Width};
            let width = width(Use::Arithmetic);
            if width == Width::Avx512 {
                // SAFETY: the CPU has AVX-512F (`width` chooses only what it has).
                return unsafe { self.rows_avx512(first, ax, ay, az) };
            }
            if width == Width::Avx2 {
                // SAFETY: the CPU has AVX2 (`width` chooses only what it has).
                return unsafe { self.rows_avx2(first, ax, ay, az) };
            }
        }
        self.rows_any(first, ax, ay, az)
    }

    /// [`Bodies::rows_any`] with AVX-512: lane `l` of each register is
    /// accumulator `l`, the same operations in the same order.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn rows_avx512(&self, first: usize, ax: &mut [f64], ay: &mut [f64], az: &mut [f64]) {
        use std::arch::x86_64::*;
        let blocks = self.x.len() / LANES;
        let (px, py, pz, pm) = (
            self.x.as_ptr(),
            self.y.as_ptr(),
            self.z.as_ptr(),
            self.m.as_ptr(),
        );
        let eps2 = _mm512_set1_pd(self.eps2);
        let zero = _mm512_setzero_pd();
        for k in 0..ax.len() {
            let i = first + k;
            let (xi, yi, zi) = (
                _mm512_set1_pd(self.x[i]),
                _mm512_set1_pd(self.y[i]),
                _mm512_set1_pd(self.z[i]),
            );
            let (mut sx, mut sy, mut sz) = (zero, zero, zero);
            for b in 0..blocks {
                let o = b * LANES;
                // SAFETY: o + LANES <= len (the arrays are padded to LANES).
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
                let q = _mm512_div_pd(
                    _mm512_loadu_pd(pm.add(o)),
                    _mm512_mul_pd(r2, _mm512_sqrt_pd(r2)),
                );
                let w = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2, zero), q);
                sx = _mm512_add_pd(sx, _mm512_mul_pd(dx, w));
                sy = _mm512_add_pd(sy, _mm512_mul_pd(dy, w));
                sz = _mm512_add_pd(sz, _mm512_mul_pd(dz, w));
            }
            let mut l = [0.0f64; LANES];
            _mm512_storeu_pd(l.as_mut_ptr(), sx);
            ax[k] = tree(&l);
            _mm512_storeu_pd(l.as_mut_ptr(), sy);
            ay[k] = tree(&l);
            _mm512_storeu_pd(l.as_mut_ptr(), sz);
            az[k] = tree(&l);
        }
    }

    /// [`Bodies::rows_any`] with AVX2: lanes 0–3 in one register, 4–7 in
    /// another.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::needless_range_loop)] // h is the half of the block, not only s's index
    unsafe fn rows_avx2(&self, first: usize, ax: &mut [f64], ay: &mut [f64], az: &mut [f64]) {
        use std::arch::x86_64::*;
        let blocks = self.x.len() / LANES;
        let (px, py, pz, pm) = (
            self.x.as_ptr(),
            self.y.as_ptr(),
            self.z.as_ptr(),
            self.m.as_ptr(),
        );
        let eps2 = _mm256_set1_pd(self.eps2);
        let zero = _mm256_setzero_pd();
        for k in 0..ax.len() {
            let i = first + k;
            let (xi, yi, zi) = (
                _mm256_set1_pd(self.x[i]),
                _mm256_set1_pd(self.y[i]),
                _mm256_set1_pd(self.z[i]),
            );
            let mut s = [[zero; 2]; 3];
            for b in 0..blocks {
                for h in 0..2 {
                    let o = b * LANES + h * 4;
                    // SAFETY: o + 4 <= len (the arrays are padded to LANES).
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
                    let q = _mm256_div_pd(
                        _mm256_loadu_pd(pm.add(o)),
                        _mm256_mul_pd(r2, _mm256_sqrt_pd(r2)),
                    );
                    let w = _mm256_and_pd(q, _mm256_cmp_pd::<_CMP_GT_OQ>(r2, zero));
                    s[0][h] = _mm256_add_pd(s[0][h], _mm256_mul_pd(dx, w));
                    s[1][h] = _mm256_add_pd(s[1][h], _mm256_mul_pd(dy, w));
                    s[2][h] = _mm256_add_pd(s[2][h], _mm256_mul_pd(dz, w));
                }
            }
            let mut l = [0.0f64; LANES];
            for (c, out) in [&mut ax[k], &mut ay[k], &mut az[k]].into_iter().enumerate() {
                _mm256_storeu_pd(l.as_mut_ptr(), s[c][0]);
                _mm256_storeu_pd(l.as_mut_ptr().add(4), s[c][1]);
                *out = tree(&l);
            }
        }
    }

    /// The kernel, portable: accumulator `l` sums `j ≡ l mod LANES`. The
    /// vector versions above do exactly these operations in this order.
    fn rows_any(&self, first: usize, ax: &mut [f64], ay: &mut [f64], az: &mut [f64]) {
        let blocks = self.x.len() / LANES;
        for (k, ((oax, oay), oaz)) in ax
            .iter_mut()
            .zip(ay.iter_mut())
            .zip(az.iter_mut())
            .enumerate()
        {
            let i = first + k;
            let (xi, yi, zi) = (self.x[i], self.y[i], self.z[i]);
            let mut sx = [0.0f64; LANES];
            let mut sy = [0.0f64; LANES];
            let mut sz = [0.0f64; LANES];
            for b in 0..blocks {
                let r = b * LANES..(b + 1) * LANES;
                let (cx, cy, cz, cm) = (
                    lanes(&self.x[r.clone()]),
                    lanes(&self.y[r.clone()]),
                    lanes(&self.z[r.clone()]),
                    lanes(&self.m[r]),
                );
                let mut w = [0.0f64; LANES];
                let mut dx = [0.0f64; LANES];
                let mut dy = [0.0f64; LANES];
                let mut dz = [0.0f64; LANES];
                for l in 0..LANES {
                    dx[l] = cx[l] - xi;
                    dy[l] = cy[l] - yi;
                    dz[l] = cz[l] - zi;
                    let r2 = dx[l] * dx[l] + dy[l] * dy[l] + dz[l] * dz[l] + self.eps2;
                    let q = cm[l] / (r2 * r2.sqrt());
                    // A body on itself (or on another at the same place,
                    // unsoftened) pulls nowhere: 0, not 0 × ∞.
                    w[l] = if r2 > 0.0 { q } else { 0.0 };
                }
                for l in 0..LANES {
                    sx[l] += dx[l] * w[l];
                    sy[l] += dy[l] * w[l];
                    sz[l] += dz[l] * w[l];
                }
            }
            *oax = tree(&sx);
            *oay = tree(&sy);
            *oaz = tree(&sz);
        }
    }
}

/// A block of the arrays as a fixed-size array (the loops over it unroll
/// into vector instructions).
#[inline(always)]
fn lanes(s: &[f64]) -> &[f64; LANES] {
    s.try_into().expect("blocks are LANES long")
}

/// The lanes' sum in a fixed tree: ((0+1)+(2+3))+((4+5)+(6+7)).
#[inline(always)]
fn tree(s: &[f64; LANES]) -> f64 {
    ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 203 bodies (not a multiple of LANES) with a pair at the same place.
    fn bodies() -> Gather {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut u = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let n = 203;
        let mut pos: Vec<DVec3> = (0..n).map(|_| DVec3::new(u(), u(), u())).collect();
        pos[7] = pos[100];
        let mass: Vec<f64> = (0..n).map(|_| 1.0 + u()).collect();
        let idx: Vec<u32> = (0..n as u32).collect();
        let mut g = Gather::default();
        g.load(&idx, &pos, &mass);
        g
    }

    fn run(g: &Gather, eps2: f64, path: &str) -> Vec<u64> {
        let b = Bodies {
            x: &g.x,
            y: &g.y,
            z: &g.z,
            m: &g.m,
            eps2,
        };
        let n = g.ax.len();
        let (mut ax, mut ay, mut az) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        match path {
            "any" => b.rows_any(0, &mut ax, &mut ay, &mut az),
            #[cfg(target_arch = "x86_64")]
            "avx2" => unsafe { b.rows_avx2(0, &mut ax, &mut ay, &mut az) },
            #[cfg(target_arch = "x86_64")]
            "avx512" => unsafe { b.rows_avx512(0, &mut ax, &mut ay, &mut az) },
            _ => unreachable!(),
        }
        ax.iter()
            .chain(&ay)
            .chain(&az)
            .map(|v| v.to_bits())
            .collect()
    }

    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        for eps2 in [0.0, 1e-4] {
            let g = bodies();
            let want = run(&g, eps2, "any");
            assert!(want.iter().all(|b| f64::from_bits(*b).is_finite()));
            #[cfg(target_arch = "x86_64")]
            {
                if std::arch::is_x86_feature_detected!("avx2") {
                    assert_eq!(run(&g, eps2, "avx2"), want, "avx2, eps² {eps2}");
                }
                if std::arch::is_x86_feature_detected!("avx512f") {
                    assert_eq!(run(&g, eps2, "avx512"), want, "avx512, eps² {eps2}");
                }
            }
        }
    }
}
