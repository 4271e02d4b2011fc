//! How two scans of the same scene, rig, seed and frames agree cell by cell, and the contract the
//! GPU backend keeps against the CPU reference (`--backend bvh`): a device's `sqrt`, division and
//! fused multiply-adds are not correctly rounded as the CPU's are, so its distances may differ in
//! the last bits, and a noisy range may then round to the neighbouring quantisation step.
//!
//! ```
//! use sim::scan::{Agreement, AgreementContract};
//! let mesh = sim::scene::builtin::flat();
//! let rig = sim::Rig::load("vlp16-roof")?;
//! let a = sim::scan::scan(&mesh, &rig, &Default::default())?;
//! let b = sim::scan::scan(&mesh, &rig, &Default::default())?;
//! let agreement = Agreement::of(&a[0].cloud, &b[0].cloud)?;
//! assert_eq!(agreement.hit_miss_share(), 1.0);
//! assert!(AgreementContract::GPU.check(&agreement, 0.002).is_ok());
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
    /// The largest range difference of a cell where both have a return, metres.
    pub max_range_diff_m: f32,
}

impl Agreement {
    /// Compares `a` and `b` cell by cell; refused when their grids differ.
    pub fn of(a: &OrderedCloud, b: &OrderedCloud) -> Result<Self> {
        if (a.rows, a.cols, a.planes) != (b.rows, b.cols, b.planes) {
            return Err(SimError::invalid(
                "clouds",
                format!("{}x{}x{} against {}x{}x{}", a.rows, a.cols, a.planes, b.rows, b.cols, b.planes),
                "the same grid",
            ));
        }
        let mut g = Agreement { cells: a.len() as u64, ..Agreement::default() };
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
    /// Largest range difference of a both-hit cell, metres, before measurement quantisation (one
    /// range quantum is added: two true ranges within this may round to neighbouring steps).
    pub max_range_diff_m: f32,
}

impl AgreementContract {
    /// The GPU backend against `--backend bvh`: hit / miss on at least 99.99 % of cells, labels
    /// equal on every cell both hit, ranges within 1 mm (plus one range quantum).
    pub const GPU: AgreementContract =
        AgreementContract { min_hit_miss_share: 0.9999, min_label_share: 1.0, max_range_diff_m: 0.001 };

    /// `Ok` when `agreement` keeps the contract for a sensor whose ranges are quantised to
    /// `range_quantum_m` (0 when not, as with `--ideal`); else what it breaks.
    pub fn check(&self, agreement: &Agreement, range_quantum_m: f32) -> std::result::Result<(), String> {
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
        let limit = self.max_range_diff_m + range_quantum_m + 1e-6;
        if agreement.max_range_diff_m > limit {
            broken.push(format!(
                "a range differs by {:.4} mm (> {:.4} mm)",
                1e3 * agreement.max_range_diff_m,
                1e3 * limit
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
        assert_eq!(Agreement::of(&a, &b).unwrap().bit_equal, 6);
        // One cell 0.5 mm off, one a miss on one side, one with another label.
        b.range_m[0] += 0.0005;
        b.point_in_vehicle[0].x += 0.0005;
        b.point_in_vehicle[1] = glam::Vec3::NAN;
        b.range_m[1] = f32::NAN;
        b.label[2] = crate::SemanticClass::CAR;
        let g = Agreement::of(&a, &b).unwrap();
        assert_eq!(
            (g.cells, g.hit_miss_equal, g.both_hit, g.labels_equal, g.within_1mm, g.bit_equal),
            (6, 5, 5, 4, 5, 4)
        );
        assert!((g.max_range_diff_m - 0.0005).abs() < 1e-6);
        let e = AgreementContract::GPU.check(&g, 0.0).unwrap_err();
        assert!(e.contains("hit/miss agree on 83.3333 %") && e.contains("labels agree on 80.0000 %"), "{e}");
        assert!(!e.contains("range"), "{e}");
        b.range_m[3] += 0.004;
        let e = AgreementContract::GPU.check(&Agreement::of(&a, &b).unwrap(), 0.002).unwrap_err();
        assert!(e.contains("differs by 4.0"), "{e}");
        assert!(Agreement::of(&a, &OrderedCloud::empty(3, 2, 1)).is_err());
    }
}
