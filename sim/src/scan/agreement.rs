//! How two scans of the same scene, rig, seed and frames agree cell by cell, and the contract the
//! GPU backend keeps against the CPU reference (`--backend bvh`): a device's `sqrt`, division and
//! fused multiply-adds are not correctly rounded as the CPU's are, and it makes a moving rig's rays
//! itself, so its rays and distances may differ in the last bits: a noisy range may then round to
//! the neighbouring quantisation step, and a beam through the very line where two surfaces meet
//! (an edge, a pole's foot on the road) may end on the other one. The contract bounds how often:
//! its shares are 1 in 10,000, so judge it on at least 10,000 cells both hit (a LUX frame has
//! about 6,000 returns: one cell is then already 0.016 %).
//!
//! ```
//! use sim::scan::{Agreement, AgreementContract};
//! let mesh = sim::scene::builtin::flat();
//! let rig = sim::Rig::load("vlp16-roof")?;
//! let a = sim::scan::scan(&mesh, &rig, &Default::default())?;
//! let b = sim::scan::scan(&mesh, &rig, &Default::default())?;
//! let agreement = Agreement::of(&a[0].cloud, &b[0].cloud, 0.002)?;
//! assert_eq!(agreement.hit_miss_share(), 1.0);
//! assert!(AgreementContract::GPU.check(&agreement).is_ok());
//! # Ok::<(), sim::SimError>(())
//! ```

use crate::OrderedCloud;
use crate::error::{Result, SimError};

/// Cell-by-cell agreement of two clouds of the same grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Agreement {
    /// Cells compared (every plane).
    pub cells: u64,
    /// Cells where both have a return or both have none.
    pub hit_miss_equal: u64,
    /// Cells where both have a return.
    pub both_hit: u64,
    /// Of those, cells with the same label.
    pub labels_equal: u64,
    /// Of those, cells whose ranges differ by at most 1 mm.
    pub within_1mm: u64,
    /// Of those, cells whose points are the same bits.
    pub bit_equal: u64,
    /// Of those, cells whose ranges differ by at most 1 mm plus one range quantum.
    pub within_tolerance: u64,
    /// The largest range difference of a cell where both have a return, metres.
    pub max_range_diff_m: f32,
    /// The range quantum of the sensors compared, metres (0 for ideal scans).
    pub range_quantum_m: f32,
}

/// Range difference two backends' cells may show before quantisation, metres.
pub const RANGE_TOLERANCE_M: f32 = 0.001;

impl Agreement {
    /// Compares `a` and `b` cell by cell, their ranges quantised to `range_quantum_m` (0 when not,
    /// as with `--ideal`: two true ranges within [`RANGE_TOLERANCE_M`] may round to neighbouring
    /// steps); refused when their grids differ.
    pub fn of(a: &OrderedCloud, b: &OrderedCloud, range_quantum_m: f32) -> Result<Self> {
        if (a.rows, a.cols, a.planes) != (b.rows, b.cols, b.planes) {
            return Err(SimError::invalid(
                "clouds",
                format!("{}x{}x{} against {}x{}x{}", a.rows, a.cols, a.planes, b.rows, b.cols, b.planes),
                "the same grid",
            ));
        }
        let mut g = Agreement { cells: a.len() as u64, range_quantum_m, ..Agreement::default() };
        let tolerance = RANGE_TOLERANCE_M + range_quantum_m + 1e-6;
        for i in 0..a.len() {
            let (ha, hb) = (a.has_return(i), b.has_return(i));
            g.hit_miss_equal += u64::from(ha == hb);
            if !(ha && hb) {
                continue;
            }
            g.both_hit += 1;
            g.labels_equal += u64::from(a.label[i] == b.label[i]);
            let d = (a.range_m[i] - b.range_m[i]).abs();
            g.max_range_diff_m = g.max_range_diff_m.max(d);
            g.within_1mm += u64::from(d <= 0.001);
            g.within_tolerance += u64::from(d <= tolerance);
            g.bit_equal += u64::from(
                a.point_in_vehicle[i].to_array().map(f32::to_bits)
                    == b.point_in_vehicle[i].to_array().map(f32::to_bits),
            );
        }
        Ok(g)
    }

    /// Adds another frame's counts.
    pub fn add(&mut self, other: &Agreement) {
        self.cells += other.cells;
        self.hit_miss_equal += other.hit_miss_equal;
        self.both_hit += other.both_hit;
        self.labels_equal += other.labels_equal;
        self.within_1mm += other.within_1mm;
        self.within_tolerance += other.within_tolerance;
        self.range_quantum_m = self.range_quantum_m.max(other.range_quantum_m);
        self.bit_equal += other.bit_equal;
        self.max_range_diff_m = self.max_range_diff_m.max(other.max_range_diff_m);
    }

    /// Share of cells where hit / miss agree.
    pub fn hit_miss_share(&self) -> f64 {
        self.hit_miss_equal as f64 / self.cells.max(1) as f64
    }

    /// Share of both-hit cells with the same label.
    pub fn label_share(&self) -> f64 {
        self.labels_equal as f64 / self.both_hit.max(1) as f64
    }

    /// Share of both-hit cells whose ranges agree within 1 mm plus one range quantum.
    pub fn range_share(&self) -> f64 {
        self.within_tolerance as f64 / self.both_hit.max(1) as f64
    }

    /// Share of both-hit cells whose points are the same bits.
    pub fn bit_equal_share(&self) -> f64 {
        self.bit_equal as f64 / self.both_hit.max(1) as f64
    }
}

/// What two backends must agree on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgreementContract {
    /// Smallest share of cells where hit / miss agree.
    pub min_hit_miss_share: f64,
    /// Smallest share of both-hit cells with the same label.
    pub min_label_share: f64,
    /// Smallest share of both-hit cells whose ranges agree within [`RANGE_TOLERANCE_M`] plus one
    /// range quantum.
    pub min_range_share: f64,
}

impl AgreementContract {
    /// The GPU backend against `--backend bvh`: hit / miss, labels and ranges (within 1 mm plus
    /// one range quantum) each agree on at least 99.99 % of the cells (module docs: the rest are
    /// beams through the line where two surfaces meet).
    pub const GPU: AgreementContract =
        AgreementContract { min_hit_miss_share: 0.9999, min_label_share: 0.9999, min_range_share: 0.9999 };

    /// `Ok` when `agreement` keeps the contract; else what it breaks.
    pub fn check(&self, agreement: &Agreement) -> std::result::Result<(), String> {
        let mut broken = Vec::new();
        if agreement.hit_miss_share() < self.min_hit_miss_share {
            broken.push(format!(
                "hit/miss agree on {:.4} % of cells (< {} %)",
                100.0 * agreement.hit_miss_share(),
                100.0 * self.min_hit_miss_share
            ));
        }
        if agreement.label_share() < self.min_label_share {
            broken.push(format!(
                "labels agree on {:.4} % of cells both hit (< {} %)",
                100.0 * agreement.label_share(),
                100.0 * self.min_label_share
            ));
        }
        if agreement.range_share() < self.min_range_share {
            broken.push(format!(
                "ranges agree within {:.4} mm on {:.4} % of cells both hit (< {} %; the largest difference {:.4} mm)",
                1e3 * (RANGE_TOLERANCE_M + agreement.range_quantum_m),
                100.0 * agreement.range_share(),
                100.0 * self.min_range_share,
                1e3 * agreement.max_range_diff_m
            ));
        }
        if broken.is_empty() { Ok(()) } else { Err(broken.join("; ")) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_breaches_are_exact() {
        let mut a = OrderedCloud::empty(2, 3, 1);
        for i in 0..6 {
            a.point_in_vehicle[i] = glam::Vec3::new(i as f32 + 1.0, 0.0, 0.0);
            a.range_m[i] = i as f32 + 1.0;
        }
        let mut b = a.clone();
        assert_eq!(Agreement::of(&a, &b, 0.0).unwrap().bit_equal, 6);
        // One cell 0.5 mm off, one a miss on one side, one with another label.
        b.range_m[0] += 0.0005;
        b.point_in_vehicle[0].x += 0.0005;
        b.point_in_vehicle[1] = glam::Vec3::NAN;
        b.range_m[1] = f32::NAN;
        b.label[2] = crate::SemanticClass::CAR;
        let g = Agreement::of(&a, &b, 0.0).unwrap();
        assert_eq!(
            (g.cells, g.hit_miss_equal, g.both_hit, g.labels_equal, g.within_1mm, g.within_tolerance, g.bit_equal),
            (6, 5, 5, 4, 5, 5, 4)
        );
        assert!((g.max_range_diff_m - 0.0005).abs() < 1e-6);
        let e = AgreementContract::GPU.check(&g).unwrap_err();
        assert!(e.contains("hit/miss agree on 83.3333 %") && e.contains("labels agree on 80.0000 %"), "{e}");
        assert!(!e.contains("range"), "{e}");
        // 4 mm off: beyond 1 mm plus a 2 mm quantum, within 1 mm plus a 5 mm one.
        b.range_m[3] += 0.004;
        let e = AgreementContract::GPU.check(&Agreement::of(&a, &b, 0.002).unwrap()).unwrap_err();
        assert!(
            e.contains("ranges agree within 3.0000 mm on 80.0000 %") && e.contains("largest difference 4.0"),
            "{e}"
        );
        let g = Agreement::of(&a, &b, 0.005).unwrap();
        assert_eq!((g.within_1mm, g.within_tolerance), (4, 5));
        // One outlier in 10,000 both-hit cells keeps the contract, two do not.
        let shares = |outliers: u64| Agreement {
            cells: 10_000,
            hit_miss_equal: 10_000,
            both_hit: 10_000,
            labels_equal: 10_000 - outliers,
            within_tolerance: 10_000 - outliers,
            ..Agreement::default()
        };
        assert!(AgreementContract::GPU.check(&shares(1)).is_ok());
        assert!(AgreementContract::GPU.check(&shares(2)).is_err());
        assert!(Agreement::of(&a, &OrderedCloud::empty(3, 2, 1), 0.0).is_err());
    }
}
