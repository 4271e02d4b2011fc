//! Receiver operating characteristic of decision values against ground truth, and the area under
//! it, for the ROC curves of McDaniel et al., Fig. 8.

use crate::error::{ClassifyError, Result};

/// The ROC curve of `scores` (higher = more likely positive) against `truth` (true = positive):
/// `(false positive rate, true positive rate)` at every distinct threshold, from `(0, 0)` (nothing
/// called positive) to `(1, 1)` (everything), thresholds descending. Points with equal scores
/// enter together (one step, diagonal where they mix classes). Errors when the lengths differ, a
/// score is NaN, or one class is absent.
pub fn roc_curve(scores: &[f64], truth: &[bool]) -> Result<Vec<(f64, f64)>> {
    if scores.len() != truth.len() {
        return Err(ClassifyError::invalid("roc truth", truth.len(), "as many truth values as scores"));
    }
    if let Some(s) = scores.iter().find(|s| s.is_nan()) {
        return Err(ClassifyError::invalid("roc scores", s, "not NaN"));
    }
    let positives = truth.iter().filter(|&&t| t).count();
    let negatives = truth.len() - positives;
    if positives == 0 || negatives == 0 {
        return Err(ClassifyError::TrainingSet { ground: positives, non_ground: negatives });
    }
    let mut order: Vec<usize> = (0..scores.len()).collect();
    order.sort_by(|&a, &b| scores[b].total_cmp(&scores[a]));
    let mut curve = vec![(0.0, 0.0)];
    let (mut tp, mut fp) = (0usize, 0usize);
    let mut k = 0;
    while k < order.len() {
        let s = scores[order[k]];
        while k < order.len() && scores[order[k]] == s {
            if truth[order[k]] {
                tp += 1;
            } else {
                fp += 1;
            }
            k += 1;
        }
        curve.push((fp as f64 / negatives as f64, tp as f64 / positives as f64));
    }
    Ok(curve)
}

/// Area under a ROC curve (trapezoids between consecutive points, as [`roc_curve`] returns them).
pub fn auc(curve: &[(f64, f64)]) -> f64 {
    curve.windows(2).map(|w| (w[1].0 - w[0].0) * (w[1].1 + w[0].1) * 0.5).sum()
}

/// The highest true positive rate on `curve` at a false positive rate strictly below `max_fpr`.
pub fn tpr_at_fpr_below(curve: &[(f64, f64)], max_fpr: f64) -> f64 {
    curve.iter().filter(|p| p.0 < max_fpr).map(|p| p.1).fold(0.0, f64::max)
}
