//! Row order per column: the method's neighbourhood (Fig. 3) assumes that rows go up in
//! elevation, so that `d_i x d_(i-1)` points away from the ground. A nodding laser breaks that: its
//! rows are scans taken at rising tilt, and for beams behind the tilt axis (the rear flanks of a
//! 270 deg fan) a rising tilt lowers the beam, so those columns run **down** in elevation; their
//! normals come out pointing into the ground and their "upper" neighbours are the lower beams.
//!
//! [`reversed_columns`] finds such columns from the data: each column votes with the elevation
//! order (each return seen from its sensor's origin, [`crate::sensor_origin`]) of up to
//! [`SAMPLED_ROWS`] returns spread over its rows (each pair of successive returns votes up or
//! down); a column whose majority runs down is reversed. Elevation
//! seen from the origin does not move with range noise (a return moves along its own beam), so the
//! vote is decided by the beam gap. To stay off the hot path of ordinary rigs, a first pass looks at
//! [`PROBE_COLUMNS`] columns spread over the grid and stops when none is reversed (a rig whose
//! reversed columns are fewer than one in 64 is taken as ordered).
//!
//! The method then runs on plane 0 with the rows of the reversed columns flipped (row `r` <->
//! `rows - 1 - r`), which is the order the paper's neighbourhood expects, and the decisions are
//! flipped back. At the seam between reversed and ordered columns (the +-90 deg beams of a nodding
//! laser, which all point the same way whatever the tilt) the neighbours do not match; those
//! columns are degenerate in any order.

use glam::Vec3;

use crate::error::is_valid;

/// Rows sampled per column for its vote, at most.
pub const SAMPLED_ROWS: usize = 16;

/// Columns looked at before deciding that no column is reversed.
pub const PROBE_COLUMNS: usize = 64;

/// Cells sampled for each sensor's origin estimate, at most.
const ORIGIN_SAMPLES: usize = 4096;

/// Per column of plane 0, whether its rows run down in elevation; `None` when no column does
/// (the common case: nothing to reorder).
pub fn reversed_columns(cloud: &sim::OrderedCloud) -> Option<Vec<bool>> {
    let (rows, cols) = (cloud.rows, cloud.cols);
    if rows < 2 || cols == 0 {
        return None;
    }
    let origins = sampled_origins(cloud);
    let origin = |i: usize| origins.get(cloud.sensor[i] as usize).copied().flatten();
    // Sine of the elevation of cell i seen from its sensor.
    let elevation = |i: usize| -> Option<f32> {
        let p = cloud.point_in_vehicle[i];
        let s = origin(i)?;
        if !is_valid(p) {
            return None;
        }
        let d = p - s;
        let len = d.length();
        (len > 0.0).then(|| d.z / len)
    };
    // Successive returns among every `step`-th row: at least `rows / SAMPLED_ROWS` rows apart, so
    // their elevations differ by several beam gaps (beyond range noise and per-laser origins);
    // any two returns of a column tell its order, wherever the column has returns at all.
    let step = (rows / SAMPLED_ROWS).max(1);
    let vote = |c: usize| -> i32 {
        let mut votes = 0i32;
        let mut last = None;
        for r in (0..rows).step_by(step) {
            if let Some(e) = elevation(r * cols + c) {
                if let Some(prev) = last {
                    votes += if e > prev {
                        1
                    } else if e < prev {
                        -1
                    } else {
                        0
                    };
                }
                last = Some(e);
            }
        }
        votes
    };
    let probe_step = cols.div_ceil(PROBE_COLUMNS).max(1);
    if !(0..cols).step_by(probe_step).any(|c| vote(c) < 0) {
        return None;
    }
    let reversed: Vec<bool> = (0..cols).map(|c| vote(c) < 0).collect();
    reversed.contains(&true).then_some(reversed)
}

/// Each sensor's origin (by sensor id) estimated from the returns among every k-th cell of plane 0
/// (about [`ORIGIN_SAMPLES`] cells in all).
fn sampled_origins(cloud: &sim::OrderedCloud) -> Vec<Option<Vec3>> {
    let n = cloud.rows * cloud.cols;
    let step = n.div_ceil(ORIGIN_SAMPLES).max(1);
    let sampled = || (0..n).step_by(step).filter(|&i| cloud.sensor[i] != u8::MAX && cloud.has_return(i));
    let Some(max_id) = sampled().map(|i| cloud.sensor[i]).max() else { return Vec::new() };
    (0..=max_id)
        .map(|id| {
            let pairs = sampled()
                .filter(move |&i| cloud.sensor[i] == id)
                .map(|i| (cloud.point_in_vehicle[i], cloud.range_m[i]));
            crate::sensor_origin::estimate_origin(pairs)
        })
        .collect()
}

/// The plane-0 cell that row `r`, column `c` of the reordered grid reads (an involution).
#[inline]
pub fn source_cell(reversed: &[bool], rows: usize, cols: usize, r: usize, c: usize) -> usize {
    if reversed[c] { (rows - 1 - r) * cols + c } else { r * cols + c }
}

/// Copies plane 0's points and ranges into `points` / `ranges` with the rows of the reversed
/// columns flipped.
pub fn reorder_plane0(cloud: &sim::OrderedCloud, reversed: &[bool], points: &mut Vec<Vec3>, ranges: &mut Vec<f32>) {
    let (rows, cols) = (cloud.rows, cloud.cols);
    points.clear();
    ranges.clear();
    for r in 0..rows {
        for c in 0..cols {
            let src = source_cell(reversed, rows, cols, r, c);
            points.push(cloud.point_in_vehicle[src]);
            ranges.push(cloud.range_m[src]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fan of `rows` x `cols` beams from `origin` at ranges of 4-12 m, whose columns
    /// `reversed_from..` run down in elevation.
    fn fan(rows: usize, cols: usize, reversed_from: usize, origin: Vec3) -> sim::OrderedCloud {
        let mut cloud = sim::OrderedCloud::empty(rows, cols, 1);
        for r in 0..rows {
            for c in 0..cols {
                let rr = if c >= reversed_from { rows - 1 - r } else { r };
                let elev = (-60.0 + 40.0 * rr as f32 / rows as f32).to_radians();
                let az = (170.0 - 340.0 * c as f32 / cols as f32).to_radians();
                let dir = Vec3::new(elev.cos() * az.cos(), elev.cos() * az.sin(), elev.sin());
                let t = 4.0 + 8.0 * ((rr * 7 + c * 3) % 11) as f32 / 11.0;
                let i = r * cols + c;
                cloud.point_in_vehicle[i] = origin + dir * t;
                cloud.range_m[i] = t;
                cloud.sensor[i] = 0;
            }
        }
        cloud
    }

    #[test]
    fn ordered_fans_are_left_alone_and_reversed_columns_are_found() {
        let origin = Vec3::new(0.3, 0.0, 1.7);
        assert_eq!(reversed_columns(&fan(16, 200, 200, origin)), None);
        let rev = reversed_columns(&fan(16, 200, 150, origin)).expect("reversed columns");
        assert_eq!(rev.iter().position(|&r| r), Some(150));
        assert_eq!(rev.iter().filter(|&&r| r).count(), 50);
    }

    #[test]
    fn reordering_flips_only_the_reversed_columns() {
        let origin = Vec3::new(0.0, 0.0, 0.55);
        let cloud = fan(8, 40, 30, origin);
        let rev = reversed_columns(&cloud).unwrap();
        let (mut p, mut r) = (Vec::new(), Vec::new());
        reorder_plane0(&cloud, &rev, &mut p, &mut r);
        assert_eq!(fan(8, 40, 40, origin).point_in_vehicle, p);
        // The mapping is an involution.
        for row in 0..8 {
            for c in 0..40 {
                let s = source_cell(&rev, 8, 40, row, c);
                assert_eq!(source_cell(&rev, 8, 40, s / 40, s % 40), row * 40 + c);
            }
        }
    }
}
