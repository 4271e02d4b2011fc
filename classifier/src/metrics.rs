//! Scores of a ground classification against ground truth: confusion counts and the measures of
//! Table I (accuracy Eq. 5, false-positive rate Eq. 6) plus precision, recall, F1 and ground IoU;
//! pooled over frames and as per-frame means; broken down by semantic class and by range band.
//!
//! Positive = ground. Only cells with a return count (no-return cells are neither). A measure whose
//! denominator is zero is reported as NaN by the accessors (e.g. FPR of a frame with no non-ground).

// Parallel per-cell arrays are indexed by cell on purpose (structure of arrays).
#![allow(clippy::needless_range_loop)]

use std::collections::BTreeMap;

use serde::Serialize;
use sim::SemanticClass;

use crate::error::is_valid;

/// Confusion counts (positive = ground).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Confusion {
    /// Ground called ground.
    pub tp: u64,
    /// Non-ground called ground.
    pub fp: u64,
    /// Non-ground called non-ground.
    pub tn: u64,
    /// Ground called non-ground.
    pub fn_: u64,
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 { f64::NAN } else { a as f64 / b as f64 }
}

impl Confusion {
    /// Adds one decision.
    pub fn add(&mut self, truth: bool, predicted: bool) {
        match (truth, predicted) {
            (true, true) => self.tp += 1,
            (false, true) => self.fp += 1,
            (false, false) => self.tn += 1,
            (true, false) => self.fn_ += 1,
        }
    }
    /// Adds other counts.
    pub fn merge(&mut self, o: &Confusion) {
        self.tp += o.tp;
        self.fp += o.fp;
        self.tn += o.tn;
        self.fn_ += o.fn_;
    }
    /// Number of points.
    pub fn total(&self) -> u64 {
        self.tp + self.fp + self.tn + self.fn_
    }
    /// Accuracy (Eq. 5): (TP + TN) / points.
    pub fn accuracy(&self) -> f64 {
        ratio(self.tp + self.tn, self.total())
    }
    /// False-positive rate (Eq. 6): FP / (FP + TN).
    pub fn fpr(&self) -> f64 {
        ratio(self.fp, self.fp + self.tn)
    }
    /// Precision: TP / (TP + FP).
    pub fn precision(&self) -> f64 {
        ratio(self.tp, self.tp + self.fp)
    }
    /// Recall: TP / (TP + FN).
    pub fn recall(&self) -> f64 {
        ratio(self.tp, self.tp + self.fn_)
    }
    /// F1: 2 TP / (2 TP + FP + FN).
    pub fn f1(&self) -> f64 {
        ratio(2 * self.tp, 2 * self.tp + self.fp + self.fn_)
    }
    /// Ground IoU: TP / (TP + FP + FN).
    pub fn iou(&self) -> f64 {
        ratio(self.tp, self.tp + self.fp + self.fn_)
    }
    /// The six measures.
    pub fn scores(&self) -> Scores {
        Scores {
            acc: self.accuracy(),
            fpr: self.fpr(),
            precision: self.precision(),
            recall: self.recall(),
            f1: self.f1(),
            iou: self.iou(),
        }
    }
}

/// The six measures of one evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Scores {
    /// Accuracy.
    pub acc: f64,
    /// False-positive rate.
    pub fpr: f64,
    /// Precision.
    pub precision: f64,
    /// Recall.
    pub recall: f64,
    /// F1.
    pub f1: f64,
    /// Ground IoU.
    pub iou: f64,
}

/// Upper edges of the range bands, metres (the last band is open).
pub const RANGE_BANDS_M: [f32; 4] = [10.0, 20.0, 40.0, 80.0];

/// Index of the range band of a distance.
pub fn range_band(range_m: f32) -> usize {
    RANGE_BANDS_M.iter().position(|&e| range_m < e).unwrap_or(RANGE_BANDS_M.len())
}

/// Name of range band `b`, e.g. `10-20m`.
pub fn range_band_name(b: usize) -> String {
    let lo = if b == 0 { 0.0 } else { RANGE_BANDS_M[b - 1] };
    match RANGE_BANDS_M.get(b) {
        Some(hi) => format!("{lo}-{hi}m"),
        None => format!("{lo}m+"),
    }
}

/// Scores accumulated over frames.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Evaluation {
    /// Pooled counts over all frames.
    pub pooled: Confusion,
    /// Counts per frame.
    pub per_frame: Vec<Confusion>,
    /// Pooled counts per semantic class (by id).
    pub by_class: BTreeMap<u16, Confusion>,
    /// Pooled counts per range band ([`RANGE_BANDS_M`]).
    pub by_range: Vec<Confusion>,
}

impl Evaluation {
    /// Adds a frame: `predicted[i]` for every cell of `cloud`. Range is the cell's `range_m` where
    /// finite, else its distance from the vehicle origin.
    pub fn add_frame(&mut self, cloud: &sim::OrderedCloud, predicted: &[bool]) {
        let mut frame = Confusion::default();
        self.by_range.resize(RANGE_BANDS_M.len() + 1, Confusion::default());
        for i in 0..cloud.len().min(predicted.len()) {
            let p = cloud.point_in_vehicle[i];
            if !is_valid(p) {
                continue;
            }
            let (t, y) = (cloud.ground[i], predicted[i]);
            frame.add(t, y);
            self.by_class.entry(cloud.label[i].0).or_default().add(t, y);
            let r = if cloud.range_m[i].is_finite() { cloud.range_m[i] } else { p.length() };
            self.by_range[range_band(r)].add(t, y);
        }
        self.pooled.merge(&frame);
        self.per_frame.push(frame);
    }

    /// Mean of each measure over the frames (frames where a measure is NaN are left out of its mean).
    pub fn per_frame_mean(&self) -> Scores {
        let mean = |f: fn(&Confusion) -> f64| {
            let v: Vec<f64> = self.per_frame.iter().map(f).filter(|x| x.is_finite()).collect();
            if v.is_empty() { f64::NAN } else { v.iter().sum::<f64>() / v.len() as f64 }
        };
        Scores {
            acc: mean(Confusion::accuracy),
            fpr: mean(Confusion::fpr),
            precision: mean(Confusion::precision),
            recall: mean(Confusion::recall),
            f1: mean(Confusion::f1),
            iou: mean(Confusion::iou),
        }
    }

    /// Class name of a class id (SemanticKITTI).
    pub fn class_name(id: u16) -> &'static str {
        SemanticClass(id).name()
    }
}
