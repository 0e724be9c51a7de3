//! CMA-ME's emitter (Fontaine et al. 2020), as pyribs 0.12's
//! `EvolutionStrategyEmitter` with its defaults: a CMA-ES whose candidates
//! are ranked by what they did to the archive ("2imp": those that found a
//! new cell first, then those that improved one, then the rest, each group
//! by the archive's value), whose parents are the candidates that entered
//! the archive ("filter" selection, μ varying from generation to
//! generation), and which restarts from a random elite when no candidate
//! entered ("no_improvement") or the search has collapsed.
//!
//! The CMA-ES is pyribs's (an adaptation of Hansen's `purecma`): log
//! weights over the μ parents, the eigendecomposition refreshed lazily
//! every `0.5 n λ / (c₁ + c_μ) / n²` evaluations, the step size updated by
//! `σ ← σ exp(min(1, (c_σ/d_σ)(|p_σ|²/n − 1)/2))`. One departure, for the
//! textbook: the evolution path and the rank-one update use the step
//! `y/σ` and add `c₁ p_c p_cᵀ` once (pyribs 0.12 scales both by σ and
//! multiplies the rank-one term by c₁ twice).
//!
//! It searches in the space the caller gives it: a bounded genome's
//! coordinates divided by each gene's width ([`super::map_elites`]), where
//! a candidate outside [0, 1] is drawn again (up to [`RESAMPLES`] times,
//! then clipped), as pyribs resamples out-of-bounds solutions.

use super::eigen::symmetric_eigen;
use super::{check_genomes, check_numbers, check_same, gaussian, Random};
use crate::archive::Added;
use serde::{Deserialize, Serialize};

/// Draws a candidate outside the bounds gets before it is clipped.
pub const RESAMPLES: usize = 100;

/// One CMA-ME emitter's state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CmaEmitter {
    n: usize,
    /// Candidates a generation (λ).
    pub batch: usize,
    sigma0: f64,
    bounded: bool,
    mean: Vec<f64>,
    sigma: f64,
    pc: Vec<f64>,
    ps: Vec<f64>,
    /// C, row-major.
    cov: Vec<f64>,
    /// C's eigenvectors as columns, row-major.
    basis: Vec<f64>,
    eigenvalues: Vec<f64>,
    /// C^(−1/2).
    invsqrt: Vec<f64>,
    condition: f64,
    updated_eval: u64,
    current_eval: u64,
    lazy_gap: f64,
    /// The candidates last asked.
    asked: Vec<Vec<f64>>,
    /// Restarts so far.
    pub restarts: u64,
}

/// pyribs's strategy parameters for `mu` parents in `n` dimensions:
/// (weights, μ_eff, c_c, c_σ, c₁, c_μ).
fn params(n: usize, mu: usize) -> (Vec<f64>, f64, f64, f64, f64, f64) {
    let n = n as f64;
    let raw: Vec<f64> = (1..=mu)
        .map(|i| animats_engine::math::log(mu as f64 + 0.5) - animats_engine::math::log(i as f64))
        .collect();
    let total: f64 = raw.iter().sum();
    let w: Vec<f64> = raw.iter().map(|x| x / total).collect();
    let mueff = w.iter().sum::<f64>().powi(2) / w.iter().map(|x| x * x).sum::<f64>();
    let cc = (4.0 + mueff / n) / (n + 4.0 + 2.0 * mueff / n);
    let cs = (mueff + 2.0) / (n + mueff + 5.0);
    let c1 = 2.0 / ((n + 1.3).powi(2) + mueff);
    let cmu = (1.0 - c1).min(2.0 * (mueff - 2.0 + 1.0 / mueff) / ((n + 2.0).powi(2) + mueff));
    (w, mueff, cc, cs, c1, cmu)
}

fn identity(n: usize) -> Vec<f64> {
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        m[i * n + i] = 1.0;
    }
    m
}

impl CmaEmitter {
    /// An emitter of `batch` candidates a generation starting at `x0` with
    /// step `sigma0`; `bounded`: candidates stay in [0, 1]ⁿ.
    pub fn new(x0: &[f64], sigma0: f64, batch: usize, bounded: bool) -> CmaEmitter {
        let n = x0.len();
        let (_, _, _, _, c1, cmu) = params(n, (batch / 2).max(1));
        let nf = n as f64;
        let mut e = CmaEmitter {
            n,
            batch,
            sigma0,
            bounded,
            mean: Vec::new(),
            sigma: sigma0,
            pc: Vec::new(),
            ps: Vec::new(),
            cov: Vec::new(),
            basis: Vec::new(),
            eigenvalues: Vec::new(),
            invsqrt: Vec::new(),
            condition: 1.0,
            updated_eval: 0,
            current_eval: 0,
            lazy_gap: 0.5 * nf * batch as f64 / (c1 + cmu) / (nf * nf),
            asked: Vec::new(),
            restarts: 0,
        };
        e.reset(x0);
        e
    }

    /// A checkpoint's emitter against the one its run's configuration
    /// makes (`fresh`): the same set-up; every vector and matrix of its
    /// genome's size and finite, σ above 0, none or all of a batch asked.
    pub(crate) fn check_state(&self, fresh: &CmaEmitter) -> Result<(), String> {
        check_same(
            "its set-up",
            &(self.n, self.batch, self.sigma0, self.bounded, self.lazy_gap),
            &(
                fresh.n,
                fresh.batch,
                fresh.sigma0,
                fresh.bounded,
                fresh.lazy_gap,
            ),
        )?;
        let n = self.n;
        check_numbers("its mean", &self.mean, n, false)?;
        check_numbers("its σ", &[self.sigma], 1, true)?;
        check_numbers("its evolution path p_c", &self.pc, n, false)?;
        check_numbers("its evolution path p_σ", &self.ps, n, false)?;
        check_numbers("its covariance", &self.cov, n * n, false)?;
        check_numbers("its eigenvectors", &self.basis, n * n, false)?;
        check_numbers("its eigenvalues", &self.eigenvalues, n, false)?;
        check_numbers("its C^(−1/2)", &self.invsqrt, n * n, false)?;
        if self.condition.is_nan() || self.updated_eval > self.current_eval {
            return Err("its eigendecomposition's bookkeeping is malformed".into());
        }
        if !(self.asked.is_empty() || self.asked.len() == self.batch) {
            return Err(format!(
                "{} candidates asked of a batch of {}",
                self.asked.len(),
                self.batch
            ));
        }
        check_genomes("asked candidate", &self.asked, n)
    }

    /// Starts again from `x0` (pyribs's `reset`).
    fn reset(&mut self, x0: &[f64]) {
        let n = self.n;
        self.current_eval = 0;
        self.updated_eval = 0;
        self.sigma = self.sigma0;
        self.mean = x0.to_vec();
        self.pc = vec![0.0; n];
        self.ps = vec![0.0; n];
        self.cov = identity(n);
        self.basis = identity(n);
        self.eigenvalues = vec![1.0; n];
        self.invsqrt = identity(n);
        self.condition = 1.0;
    }

    fn update_eigensystem(&mut self) {
        if (self.current_eval as f64) <= self.updated_eval as f64 + self.lazy_gap {
            return;
        }
        let n = self.n;
        // Symmetric by construction up to rounding: take the upper triangle.
        for i in 0..n {
            for j in 0..i {
                self.cov[i * n + j] = self.cov[j * n + i];
            }
        }
        let (values, vectors) = symmetric_eigen(&self.cov, n);
        self.eigenvalues = values.iter().map(|v| v.abs().max(1e-300)).collect();
        self.basis = vectors;
        let max = self.eigenvalues.iter().cloned().fold(0.0, f64::max);
        let min = self
            .eigenvalues
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min);
        self.condition = max / min;
        for i in 0..n {
            for j in 0..n {
                self.invsqrt[i * n + j] = (0..n)
                    .map(|k| {
                        self.basis[i * n + k] * self.basis[j * n + k] / self.eigenvalues[k].sqrt()
                    })
                    .sum();
            }
        }
        self.updated_eval = self.current_eval;
    }

    /// The next `batch` candidates.
    pub fn ask(&mut self, rng: &mut Random) -> Vec<Vec<f64>> {
        self.update_eigensystem();
        let n = self.n;
        let scale: Vec<f64> = self.eigenvalues.iter().map(|v| v.sqrt()).collect();
        let mut out = Vec::with_capacity(self.batch);
        for _ in 0..self.batch {
            let mut x = vec![0.0; n];
            for attempt in 0..=RESAMPLES {
                let z: Vec<f64> = (0..n).map(|_| self.sigma * gaussian(rng)).collect();
                for (i, xi) in x.iter_mut().enumerate() {
                    *xi = self.mean[i]
                        + (0..n)
                            .map(|k| self.basis[i * n + k] * scale[k] * z[k])
                            .sum::<f64>();
                }
                if !self.bounded || x.iter().all(|v| (0.0..=1.0).contains(v)) {
                    break;
                }
                if attempt == RESAMPLES {
                    for v in &mut x {
                        *v = v.clamp(0.0, 1.0);
                    }
                }
            }
            out.push(x);
        }
        self.asked = out.clone();
        out
    }

    /// Takes what the archive made of the last `ask`'s candidates, in
    /// order; `restart_from` draws an elite (in this emitter's space) when
    /// the emitter must start again. True if it restarted.
    pub fn tell(
        &mut self,
        added: &[Added],
        restart_from: impl FnOnce() -> Option<Vec<f64>>,
    ) -> bool {
        let n = self.n;
        let nf = n as f64;
        let solutions = std::mem::take(&mut self.asked);
        self.current_eval += solutions.len() as u64;
        // 2imp: status first, then value, both descending (stable).
        let mut order: Vec<usize> = (0..added.len()).collect();
        order.sort_by(|&a, &b| {
            added[b]
                .status
                .cmp(&added[a].status)
                .then(added[b].value.total_cmp(&added[a].value))
        });
        let parents = added.iter().filter(|a| a.status > 0).count();
        if parents > 0 {
            let (w, mueff, cc, cs, c1, cmu) = params(n, parents);
            let damps = 1.0 + 2.0 * (((mueff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + cs;
            let old = self.mean.clone();
            let chosen: Vec<&Vec<f64>> = order[..parents].iter().map(|&i| &solutions[i]).collect();
            for i in 0..n {
                self.mean[i] = chosen.iter().zip(&w).map(|(x, wk)| wk * x[i]).sum();
            }
            let y: Vec<f64> = (0..n)
                .map(|i| (self.mean[i] - old[i]) / self.sigma)
                .collect();
            let z: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| self.invsqrt[i * n + j] * y[j]).sum())
                .collect();
            let kps = (cs * (2.0 - cs) * mueff).sqrt();
            for (p, zi) in self.ps.iter_mut().zip(&z) {
                *p = (1.0 - cs) * *p + kps * zi;
            }
            let ps2: f64 = self.ps.iter().map(|v| v * v).sum();
            let gens = self.current_eval as f64 / self.batch as f64;
            let left = ps2 / nf / (1.0 - animats_engine::math::pow(1.0 - cs, 2.0 * gens));
            let hsig = if left < 2.0 + 4.0 / (nf + 1.0) {
                1.0
            } else {
                0.0
            };
            let kpc = hsig * (cc * (2.0 - cc) * mueff).sqrt();
            for (p, yi) in self.pc.iter_mut().zip(&y) {
                *p = (1.0 - cc) * *p + kpc * yi;
            }
            let c1a = c1 * (1.0 - (1.0 - hsig * hsig) * cc * (2.0 - cc));
            let wsum: f64 = w.iter().sum();
            let steps: Vec<Vec<f64>> = chosen
                .iter()
                .map(|x| (0..n).map(|i| (x[i] - old[i]) / self.sigma).collect())
                .collect();
            for i in 0..n {
                for j in i..n {
                    let rank_mu: f64 = steps.iter().zip(&w).map(|(s, wk)| wk * s[i] * s[j]).sum();
                    let v = self.cov[i * n + j] * (1.0 - c1a - cmu * wsum)
                        + c1 * self.pc[i] * self.pc[j]
                        + cmu * rank_mu;
                    self.cov[i * n + j] = v;
                    self.cov[j * n + i] = v;
                }
            }
            self.sigma *=
                animats_engine::math::exp((1.0f64).min(cs / damps * (ps2 / nf - 1.0) / 2.0));
        }
        let spread = match (order.first(), order.last()) {
            (Some(&a), Some(&b)) if order.len() >= 2 => {
                let ds = added[a].status as f64 - added[b].status as f64;
                let dv = added[a].value - added[b].value;
                (ds * ds + dv * dv).sqrt()
            }
            _ => f64::INFINITY,
        };
        let max_eig = self.eigenvalues.iter().cloned().fold(0.0, f64::max);
        let stop = self.condition > 1e14 || self.sigma * max_eig.sqrt() < 1e-11 || spread < 1e-12;
        if stop || parents == 0 || !self.sigma.is_finite() {
            if let Some(x0) = restart_from() {
                self.reset(&x0);
                self.restarts += 1;
                return true;
            }
        }
        false
    }
}
