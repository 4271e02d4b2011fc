//! Scores of ground decisions over a region: counts, recall, false-ground rate, precision, F1.

use std::fmt;

/// Confusion counts of ground decisions over one region, pooled over the scan's frames. "Positive"
/// is ground: `tp` ground returns called ground, `fn_` ground returns missed, `fp` non-ground returns
/// called ground, `tn` non-ground returns rejected.
///
/// A rate whose denominator is zero is NaN (e.g. the recall of a region without ground), so an
/// assertion like `recall() >= 0.9` fails rather than passing vacuously.
///
/// ```
/// use groundtruth_scenario::RegionScore;
/// let s = RegionScore { region: "demo".into(), tp: 90, fn_: 10, fp: 5, tn: 95 };
/// assert_eq!(s.returns(), 200);
/// assert_eq!(s.recall(), 0.9);
/// assert_eq!(s.false_ground_rate(), 0.05);
/// assert!((s.f1() - 2.0 * 0.9 * (90.0 / 95.0) / (0.9 + 90.0 / 95.0)).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RegionScore {
    /// The region's name.
    pub region: String,
    /// Ground returns called ground.
    pub tp: u64,
    /// Ground returns called non-ground (missed ground).
    pub fn_: u64,
    /// Non-ground returns called ground (false ground).
    pub fp: u64,
    /// Non-ground returns called non-ground.
    pub tn: u64,
}

impl RegionScore {
    /// Adds one decision on a return whose truth is `ground`.
    ///
    /// ```
    /// let mut s = groundtruth_scenario::RegionScore::default();
    /// s.add(true, true);
    /// s.add(false, true);
    /// assert_eq!((s.tp, s.fp), (1, 1));
    /// ```
    pub fn add(&mut self, ground: bool, called_ground: bool) {
        let mut c = self.counts();
        c.add(ground, called_ground);
        (self.tp, self.fp, self.tn, self.fn_) = (c.tp, c.fp, c.tn, c.fn_);
    }

    /// The counts as the classifier's metrics hold them (whose rates these are).
    pub fn counts(&self) -> classifier::Confusion {
        classifier::Confusion { tp: self.tp, fp: self.fp, tn: self.tn, fn_: self.fn_ }
    }

    /// Returns in the region.
    ///
    /// ```
    /// let s = groundtruth_scenario::RegionScore { tp: 1, fn_: 2, fp: 3, tn: 4, ..Default::default() };
    /// assert_eq!(s.returns(), 10);
    /// ```
    pub fn returns(&self) -> u64 {
        self.counts().total()
    }

    /// Ground returns in the region (`tp + fn_`).
    ///
    /// ```
    /// let s = groundtruth_scenario::RegionScore { tp: 1, fn_: 2, fp: 3, tn: 4, ..Default::default() };
    /// assert_eq!(s.ground(), 3);
    /// ```
    pub fn ground(&self) -> u64 {
        self.tp + self.fn_
    }

    /// Non-ground returns in the region (`fp + tn`).
    ///
    /// ```
    /// let s = groundtruth_scenario::RegionScore { tp: 1, fn_: 2, fp: 3, tn: 4, ..Default::default() };
    /// assert_eq!(s.non_ground(), 7);
    /// ```
    pub fn non_ground(&self) -> u64 {
        self.fp + self.tn
    }

    /// Share of the ground returns called ground, `tp / (tp + fn_)`; NaN without ground.
    ///
    /// ```
    /// let s = groundtruth_scenario::RegionScore { tp: 3, fn_: 1, ..Default::default() };
    /// assert_eq!(s.recall(), 0.75);
    /// ```
    pub fn recall(&self) -> f64 {
        self.counts().recall()
    }

    /// Share of the non-ground returns called ground, `fp / (fp + tn)`; NaN without non-ground.
    ///
    /// ```
    /// let s = groundtruth_scenario::RegionScore { fp: 1, tn: 19, ..Default::default() };
    /// assert_eq!(s.false_ground_rate(), 0.05);
    /// ```
    pub fn false_ground_rate(&self) -> f64 {
        self.counts().fpr()
    }

    /// Share of the returns called ground that are ground, `tp / (tp + fp)`; NaN if none was.
    ///
    /// ```
    /// let s = groundtruth_scenario::RegionScore { tp: 3, fp: 1, ..Default::default() };
    /// assert_eq!(s.precision(), 0.75);
    /// ```
    pub fn precision(&self) -> f64 {
        self.counts().precision()
    }

    /// F1 of the ground class, `2 tp / (2 tp + fp + fn_)`; NaN when all three are zero.
    ///
    /// ```
    /// let s = groundtruth_scenario::RegionScore { tp: 8, fp: 2, fn_: 2, ..Default::default() };
    /// assert_eq!(s.f1(), 0.8);
    /// ```
    pub fn f1(&self) -> f64 {
        self.counts().f1()
    }

    /// Share of the region's returns decided right, `(tp + tn) / returns`.
    ///
    /// ```
    /// let s = groundtruth_scenario::RegionScore { tp: 8, tn: 1, fp: 1, ..Default::default() };
    /// assert_eq!(s.accuracy(), 0.9);
    /// ```
    pub fn accuracy(&self) -> f64 {
        self.counts().accuracy()
    }
}

impl fmt::Display for RegionScore {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: {} returns ({} ground): recall {:.4}, false-ground rate {:.4}, precision {:.4}, F1 {:.4} \
             (tp {}, fn {}, fp {}, tn {})",
            self.region,
            self.returns(),
            self.ground(),
            self.recall(),
            self.false_ground_rate(),
            self.precision(),
            self.f1(),
            self.tp,
            self.fn_,
            self.fp,
            self.tn
        )
    }
}
