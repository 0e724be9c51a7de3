//! Eigenvalues and eigenvectors of a symmetric matrix (CMA-ES's and
//! CMA-ME's covariance), deterministic to the bit on every platform: plain
//! IEEE additions, multiplications, divisions and square roots in a fixed
//! order, no library routine and no run-time choice of vector width.
//!
//! Two methods. Up to [`JACOBI_UP_TO`] rows, cyclic Jacobi rotations,
//! accurate to each eigenvalue's own size: every shipped scene's genome
//! (at most 37 genes under CMA-ES) is decomposed this way. Above, Householder
//! reduction to a tridiagonal matrix followed by the implicit QL method
//! with Wilkinson's shift (Wilkinson and Reinsch's *tred2* and *tql2*, as
//! in EISPACK), every inner loop along a contiguous row: about 9 n³
//! operations against Jacobi's 6 n³ for each of its several sweeps. One
//! thread, a dense covariance (`cargo run --release -p animats-bench
//! --example cma_es_genes`, Intel Xeon, 2026-12-03): Jacobi 0.065, 7.0,
//! 265 ms at 20, 100, 300 rows, minutes at 1,000; Householder-QL 0.018,
//! 1.1, 23, 980 ms.

/// The largest covariance decomposed by Jacobi rotations; larger ones by
/// Householder and QL.
pub const JACOBI_UP_TO: usize = 64;

/// Eigenvalues, and eigenvectors as the columns of a row-major matrix, of
/// the symmetric `n × n` matrix `m` (row-major): by Jacobi rotations up to
/// [`JACOBI_UP_TO`] rows, by Householder and QL above.
pub fn symmetric_eigen(m: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    if n <= JACOBI_UP_TO {
        jacobi_eigen(m, n)
    } else {
        householder_ql_eigen(m, n)
    }
}

/// Eigenvalues and eigenvectors (as the columns of a row-major matrix) of a
/// symmetric `n × n` matrix, by cyclic Jacobi rotations.
///
/// The eigenvectors are accumulated as rows (`vt`, the transpose of the
/// result), so that each rotation updates two contiguous rows of them
/// instead of two columns `n` apart: the same operations on the same
/// numbers, so the same bits, a 100 × 100 matrix in 57 % of the time
/// (docs/PERFORMANCE.md). The matrix's own column update stays strided:
/// rounding leaves it not exactly symmetric, so its columns cannot be read
/// from its rows.
pub fn jacobi_eigen(m: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut a = m.to_vec();
    let mut vt = vec![0.0; n * n];
    for i in 0..n {
        vt[i * n + i] = 1.0;
    }
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * n + j] * a[i * n + j])
            .sum();
        let diag: f64 = (0..n).map(|i| a[i * n + i] * a[i * n + i]).sum();
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = a[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let akp = a[k * n + p];
                    let akq = a[k * n + q];
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                let (head, tail) = a.split_at_mut(q * n);
                let (ap, aq) = (&mut head[p * n..(p + 1) * n], &mut tail[..n]);
                for (apk, aqk) in ap.iter_mut().zip(aq.iter_mut()) {
                    let (x, y) = (*apk, *aqk);
                    *apk = c * x - s * y;
                    *aqk = s * x + c * y;
                }
                let (head, tail) = vt.split_at_mut(q * n);
                let (vp, vq) = (&mut head[p * n..(p + 1) * n], &mut tail[..n]);
                for (vkp, vkq) in vp.iter_mut().zip(vq.iter_mut()) {
                    let (x, y) = (*vkp, *vkq);
                    *vkp = c * x - s * y;
                    *vkq = s * x + c * y;
                }
            }
        }
    }
    let mut v = vec![0.0; n * n];
    for (i, row) in vt.chunks_exact(n.max(1)).enumerate() {
        for (k, &x) in row.iter().enumerate() {
            v[k * n + i] = x;
        }
    }
    ((0..n).map(|i| a[i * n + i]).collect(), v)
}

/// `√(a² + b²)` without overflow or underflow on the way, in a fixed
/// order (std's `hypot` is the platform's). Not the engine's
/// `math::hypot`: `libm`'s correctly rounded one made the decomposition
/// 3.7× slower at 20 rows and 2.0× at 100 (`cma_es_genes`, 0.075 against
/// 0.020 ms and 2.45 against 1.22 ms), and the rotations need no more
/// than this.
fn hypot(a: f64, b: f64) -> f64 {
    let (a, b) = (a.abs(), b.abs());
    let (big, small) = if a >= b { (a, b) } else { (b, a) };
    if big == 0.0 {
        return 0.0;
    }
    let r = small / big;
    big * (1.0 + r * r).sqrt()
}

/// Eigenvalues and eigenvectors (as the columns of a row-major matrix) of a
/// symmetric `n × n` matrix: Householder reduction to tridiagonal form,
/// then the implicit QL method with Wilkinson's shift.
///
/// The transformations are accumulated in `w`, the *transpose* of the
/// textbook's matrix of vectors, so that every inner loop runs along a
/// row: the same operations on the same numbers as the column-wise
/// textbook code, in cache order. An eigenvalue that has not converged in
/// 60 QL iterations (which finite input does not reach) is left as it is.
pub fn householder_ql_eigen(m: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    // Scaled by a power of two (exactly) to a largest entry in [½, 1), so
    // that what the method neglects, relative to the matrix, lies far
    // above underflow, where rotations lose their orthogonality.
    let largest = m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let k = if largest.is_finite() && largest > 0.0 {
        -(((largest.to_bits() >> 52) & 0x7ff) as i32 - 1022)
    } else {
        0
    };
    // w[x n + y] is the textbook's V[y][x]; V starts as the matrix.
    let mut w = vec![0.0; n * n];
    for x in 0..n {
        for y in 0..n {
            w[x * n + y] = scale_by_pow2(m[y * n + x], k);
        }
    }
    let mut d = vec![0.0; n];
    let mut e = vec![0.0; n];
    tridiagonalise(&mut w, &mut d, &mut e, n);
    ql_implicit(&mut w, &mut d, &mut e, n);
    for l in &mut d {
        *l = scale_by_pow2(*l, -k);
    }
    // Eigenvector j is row j of w.
    let mut v = vec![0.0; n * n];
    for (j, row) in w.chunks_exact(n).enumerate() {
        for (k, &x) in row.iter().enumerate() {
            v[k * n + j] = x;
        }
    }
    (d, v)
}

/// The smallest row sum a Householder vector is scaled by: 2⁻⁹⁷⁰, above
/// which dividing by it keeps every bit of a normal number's worth.
const TINY: f64 = f64::MIN_POSITIVE / f64::EPSILON;

/// `x` times 2^`k`, exactly while the result is normal (in steps that
/// stay within the exponent's range).
fn scale_by_pow2(mut x: f64, mut k: i32) -> f64 {
    while k != 0 {
        let step = k.clamp(-1000, 1000);
        x *= f64::from_bits(((1023 + step) as u64) << 52);
        k -= step;
    }
    x
}

/// Householder reduction of the symmetric matrix held in `w` (transposed
/// storage) to tridiagonal form: diagonal `d`, sub-diagonal `e[1..]`; `w`
/// ends as the accumulated orthogonal transformation.
fn tridiagonalise(w: &mut [f64], d: &mut [f64], e: &mut [f64], n: usize) {
    for j in 0..n {
        d[j] = w[j * n + n - 1];
    }
    for i in (1..n).rev() {
        let mut scale = 0.0;
        let mut h = 0.0;
        for dk in &d[..i] {
            scale += dk.abs();
        }
        // A row whose entries are all near underflow is taken as zero
        // (a change far below the method's rounding): scaled by a
        // subnormal sum, its Householder vector would lose its length's
        // bits and the transformation its orthogonality.
        if scale < TINY {
            e[i] = d[i - 1];
            for j in 0..i {
                d[j] = w[j * n + i - 1];
                w[j * n + i] = 0.0;
                w[i * n + j] = 0.0;
            }
        } else {
            for dk in &mut d[..i] {
                *dk /= scale;
                h += *dk * *dk;
            }
            let mut f = d[i - 1];
            let mut g = h.sqrt();
            if f > 0.0 {
                g = -g;
            }
            e[i] = scale * g;
            h -= f * g;
            d[i - 1] = f - g;
            e[..i].fill(0.0);
            for j in 0..i {
                f = d[j];
                w[i * n + j] = f;
                let row = &w[j * n..j * n + i];
                g = e[j] + row[j] * f;
                for k in j + 1..i {
                    g += row[k] * d[k];
                    e[k] += row[k] * f;
                }
                e[j] = g;
            }
            f = 0.0;
            for j in 0..i {
                e[j] /= h;
                f += e[j] * d[j];
            }
            let hh = f / (h + h);
            for j in 0..i {
                e[j] -= hh * d[j];
            }
            for j in 0..i {
                f = d[j];
                g = e[j];
                let row = &mut w[j * n..j * n + n];
                for k in j..i {
                    row[k] -= f * e[k] + g * d[k];
                }
                d[j] = row[i - 1];
                row[i] = 0.0;
            }
        }
        d[i] = h;
    }
    // Accumulate the transformations.
    for i in 0..n - 1 {
        w[i * n + n - 1] = w[i * n + i];
        w[i * n + i] = 1.0;
        let h = d[i + 1];
        let (head, tail) = w.split_at_mut((i + 1) * n);
        let next = &mut tail[..n];
        if h != 0.0 {
            for k in 0..=i {
                d[k] = next[k] / h;
            }
            for j in 0..=i {
                let row = &mut head[j * n..j * n + n];
                let mut g = 0.0;
                for k in 0..=i {
                    g += next[k] * row[k];
                }
                for k in 0..=i {
                    row[k] -= g * d[k];
                }
            }
        }
        next[..=i].fill(0.0);
    }
    for j in 0..n {
        d[j] = w[j * n + n - 1];
        w[j * n + n - 1] = 0.0;
    }
    w[(n - 1) * n + n - 1] = 1.0;
    e[0] = 0.0;
}

/// The implicit QL method on the tridiagonal matrix (`d`, `e[1..]`),
/// rotating the rows of `w`: `d` ends as the eigenvalues, the rows of `w`
/// as their eigenvectors.
fn ql_implicit(w: &mut [f64], d: &mut [f64], e: &mut [f64], n: usize) {
    for i in 1..n {
        e[i - 1] = e[i];
    }
    e[n - 1] = 0.0;
    let eps = f64::EPSILON;
    let mut f = 0.0;
    // Negligible: below ε of the whole matrix's norm (the textbook's
    // running norm of the part done spins on tiny leading blocks).
    let tst1 = (0..n).fold(0.0f64, |t, l| t.max(d[l].abs() + e[l].abs()));
    // (False for NaN: a NaN element is never negligible, and the search
    // stops at the last row.)
    let negligible = |x: f64| x.abs() <= eps * tst1;
    for l in 0..n {
        // Find a negligible sub-diagonal element.
        let mut m = l;
        while m < n - 1 && !negligible(e[m]) {
            m += 1;
        }
        if m > l {
            for _ in 0..60 {
                // The shift.
                let mut g = d[l];
                let mut p = (d[l + 1] - g) / (2.0 * e[l]);
                let mut r = hypot(p, 1.0);
                if p < 0.0 {
                    r = -r;
                }
                d[l] = e[l] / (p + r);
                d[l + 1] = e[l] * (p + r);
                let dl1 = d[l + 1];
                let mut h = g - d[l];
                for di in &mut d[l + 2..] {
                    *di -= h;
                }
                f += h;
                // The implicit QL sweep.
                p = d[m];
                let (mut c, mut c2, mut c3) = (1.0, 1.0, 1.0);
                let el1 = e[l + 1];
                let (mut s, mut s2) = (0.0, 0.0);
                for i in (l..m).rev() {
                    c3 = c2;
                    c2 = c;
                    s2 = s;
                    g = c * e[i];
                    h = c * p;
                    r = hypot(p, e[i]);
                    e[i + 1] = s * r;
                    s = e[i] / r;
                    c = p / r;
                    p = c * d[i] - s * g;
                    d[i + 1] = h + s * (c * g + s * d[i]);
                    let (head, tail) = w.split_at_mut((i + 1) * n);
                    let (vi, vi1) = (&mut head[i * n..], &mut tail[..n]);
                    for (a, b) in vi.iter_mut().zip(vi1.iter_mut()) {
                        let h = *b;
                        *b = s * *a + c * h;
                        *a = c * *a - s * h;
                    }
                }
                p = -s * s2 * c3 * el1 * e[l] / dl1;
                e[l] = s * p;
                d[l] = c * p;
                if negligible(e[l]) || e[l].is_nan() {
                    break;
                }
            }
        }
        d[l] += f;
        e[l] = 0.0;
    }
}

#[cfg(test)]
// std's cos: an independent reference here
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::{householder_ql_eigen, jacobi_eigen, symmetric_eigen, JACOBI_UP_TO};
    use crate::optimiser::Random;

    type Method = fn(&[f64], usize) -> (Vec<f64>, Vec<f64>);
    const METHODS: [(&str, Method); 2] = [
        ("Jacobi", jacobi_eigen),
        ("Householder-QL", householder_ql_eigen),
    ];

    /// A random symmetric matrix of `n` rows, entries in [−½, ½); or, if
    /// `covariance`, the product of such a matrix with itself (B Bᵀ).
    fn random_matrix(rng: &mut Random, n: usize, covariance: bool) -> Vec<f64> {
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            for j in i..n {
                let x = rng.uniform() - 0.5;
                m[i * n + j] = x;
                m[j * n + i] = x;
            }
        }
        if covariance {
            let b = m.clone();
            for i in 0..n {
                for j in 0..n {
                    m[i * n + j] = (0..n).map(|k| b[i * n + k] * b[j * n + k]).sum();
                }
            }
        }
        m
    }

    /// Each pair is an eigenpair (‖A v − λ v‖ within max(1e-12, n 1e-14)
    /// of ‖A‖: backward stable, the error grows with n at most), the vectors
    /// orthonormal to max(1e-13, n 1e-15), and the values sum to the trace.
    fn check_eigenpairs(name: &str, m: &[f64], n: usize, values: &[f64], v: &[f64]) {
        let norm = m.iter().map(|x| x * x).sum::<f64>().sqrt();
        let tol = 1e-12f64.max(n as f64 * 1e-14) * norm;
        let orth = 1e-13f64.max(n as f64 * 1e-15);
        assert_eq!((values.len(), v.len()), (n, n * n), "{name}");
        for (i, &l) in values.iter().enumerate() {
            let residual = (0..n)
                .map(|r| {
                    let av: f64 = (0..n).map(|k| m[r * n + k] * v[k * n + i]).sum();
                    (av - l * v[r * n + i]).powi(2)
                })
                .sum::<f64>()
                .sqrt();
            assert!(residual <= tol, "{name}, n {n}, pair {i}: {residual}");
            for j in 0..n {
                let dot: f64 = (0..n).map(|k| v[k * n + i] * v[k * n + j]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((dot - want).abs() <= orth, "{name}, n {n}: v{i}·v{j} {dot}");
            }
        }
        let trace: f64 = (0..n).map(|i| m[i * n + i]).sum();
        let sum: f64 = values.iter().sum();
        assert!((trace - sum).abs() <= tol.max(1e-12), "{name}, n {n}");
    }

    /// Random symmetric matrices and covariances of 1 to 101 rows (and 300
    /// for Householder-QL): eigenpairs, orthonormal vectors, the trace;
    /// a covariance's values are not negative; and the two methods find the
    /// same values, sorted, to 1e-12 of ‖A‖.
    #[test]
    fn both_methods_give_orthonormal_eigenpairs() {
        let mut rng = Random::for_entry(7, 0);
        for n in [1usize, 2, 3, 7, 16, 33, 100, 101, 300] {
            for covariance in [false, true] {
                let m = random_matrix(&mut rng, n, covariance);
                let norm = m.iter().map(|x| x * x).sum::<f64>().sqrt();
                let mut sorted = Vec::new();
                for (name, method) in METHODS {
                    if name == "Jacobi" && n > 101 {
                        continue;
                    }
                    let (values, v) = method(&m, n);
                    check_eigenpairs(name, &m, n, &values, &v);
                    if covariance {
                        let low = values.iter().copied().fold(f64::INFINITY, f64::min);
                        assert!(
                            low >= -1e-12 * norm,
                            "{name}, n {n}: a covariance's value {low}"
                        );
                    }
                    let mut s = values.clone();
                    s.sort_by(f64::total_cmp);
                    sorted.push(s);
                }
                if let [a, b] = &sorted[..] {
                    for (x, y) in a.iter().zip(b) {
                        assert!((x - y).abs() <= 1e-12 * norm, "n {n}: {x} against {y}");
                    }
                }
            }
        }
    }

    /// Against the analytic spectrum of the second-difference matrix
    /// (2 on the diagonal, −1 beside it): 2 − 2 cos(kπ/(n+1)), k = 1…n,
    /// to 2 n ε ‖A‖₂ (‖A‖₂ < 4: a backward-stable method's error), for
    /// sizes either side of the switch between the methods;
    /// and matrices whose spectrum is degenerate (the identity, zero, a
    /// diagonal with repeats, a rank-one matrix) exactly or to 1e-14.
    #[test]
    fn the_spectrum_of_known_matrices() {
        for n in [5usize, JACOBI_UP_TO, JACOBI_UP_TO + 1, 257] {
            let mut m = vec![0.0; n * n];
            for i in 0..n {
                m[i * n + i] = 2.0;
                if i + 1 < n {
                    m[i * n + i + 1] = -1.0;
                    m[(i + 1) * n + i] = -1.0;
                }
            }
            let (mut values, v) = symmetric_eigen(&m, n);
            check_eigenpairs("second difference", &m, n, &values, &v);
            values.sort_by(f64::total_cmp);
            for (k, l) in values.iter().enumerate() {
                let want =
                    2.0 - 2.0 * ((k + 1) as f64 * std::f64::consts::PI / (n + 1) as f64).cos();
                let tol = 2.0 * n as f64 * f64::EPSILON * 4.0;
                assert!(
                    (l - want).abs() <= tol,
                    "n {n}, value {k}: {l} against {want}"
                );
            }
        }
        // (Rank one at 42 and 117 rows left the textbook's QL rotating
        // subnormal numbers, vectors 6 % off unit length.)
        for ((name, method), n) in METHODS.iter().flat_map(|m| [(m, 42), (m, 117), (m, 150)]) {
            let mut eye = vec![0.0; n * n];
            let mut diag = vec![0.0; n * n];
            let mut rank_one = vec![0.0; n * n];
            for i in 0..n {
                eye[i * n + i] = 1.0;
                diag[i * n + i] = [3.0, -1.0, 3.0, 0.5][i % 4];
                for j in 0..n {
                    rank_one[i * n + j] = ((i % 7) as f64 - 3.0) * ((j % 7) as f64 - 3.0);
                }
            }
            let (values, v) = method(&eye, n);
            assert!(values.iter().all(|&l| l == 1.0), "{name}: identity");
            check_eigenpairs(name, &eye, n, &values, &v);
            let (values, v) = method(&vec![0.0; n * n], n);
            assert!(values.iter().all(|&l| l == 0.0), "{name}: zero");
            check_eigenpairs(name, &vec![0.0; n * n], n, &values, &v);
            let (mut values, v) = method(&diag, n);
            check_eigenpairs(name, &diag, n, &values, &v);
            values.sort_by(f64::total_cmp);
            let count = |x: f64| values.iter().filter(|&&l| l == x).count();
            let of = |r: usize| (0..n).filter(|i| i % 4 == r).count();
            assert_eq!(
                (count(-1.0), count(0.5), count(3.0)),
                (of(1), of(3), of(0) + of(2)),
                "{name}"
            );
            // Rank one: u uᵀ with u = (i mod 7) − 3: one value ‖u‖², the rest 0.
            let (mut values, v) = method(&rank_one, n);
            check_eigenpairs(name, &rank_one, n, &values, &v);
            values.sort_by(f64::total_cmp);
            let uu: f64 = (0..n).map(|i| ((i % 7) as f64 - 3.0).powi(2)).sum();
            assert!(
                (values[n - 1] - uu).abs() <= 1e-14 * uu,
                "{name}: {} against {uu}",
                values[n - 1]
            );
            assert!(
                values[..n - 1].iter().all(|l| l.abs() <= 1e-14 * uu),
                "{name}"
            );
        }
    }

    /// Non-finite input ends (in a bounded number of sweeps or iterations)
    /// with non-finite values, which CMA-ES takes as a broken state; no
    /// panic, no hang.
    #[test]
    fn non_finite_input_ends() {
        for (name, method) in METHODS {
            for bad in [f64::NAN, f64::INFINITY] {
                let n = 120;
                let mut rng = Random::for_entry(3, 0);
                let mut m = random_matrix(&mut rng, n, false);
                m[5 * n + 7] = bad;
                m[7 * n + 5] = bad;
                let (values, _) = method(&m, n);
                assert!(values.iter().any(|l| !l.is_finite()), "{name}: {bad}");
            }
        }
    }

    /// The same bits every time (no state, no threads, no run-time choice).
    #[test]
    fn decompositions_are_repeatable() {
        let mut rng = Random::for_entry(11, 0);
        let m = random_matrix(&mut rng, 180, true);
        let a = householder_ql_eigen(&m, 180);
        let b = householder_ql_eigen(&m, 180);
        assert!(a
            .0
            .iter()
            .zip(&b.0)
            .all(|(x, y)| x.to_bits() == y.to_bits()));
        assert!(a
            .1
            .iter()
            .zip(&b.1)
            .all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}
