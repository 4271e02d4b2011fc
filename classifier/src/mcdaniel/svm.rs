//! A linear support vector machine trained by dual coordinate descent (Hsieh, Chang, Lin, Keerthi
//! and Sundararajan, *A Dual Coordinate Descent Method for Large-scale Linear SVM*, ICML 2008), the
//! solver of LIBLINEAR's `-s 3` (L2-regularised L1-loss, i.e. hinge-loss, SVC in the dual):
//!
//! `min_w 1/2 |w|^2 + C sum_i max(0, 1 - y_i w . x_i)`,
//!
//! with the bias as an extra constant feature 1 appended to every `x_i` (LIBLINEAR's `-B 1`; the
//! bias is regularised like the weights, as there). The dual variables `alpha_i in [0, C]` are
//! visited in a random order each outer iteration (a permutation drawn from a seeded
//! Xoshiro256PlusPlus, so training is deterministic), with LIBLINEAR's shrinking of variables that
//! sit at a bound. It stops when the projected gradient's spread `max PG - min PG` falls to
//! [`SvmParams::eps`] on the full set (LIBLINEAR's criterion) or after [`SvmParams::max_iter`]
//! outer iterations.

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::error::{ClassifyError, Result};

/// Training parameters of [`train_linear_svm`].
#[derive(Clone, Debug, PartialEq)]
pub struct SvmParams {
    /// Cost `C` of a margin violation (> 0; McDaniel et al. use 100).
    pub c: f64,
    /// Stopping tolerance on the projected gradient's spread (> 0; LIBLINEAR's default for `-s 3`
    /// is 0.1; ours is 0.01 for a tighter optimum on a few thousand points).
    pub eps: f64,
    /// Most outer iterations (passes over the (shrunk) active set; 1 ..= 1000000). LIBLINEAR stops
    /// at 1000; at C = 100 on overlapping classes that leaves the dual far from converged (two
    /// forests need 60,000-112,000 passes, most variables shrunk away: about 0.2 s for 4,000
    /// candidates), so ours is 300,000.
    pub max_iter: usize,
    /// Seed of the visiting order.
    pub seed: u64,
    /// Shrink variables at a bound (LIBLINEAR does; the optimum is the same).
    pub shrinking: bool,
}

impl Default for SvmParams {
    fn default() -> Self {
        Self { c: 100.0, eps: 0.01, max_iter: 300_000, seed: 0, shrinking: true }
    }
}

impl SvmParams {
    /// Checks every field, naming it and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if !(self.c.is_finite() && self.c > 0.0) {
            return Err(ClassifyError::invalid("svm.c", self.c, "finite, > 0"));
        }
        if !(self.eps.is_finite() && self.eps > 0.0) {
            return Err(ClassifyError::invalid("svm.eps", self.eps, "finite, > 0"));
        }
        if self.max_iter == 0 || self.max_iter > 1_000_000 {
            return Err(ClassifyError::invalid("svm.max_iter", self.max_iter, "1 ..= 1000000"));
        }
        Ok(())
    }
}

/// A trained linear SVM: decision value `w . x + b`, positive class where it is > 0.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearSvm {
    /// Weights, one per feature.
    pub weights: Vec<f64>,
    /// Bias `b` (the weight of the constant feature 1).
    pub bias: f64,
    /// Outer iterations run.
    pub iterations: usize,
    /// Whether the stopping tolerance was reached (false: stopped at `max_iter`).
    pub converged: bool,
}

impl LinearSvm {
    /// The decision value `w . x + b`.
    pub fn decision_value(&self, x: &[f64]) -> f64 {
        self.weights.iter().zip(x).map(|(w, v)| w * v).sum::<f64>() + self.bias
    }
}

/// Trains a linear SVM on `n = y.len()` points of `dim` features, stored row by row in `x`
/// (`x.len() == n * dim`); `y[i]` true is the positive class. Errors when the sizes disagree, a
/// feature is not finite, or one class is absent.
pub fn train_linear_svm(x: &[f64], dim: usize, y: &[bool], params: &SvmParams) -> Result<LinearSvm> {
    params.validate()?;
    let n = y.len();
    if dim == 0 || x.len() != n * dim {
        return Err(ClassifyError::invalid(
            "svm training set",
            format!("{} values for {n} points", x.len()),
            "points x features",
        ));
    }
    if let Some(v) = x.iter().find(|v| !v.is_finite()) {
        return Err(ClassifyError::invalid("svm training set", v, "finite feature values"));
    }
    let positives = y.iter().filter(|&&b| b).count();
    if positives == 0 || positives == n {
        return Err(ClassifyError::TrainingSet { ground: positives, non_ground: n - positives });
    }
    let c = params.c;
    let row = |i: usize| &x[i * dim..(i + 1) * dim];
    let sign = |i: usize| if y[i] { 1.0 } else { -1.0 };
    // Q_ii = x_i . x_i + 1 (the bias feature).
    let qd: Vec<f64> = (0..n).map(|i| row(i).iter().map(|v| v * v).sum::<f64>() + 1.0).collect();
    let mut w = vec![0.0f64; dim];
    let mut b = 0.0f64;
    let mut alpha = vec![0.0f64; n];
    let mut index: Vec<usize> = (0..n).collect();
    let mut active = n;
    let mut pg_max_old = f64::INFINITY;
    let mut pg_min_old = f64::NEG_INFINITY;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(params.seed);
    let mut iter = 0;
    let mut converged = false;
    while iter < params.max_iter {
        let mut pg_max_new = f64::NEG_INFINITY;
        let mut pg_min_new = f64::INFINITY;
        for s in 0..active {
            let j = s + rng.random_range(0..active - s);
            index.swap(s, j);
        }
        let mut s = 0;
        while s < active {
            let i = index[s];
            let yi = sign(i);
            let xi = row(i);
            let g = yi * (w.iter().zip(xi).map(|(a, v)| a * v).sum::<f64>() + b) - 1.0;
            let mut pg = 0.0;
            if alpha[i] == 0.0 {
                if params.shrinking && g > pg_max_old {
                    active -= 1;
                    index.swap(s, active);
                    continue;
                } else if g < 0.0 {
                    pg = g;
                }
            } else if alpha[i] == c {
                if params.shrinking && g < pg_min_old {
                    active -= 1;
                    index.swap(s, active);
                    continue;
                } else if g > 0.0 {
                    pg = g;
                }
            } else {
                pg = g;
            }
            pg_max_new = pg_max_new.max(pg);
            pg_min_new = pg_min_new.min(pg);
            if pg.abs() > 1e-12 {
                let old = alpha[i];
                alpha[i] = (old - g / qd[i]).clamp(0.0, c);
                let d = (alpha[i] - old) * yi;
                for (a, v) in w.iter_mut().zip(xi) {
                    *a += d * v;
                }
                b += d;
            }
            s += 1;
        }
        iter += 1;
        if pg_max_new - pg_min_new <= params.eps {
            if active == n {
                converged = true;
                break;
            }
            active = n;
            pg_max_old = f64::INFINITY;
            pg_min_old = f64::NEG_INFINITY;
            continue;
        }
        pg_max_old = if pg_max_new <= 0.0 { f64::INFINITY } else { pg_max_new };
        pg_min_old = if pg_min_new >= 0.0 { f64::NEG_INFINITY } else { pg_min_new };
    }
    Ok(LinearSvm { weights: w, bias: b, iterations: iter, converged })
}

/// The primal objective `1/2 (|w|^2 + b^2) + C sum_i max(0, 1 - y_i (w . x_i + b))` of a model
/// (the bias regularised, as in training), to compare solvers.
pub fn primal_objective(svm: &LinearSvm, x: &[f64], dim: usize, y: &[bool], c: f64) -> f64 {
    let reg = 0.5 * (svm.weights.iter().map(|w| w * w).sum::<f64>() + svm.bias * svm.bias);
    let loss: f64 = (0..y.len())
        .map(|i| {
            let yi = if y[i] { 1.0 } else { -1.0 };
            (1.0 - yi * svm.decision_value(&x[i * dim..(i + 1) * dim])).max(0.0)
        })
        .sum();
    reg + c * loss
}
