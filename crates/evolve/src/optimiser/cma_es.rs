//! CMA-ES (Hansen's (μ/μ_w, λ) evolution strategy with cumulative step-size
//! adaptation, rank-one and rank-μ updates), written from Hansen's tutorial
//! "The CMA Evolution Strategy: A Tutorial" (2016, Table 1): default
//! λ = 4 + ⌊3 ln n⌋, μ = ⌊λ/2⌋, log-linear weights, and *active* covariance
//! adaptation as pycma does by default: the worse half of each generation
//! gets negative weights (scaled as the tutorial's α⁻ terms say, and each
//! of those steps rescaled to length √n in C's metric) that shrink C along
//! directions that failed. The eigendecomposition of C is refreshed every
//! `λ / (c1 + cμ) / n / 10` evaluations ([`super::eigen`]: Jacobi
//! rotations up to 64 genes, Householder and QL above; both the same bits
//! on every platform).
//!
//! It minimises internally; [`Optimiser`] maximises, so fitness is negated.
//!
//! **Restarts** (IPOP, Auger & Hansen 2005), when asked for: a run that has
//! converged (σ × the largest axis of C below 1e-12 × σ₀), whose C is
//! ill-conditioned (condition number above 1e14), or that has not improved
//! its best for `100 + 30 n / λ` generations starts again with twice the
//! population, from a point drawn uniformly in the bounds (without bounds,
//! from the start), with σ₀. The best so far is kept across restarts.
//! Whether or not restarts were asked for, a state that has broken down
//! numerically (σ beyond 1e8 σ₀, or anything non-finite: what a run does
//! long after it has converged) starts afresh from the best so far with the
//! same population, so that a long evolution never asks for NaN.
//!
//! **Bounds**, when given, are handled in the unit box: the strategy works
//! on `y` with `genome = lo + (hi − lo) y`, starts at the start genome with
//! step size σ₀ (default 0.3) in those units, evaluates the candidate
//! repaired into the box, and ranks it by its value plus a penalty
//! `γ ‖y − repair(y)‖²`, with γ the inter-quartile range of the
//! generation's values (at least 1e-9 × max(1, |median|)), so that a
//! candidate outside the box ranks below an equal one inside.

use super::eigen::symmetric_eigen;
use super::{
    check_genomes, check_numbers, check_same, check_told, gaussian, sane, BestSoFar, Bounds,
    Optimiser, Random, Setup,
};
use animats_engine::math;
use serde::{Deserialize, Serialize};

/// CMA-ES's whole state (what a checkpoint stores).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CmaEs {
    seed: u64,
    lane: usize,
    n: usize,
    lambda: usize,
    weights: Vec<f64>,
    mueff: f64,
    cc: f64,
    cs: f64,
    c1: f64,
    cmu: f64,
    damps: f64,
    chi_n: f64,
    bounds: Option<Bounds>,
    /// Mean, in the strategy's coordinates.
    mean: Vec<f64>,
    /// Step size.
    pub sigma: f64,
    /// Covariance, row-major n × n.
    c: Vec<f64>,
    /// Eigenvectors of C (columns), row-major.
    b: Vec<f64>,
    /// Square roots of C's eigenvalues.
    d: Vec<f64>,
    pc: Vec<f64>,
    ps: Vec<f64>,
    counteval: u64,
    eigeneval: u64,
    generation: u64,
    pending: Vec<Vec<f64>>,
    best: BestSoFar,
    /// Where the first run started (a genome), for restarts without bounds.
    #[serde(default)]
    start: Vec<f64>,
    /// σ₀.
    #[serde(default)]
    sigma0: f64,
    /// Restarts still allowed.
    #[serde(default)]
    restarts_left: u32,
    /// Restarts done.
    #[serde(default)]
    pub restarts_done: u32,
    /// The best value (minimised) of this run, and generations since it improved.
    #[serde(default)]
    run_best: Option<f64>,
    #[serde(default)]
    stale: u64,
}

/// The strategy parameters of `λ` candidates in `n` dimensions (Hansen's
/// Table 1, with active CMA's negative weights).
#[derive(PartialEq)]
struct Parameters {
    weights: Vec<f64>,
    mueff: f64,
    cc: f64,
    cs: f64,
    c1: f64,
    cmu: f64,
    damps: f64,
    chi_n: f64,
}

impl Parameters {
    fn of(n: usize, lambda: usize) -> Parameters {
        let nf = n as f64;
        let mu = lambda / 2;
        let raw: Vec<f64> = (0..lambda)
            .map(|i| {
                animats_engine::math::log((lambda as f64 + 1.0) / 2.0)
                    - animats_engine::math::log(i as f64 + 1.0)
            })
            .collect();
        let (pos, neg) = raw.split_at(mu);
        let mu_eff =
            |w: &[f64]| w.iter().sum::<f64>().powi(2) / w.iter().map(|x| x * x).sum::<f64>();
        let mueff = mu_eff(pos);
        let cc = (4.0 + mueff / nf) / (nf + 4.0 + 2.0 * mueff / nf);
        let cs = (mueff + 2.0) / (nf + mueff + 5.0);
        let c1 = 2.0 / ((nf + 1.3).powi(2) + mueff);
        let cmu = (1.0 - c1).min(2.0 * (mueff - 2.0 + 1.0 / mueff) / ((nf + 2.0).powi(2) + mueff));
        // Negative weights for the worse half (Table 1): the smallest of
        // α_μ⁻, α_μeff⁻ and α_posdef⁻ over the sum of their magnitudes.
        let pos_sum: f64 = pos.iter().sum();
        let neg_sum: f64 = neg.iter().map(|w| w.abs()).sum();
        let alpha = if neg.iter().any(|w| *w < 0.0) && cmu > 0.0 {
            let mueff_neg = mu_eff(neg);
            (1.0 + c1 / cmu)
                .min(1.0 + 2.0 * mueff_neg / (mueff + 2.0))
                .min((1.0 - c1 - cmu) / (nf * cmu))
        } else {
            0.0
        };
        let weights: Vec<f64> = raw
            .iter()
            .map(|&w| {
                if w >= 0.0 {
                    w / pos_sum
                } else {
                    alpha * w / neg_sum
                }
            })
            .collect();
        let damps = 1.0 + 2.0 * (((mueff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + cs;
        let chi_n = nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf));
        Parameters {
            weights,
            mueff,
            cc,
            cs,
            c1,
            cmu,
            damps,
            chi_n,
        }
    }
}

impl CmaEs {
    /// A fresh strategy from a setup.
    pub fn new(s: &Setup) -> CmaEs {
        let n = s.start.len();
        let lambda = s
            .population
            .unwrap_or_else(|| crate::optimiser::cma_default_lambda(n))
            .max(2);
        let p = Parameters::of(n, lambda);
        let mean = match &s.bounds {
            Some(bd) => s
                .start
                .iter()
                .enumerate()
                .map(|(i, x)| (x - bd.lo[i]) / bd.width(i))
                .collect(),
            None => s.start.clone(),
        };
        let mut eye = vec![0.0; n * n];
        for i in 0..n {
            eye[i * n + i] = 1.0;
        }
        CmaEs {
            seed: s.seed,
            lane: s.lane,
            n,
            lambda,
            weights: p.weights,
            mueff: p.mueff,
            cc: p.cc,
            cs: p.cs,
            c1: p.c1,
            cmu: p.cmu,
            damps: p.damps,
            chi_n: p.chi_n,
            bounds: s.bounds.clone(),
            mean,
            sigma: s.sigma.unwrap_or(0.3),
            c: eye.clone(),
            b: eye,
            d: vec![1.0; n],
            pc: vec![0.0; n],
            ps: vec![0.0; n],
            counteval: 0,
            eigeneval: 0,
            generation: 0,
            pending: Vec::new(),
            best: BestSoFar::default(),
            start: s.start.clone(),
            sigma0: s.sigma.unwrap_or(0.3),
            restarts_left: s.restarts,
            restarts_done: 0,
            run_best: None,
            stale: 0,
        }
    }

    /// A checkpoint's strategy against the one its run's configuration
    /// makes (`fresh`): the same set-up; a population of the configured
    /// one doubled at each restart done, with the parameters that
    /// population gives; every vector and matrix of its genome's size and
    /// finite, σ and the axes' lengths above 0.
    pub(crate) fn check_state(&self, fresh: &CmaEs) -> Result<(), String> {
        check_same(
            "its seed and lane",
            &(self.seed, self.lane),
            &(fresh.seed, fresh.lane),
        )?;
        check_same(
            "its start",
            &(self.n, &self.start),
            &(fresh.n, &fresh.start),
        )?;
        check_same("its bounds", &self.bounds, &fresh.bounds)?;
        check_same("its initial step size", &self.sigma0, &fresh.sigma0)?;
        let restarts = self.restarts_done.checked_add(self.restarts_left);
        check_same("its restarts", &restarts, &Some(fresh.restarts_left))?;
        // (IPOP doubles the population at each restart; a run of 2^24
        // candidates a generation is not one that ran.)
        let lambda = fresh
            .lambda
            .checked_shl(self.restarts_done)
            .filter(|l| *l <= 1 << 24 && l >> self.restarts_done == fresh.lambda);
        check_same("its population", &Some(self.lambda), &lambda)?;
        let derived = Parameters {
            weights: self.weights.clone(),
            mueff: self.mueff,
            cc: self.cc,
            cs: self.cs,
            c1: self.c1,
            cmu: self.cmu,
            damps: self.damps,
            chi_n: self.chi_n,
        };
        if derived != Parameters::of(self.n, self.lambda) {
            return Err("its weights and learning rates are not what its population gives".into());
        }
        let n = self.n;
        check_numbers("its mean", &self.mean, n, false)?;
        check_numbers("its σ", &[self.sigma], 1, true)?;
        check_numbers("its covariance", &self.c, n * n, false)?;
        check_numbers("its eigenvectors", &self.b, n * n, false)?;
        check_numbers("its axes' lengths", &self.d, n, true)?;
        check_numbers("its evolution path p_c", &self.pc, n, false)?;
        check_numbers("its evolution path p_σ", &self.ps, n, false)?;
        if !(self.pending.is_empty() || self.pending.len() == self.lambda) {
            return Err(format!(
                "{} candidates pending in a population of {}",
                self.pending.len(),
                self.lambda
            ));
        }
        check_genomes("pending candidate", &self.pending, n)?;
        if self.eigeneval > self.counteval {
            return Err("its eigendecomposition is from evaluations not yet made".into());
        }
        self.best.check(Some(n))
    }

    /// Whether this run is done: converged, ill-conditioned or stagnant.
    fn run_is_over(&self) -> bool {
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for d in &self.d {
            lo = lo.min(*d);
            hi = hi.max(*d);
        }
        let patience = 100 + (30 * self.n).div_ceil(self.lambda) as u64;
        self.sigma * hi < 1e-12 * self.sigma0 || hi > 1e7 * lo || self.stale >= patience
    }

    /// Whether the state has broken down numerically: σ beyond 1e8 × σ₀ or
    /// anything non-finite. Long after a run has converged, with the fitness
    /// flat to the last bit, σ drifts up as C's axes shrink until σ
    /// overflows.
    fn broken(&self) -> bool {
        !(self.sigma.is_finite() && self.sigma <= 1e8 * self.sigma0)
            || self.mean.iter().chain(&self.c).any(|x| !x.is_finite())
    }

    /// Starts a new run of population `lambda`, keeping the best, the
    /// generation count and the random streams' names: an IPOP restart from
    /// a random point in the bounds (`random`), or a fresh run from the best
    /// so far.
    fn restart(&mut self, lambda: usize, random: bool, restarts_left: u32) {
        let mut rng = Random::for_evaluation(self.seed ^ 0x4950_4f50, self.lane, self.generation);
        let start = match (&self.bounds, random, self.best.get()) {
            (Some(b), true, _) => (0..self.n)
                .map(|i| b.lo[i] + b.width(i) * rng.uniform())
                .collect(),
            (_, false, Some((best, _))) => best.to_vec(),
            _ => self.start.clone(),
        };
        let setup = Setup {
            kind: crate::optimiser::OptimiserKind::CmaEs,
            start,
            bounds: self.bounds.clone(),
            population: Some(lambda),
            seed: self.seed,
            lane: self.lane,
            sigma: Some(self.sigma0),
            restarts: restarts_left,
        };
        let mut next = CmaEs::new(&setup);
        next.generation = self.generation;
        next.best = std::mem::take(&mut self.best);
        next.start = std::mem::take(&mut self.start);
        next.restarts_done = self.restarts_done + u32::from(random);
        *self = next;
    }

    /// Candidates per generation.
    pub fn lambda(&self) -> usize {
        self.lambda
    }

    /// The current mean, as a genome.
    pub fn mean(&self) -> Vec<f64> {
        self.to_genome(&self.mean)
    }

    fn to_genome(&self, y: &[f64]) -> Vec<f64> {
        match &self.bounds {
            Some(bd) => y
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    // Clamped again: lo + width rounds past hi by an ulp.
                    (bd.lo[i] + bd.width(i) * v.clamp(0.0, 1.0)).clamp(bd.lo[i], bd.hi[i])
                })
                .collect(),
            None => y.to_vec(),
        }
    }

    fn outside(&self, y: &[f64]) -> f64 {
        match &self.bounds {
            Some(_) => y.iter().map(|v| (v - v.clamp(0.0, 1.0)).powi(2)).sum(),
            None => 0.0,
        }
    }

    fn refresh_eigen(&mut self) {
        let n = self.n;
        // Keep C exactly symmetric before decomposing it.
        for i in 0..n {
            for j in 0..i {
                let v = 0.5 * (self.c[i * n + j] + self.c[j * n + i]);
                self.c[i * n + j] = v;
                self.c[j * n + i] = v;
            }
        }
        let (values, vectors) = symmetric_eigen(&self.c, n);
        self.d = values.iter().map(|v| v.max(1e-300).sqrt()).collect();
        self.b = vectors;
    }
}

impl CmaEs {
    /// The values to minimise of the pending candidates told `fitness`
    /// (−fitness, −∞ fitness → +∞, ranked last, plus the bound penalty),
    /// and the candidates in their order, best first (the first of equals).
    fn rank(&self, fitness: &[f64]) -> (Vec<f64>, Vec<usize>) {
        let mut values: Vec<f64> = fitness.iter().map(|f| -sane(*f)).collect();
        if self.bounds.is_some() {
            let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
            finite.sort_by(f64::total_cmp);
            let q = |p: f64| {
                if finite.is_empty() {
                    0.0
                } else {
                    finite[((finite.len() - 1) as f64 * p).round() as usize]
                }
            };
            let gamma = (q(0.75) - q(0.25)).max(1e-9 * q(0.5).abs().max(1.0));
            for (v, y) in values.iter_mut().zip(&self.pending) {
                *v += gamma * self.outside(y);
            }
        }
        let mut order: Vec<usize> = (0..self.lambda).collect();
        order.sort_by(|&a, &b| values[a].total_cmp(&values[b]).then(a.cmp(&b)));
        (values, order)
    }

    /// Moves the mean to the weighted recombination of the best (positive
    /// weights only); returns the old mean and the step `y_w`.
    fn move_mean(&mut self, order: &[usize]) -> (Vec<f64>, Vec<f64>) {
        let n = self.n;
        let old = self.mean.clone();
        let mut mean = vec![0.0; n];
        for (w, &k) in self.weights.iter().zip(order).filter(|(w, _)| **w > 0.0) {
            for (m, y) in mean.iter_mut().zip(&self.pending[k]) {
                *m += w * y;
            }
        }
        self.mean = mean;
        let yw = (0..n)
            .map(|i| (self.mean[i] - old[i]) / self.sigma)
            .collect();
        (old, yw)
    }

    /// The evolution paths after step `yw`; returns |p_σ|² and h_σ (1 or 0).
    fn update_paths(&mut self, yw: &[f64]) -> (f64, f64) {
        let n = self.n;
        // C^{-1/2} y_w = B D^{-1} Bᵀ y_w
        let mut bt = vec![0.0; n];
        for (j, v) in bt.iter_mut().enumerate() {
            let mut s = 0.0;
            for (i, y) in yw.iter().enumerate() {
                s += self.b[i * n + j] * y;
            }
            *v = s / self.d[j];
        }
        let ks = (self.cs * (2.0 - self.cs) * self.mueff).sqrt();
        for i in 0..n {
            let mut s = 0.0;
            for (j, v) in bt.iter().enumerate() {
                s += self.b[i * n + j] * v;
            }
            self.ps[i] = (1.0 - self.cs) * self.ps[i] + ks * s;
        }
        let ps2: f64 = self.ps.iter().map(|v| v * v).sum();
        let gens = self.counteval as f64 / self.lambda as f64;
        let hsig = ps2 / n as f64 / (1.0 - math::pow(1.0 - self.cs, 2.0 * gens))
            < 2.0 + 4.0 / (n as f64 + 1.0);
        let hsig = if hsig { 1.0 } else { 0.0 };
        let kc = (self.cc * (2.0 - self.cc) * self.mueff).sqrt();
        for (p, y) in self.pc.iter_mut().zip(yw) {
            *p = (1.0 - self.cc) * *p + hsig * kc * y;
        }
        (ps2, hsig)
    }

    /// The covariance's rank-one and rank-μ update, the candidates in
    /// `order` stepping from the `old` mean.
    fn update_covariance(&mut self, order: &[usize], old: &[f64], hsig: f64) {
        let n = self.n;
        let (c1, cmu) = (self.c1, self.cmu);
        let c1a = c1 * (1.0 - (1.0 - hsig * hsig) * self.cc * (2.0 - self.cc));
        let steps: Vec<Vec<f64>> = order
            .iter()
            .map(|&k| {
                self.pending[k]
                    .iter()
                    .zip(old)
                    .map(|(y, m)| (y - m) / self.sigma)
                    .collect()
            })
            .collect();
        // A negative weight's step is rescaled to length √n in C's metric
        // (w° = w n / |C^{-1/2} y|²), so that C stays positive definite.
        let scaled: Vec<f64> = self
            .weights
            .iter()
            .zip(&steps)
            .map(|(&w, y)| {
                if w >= 0.0 {
                    w
                } else {
                    let mut norm2 = 0.0;
                    for j in 0..n {
                        let mut s = 0.0;
                        for (i, yi) in y.iter().enumerate() {
                            s += self.b[i * n + j] * yi;
                        }
                        norm2 += (s / self.d[j]).powi(2);
                    }
                    w * n as f64 / norm2.max(1e-300)
                }
            })
            .collect();
        let weight_sum: f64 = self.weights.iter().sum();
        for i in 0..n {
            for j in 0..=i {
                let mut rank_mu = 0.0;
                for (w, s) in scaled.iter().zip(&steps) {
                    rank_mu += w * s[i] * s[j];
                }
                let v = (1.0 - c1a - cmu * weight_sum) * self.c[i * n + j]
                    + c1 * self.pc[i] * self.pc[j]
                    + cmu * rank_mu;
                self.c[i * n + j] = v;
                self.c[j * n + i] = v;
            }
        }
    }
}

impl Optimiser for CmaEs {
    fn ask(&mut self) -> Vec<Vec<f64>> {
        let n = self.n;
        let generation = self.generation + 1;
        let mut rng = Random::for_evaluation(self.seed, self.lane, generation);
        let mut out = Vec::with_capacity(self.lambda);
        self.pending.clear();
        for _ in 0..self.lambda {
            let z: Vec<f64> = (0..n).map(|_| gaussian(&mut rng)).collect();
            let y: Vec<f64> = (0..n)
                .map(|i| {
                    let mut s = 0.0;
                    for (j, zj) in z.iter().enumerate() {
                        s += self.b[i * n + j] * self.d[j] * zj;
                    }
                    self.mean[i] + self.sigma * s
                })
                .collect();
            out.push(self.to_genome(&y));
            self.pending.push(y);
        }
        out
    }

    fn tell(&mut self, fitness: &[f64]) -> Result<(), String> {
        check_told(self.pending.len(), fitness.len())?;
        for (y, f) in self.pending.iter().zip(fitness) {
            let g = self.to_genome(y);
            self.best.offer(&g, *f);
        }
        let (values, order) = self.rank(fitness);
        self.counteval += self.lambda as u64;
        let (old, yw) = self.move_mean(&order);
        let (ps2, hsig) = self.update_paths(&yw);
        self.update_covariance(&order, &old, hsig);
        self.sigma *=
            animats_engine::math::exp((self.cs / self.damps) * (ps2.sqrt() / self.chi_n - 1.0));
        let (n, lambda) = (self.n as f64, self.lambda as f64);
        if (self.counteval - self.eigeneval) as f64 > lambda / (self.c1 + self.cmu) / n / 10.0 {
            self.eigeneval = self.counteval;
            self.refresh_eigen();
        }
        self.pending.clear();
        self.generation += 1;
        if self.restarts_left > 0 {
            let top = values[order[0]];
            if self.run_best.is_none_or(|b| top < b) {
                self.run_best = Some(top);
                self.stale = 0;
            } else {
                self.stale += 1;
            }
            if self.run_is_over() || self.broken() {
                let left = self.restarts_left - 1;
                self.restart(2 * self.lambda, true, left);
                return Ok(());
            }
        }
        if self.broken() {
            self.restart(self.lambda, false, 0);
        }
        Ok(())
    }

    fn best(&self) -> Option<(&[f64], f64)> {
        self.best.get()
    }

    fn generation(&self) -> u64 {
        self.generation
    }
}
