//! The usable points of a cloud: those with finite coordinates that are not the (0, 0, 0) a
//! driver writes for a no-return, nor nearer than the sensor's minimum range where it is known
//! (a motion-compensated no-return: [`super::BeamTable::min_range_m`]). Bad points (NaN,
//! infinite) are counted and skipped, and more than [`MAX_BAD_FRACTION`] of them refuse the cloud;
//! no-returns are counted and skipped.
//!
//! Real files rarely hold either, so the common case keeps no index list at all: usable point `i`
//! is input point `i` ([`Usable::point`]), and the passes over the points read them contiguously.

use super::MAX_BAD_FRACTION;
use super::input_point::InputPoint;
use super::report::OrderingReport;
use crate::error::{ClassifyError, Result};

/// Which input points are usable, in input order.
#[derive(Clone, Debug)]
pub(crate) struct Usable {
    /// Input index of each usable point; `None` when every point is usable.
    idx: Option<Vec<u32>>,
    len: usize,
}

impl Usable {
    /// Finds the usable points of `points`, counting bad points and no-returns (points nearer
    /// than `min_range_m` among them; 0: none) in `report`.
    pub(crate) fn find<P: InputPoint>(points: &[P], min_range_m: f32, report: &mut OrderingReport) -> Result<Self> {
        Self::check_count(points.len())?;
        // A counting pass without branches (it vectorizes); the index list only where needed.
        Self::from_counts(points, count_bad_and_zero(points), min_range_m, report)
    }

    /// Refuses clouds of more points than the cells' `u32` indices can hold.
    pub(crate) fn check_count(n: usize) -> Result<()> {
        if n > u32::MAX as usize / 2 {
            return Err(ClassifyError::Ordering(format!("{n} points are too many")));
        }
        Ok(())
    }

    /// The usable points of `points` from the counts of their bad points and no-returns, made by
    /// a pass that read every point (the polar pass of scan unfolding reads them once for both).
    pub(crate) fn from_counts<P: InputPoint>(
        points: &[P],
        (bad, zero): (usize, usize),
        min_range_m: f32,
        report: &mut OrderingReport,
    ) -> Result<Self> {
        // Nearer than the minimum range, not at (0, 0, 0) (counted above): one more pass, only
        // where the sensor's minimum range is known.
        let near_sq = min_range_m * min_range_m;
        let too_near = |p: glam::Vec3| {
            let d = p.length_squared();
            (d < near_sq) & (d > 0.0)
        };
        let near = if min_range_m > 0.0 { points.iter().filter(|p| too_near(p.xyz())).count() } else { 0 };
        report.skipped += bad;
        report.no_returns += zero + near;
        report.too_near += near;
        report.min_range_m = min_range_m;
        if report.skipped as f64 > MAX_BAD_FRACTION * points.len() as f64 {
            return Err(ClassifyError::Ordering(format!(
                "{} of {} points have NaN or infinite coordinates (at most {} % may)",
                report.skipped,
                points.len(),
                MAX_BAD_FRACTION * 100.0
            )));
        }
        if bad + zero + near == 0 {
            return Ok(Self { idx: None, len: points.len() });
        }
        let idx: Vec<u32> = (0..points.len() as u32)
            .filter(|&k| {
                let p = points[k as usize].xyz();
                bad_and_no_return(p.x, p.y, p.z) == (false, false) && !too_near(p)
            })
            .collect();
        Ok(Self { len: idx.len(), idx: Some(idx) })
    }

    /// Number of usable points.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Input index of usable point `i`.
    #[inline(always)]
    pub(crate) fn point(&self, i: usize) -> usize {
        match &self.idx {
            None => i,
            Some(idx) => idx[i] as usize,
        }
    }

    /// The input indices as a list, `None` when every point is usable (index = position).
    pub(crate) fn indices(&self) -> Option<&[u32]> {
        self.idx.as_deref()
    }

    /// Input indices of the usable points, in order.
    pub(crate) fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.len).map(|i| self.point(i) as u32)
    }
}

/// Whether the point `(x, y, z)` is bad (a non-finite coordinate) and whether it is a no-return
/// (at (0, 0, 0)): the definitions of every count and list of usable points (this module's, and
/// the polar pass's), without branches so that the passes vectorize.
#[inline(always)]
pub(crate) fn bad_and_no_return(x: f32, y: f32, z: f32) -> (bool, bool) {
    (!(x.is_finite() & y.is_finite() & z.is_finite()), (x == 0.0) & (y == 0.0) & (z == 0.0))
}

/// Points with a non-finite coordinate and points at (0, 0, 0), counted (compiled for AVX2
/// where the CPU has it: the same counts, about half the instructions of the baseline build).
fn count_bad_and_zero<P: InputPoint>(points: &[P]) -> (usize, usize) {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::avx512() {
        // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ, AVX2, BMI1 and BMI2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return count_avx512(points);
        }
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return count_avx2(points);
        }
    }
    count_body(points)
}

/// [`count_body`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn count_avx2<P: InputPoint>(points: &[P]) -> (usize, usize) {
    count_body(points)
}

/// [`count_body`] compiled for AVX-512 ([`crate::cpu::avx512`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
fn count_avx512<P: InputPoint>(points: &[P]) -> (usize, usize) {
    count_body(points)
}

/// The body of [`count_bad_and_zero`], inlined into each instruction-set variant.
#[inline(always)]
fn count_body<P: InputPoint>(points: &[P]) -> (usize, usize) {
    let (mut bad, mut zero) = (0usize, 0usize);
    for p in points {
        let p = p.xyz();
        let (is_bad, is_zero) = bad_and_no_return(p.x, p.y, p.z);
        bad += usize::from(is_bad);
        zero += usize::from(is_zero);
    }
    (bad, zero)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn counts_bad_points_and_no_returns_and_lists_the_rest() {
        let mut pts = vec![Vec3::new(1.0, 2.0, 3.0); 300];
        pts[5] = Vec3::ZERO;
        pts[7] = Vec3::new(f32::NAN, 0.0, 0.0);
        pts[9] = Vec3::new(0.0, f32::INFINITY, 0.0);
        let mut report = OrderingReport::default();
        let u = Usable::find(&pts, 0.0, &mut report).unwrap();
        assert_eq!((report.skipped, report.no_returns, u.len()), (2, 1, 297));
        assert_eq!((u.point(4), u.point(5), u.point(6), u.point(7)), (4, 6, 8, 10));
        assert_eq!(u.iter().count(), 297);
        let mut report = OrderingReport::default();
        let all = Usable::find(&pts[10..], 0.0, &mut report).unwrap();
        assert!(all.indices().is_none());
        assert_eq!((all.len(), all.point(17), report.skipped + report.no_returns), (290, 17, 0));
        // With a minimum range of 3.8 m (the points lie 3.74 m out): every usable point is too
        // near; at 3.7 m none is. The one at 0, 0, 0 is a no-return either way, not too near.
        let mut report = OrderingReport::default();
        let none = Usable::find(&pts, 3.8, &mut report).unwrap();
        assert_eq!((none.len(), report.no_returns, report.too_near, report.skipped), (0, 298, 297, 2));
        let mut report = OrderingReport::default();
        let u = Usable::find(&pts, 3.7, &mut report).unwrap();
        assert_eq!((u.len(), report.no_returns, report.too_near, report.min_range_m), (297, 1, 0, 3.7));
        // More than 1 % bad: refused.
        pts[11] = Vec3::NAN;
        pts[12] = Vec3::NAN;
        let mut report = OrderingReport::default();
        assert!(Usable::find(&pts[..100], 0.0, &mut report).is_err());
    }
}
