//! Isolated returns: the particle filter stage of `grid-dror`, a dynamic-radius outlier test
//! (after DROR, Charron, Phillips and Waslander 2018, "De-noising of lidar point clouds corrupted by
//! snowfall", CRV) run on the ordered grid instead of a k-d tree.
//!
//! A falling flake, a rain drop or a speck of dust is a return whose neighbours in the scan lie far
//! behind it: the beams beside it pass the particle and hit the surface. A surface point has
//! neighbours at about `r alpha` (its range times the sensor's angular step) along its ring. A return
//! is **isolated** when fewer than `min_neighbours` of the returns in its window (rows `+-1`, columns
//! `+-window_cols`, columns wrapping round) lie within `max(min_radius_m, radius_multiplier r alpha)`
//! of it. `alpha` is measured on the frame itself (the median of `|p_j - p_i| / r_i` over
//! neighbouring columns of a ring), so the test needs no sensor table. Plane 0 only.
//!
//! ```
//! use classifier::baselines::isolated::{IsolationParams, isolated_returns};
//! // A flat ring of returns 10 m away, one column every 0.2 deg, and one speck in front of column 7.
//! let (rows, cols) = (3, 90);
//! let mut cloud = sim::OrderedCloud::empty(rows, cols, 1);
//! for r in 0..rows {
//!     for c in 0..cols {
//!         let a = (c as f32 * 0.2).to_radians();
//!         let range = if c == 7 && r == 1 { 3.0 } else { 10.0 };
//!         let z = -0.02 * r as f32 * range;
//!         let i = r * cols + c;
//!         cloud.point_in_vehicle[i] = glam::Vec3::new(range * a.cos(), range * a.sin(), z);
//!         cloud.range_m[i] = range;
//!     }
//! }
//! let mut isolated = Vec::new();
//! isolated_returns(&cloud, &IsolationParams::default(), &mut isolated);
//! assert_eq!(isolated.iter().filter(|&&x| x).count(), 1);
//! assert!(isolated[cols + 7]);
//! ```

use glam::Vec3;

use crate::error::is_valid;

/// Parameters of the isolation test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsolationParams {
    /// Columns on each side in the window (rows are always `+-1`).
    pub window_cols: usize,
    /// The search radius in angular steps (DROR's `beta`): 3.
    pub radius_multiplier: f32,
    /// The smallest search radius, metres (returns near the sensor: range noise).
    pub min_radius_m: f32,
    /// Neighbours within the radius a return needs not to be isolated.
    pub min_neighbours: usize,
}

impl Default for IsolationParams {
    fn default() -> Self {
        Self { window_cols: 2, radius_multiplier: 3.0, min_radius_m: 0.05, min_neighbours: 2 }
    }
}

/// Per cell of plane 0 (grid order), whether it is an isolated return (false where no return).
pub fn isolated_returns(cloud: &sim::OrderedCloud, params: &IsolationParams, out: &mut Vec<bool>) {
    let (rows, cols) = (cloud.rows, cloud.cols);
    let n0 = rows * cols;
    out.clear();
    out.resize(n0, false);
    if n0 == 0 {
        return;
    }
    let points = &cloud.point_in_vehicle[..n0];
    let range = &cloud.range_m[..n0];
    let valid = |i: usize| is_valid(points[i]) && range[i] > 0.0;
    let alpha = angular_step(points, range, rows, cols, &valid);
    let w = params.window_cols.min(cols.saturating_sub(1) / 2);
    for row in 0..rows {
        for col in 0..cols {
            let i = row * cols + col;
            if !valid(i) {
                continue;
            }
            let p = points[i];
            let radius = params.min_radius_m.max(params.radius_multiplier * range[i] * alpha);
            let r2 = radius * radius;
            let mut found = 0usize;
            'window: for nr in row.saturating_sub(1)..(row + 2).min(rows) {
                for dc in 0..=2 * w {
                    let nc = (col + cols + dc - w) % cols;
                    let j = nr * cols + nc;
                    if j != i && valid(j) && p.distance_squared(points[j]) <= r2 {
                        found += 1;
                        if found >= params.min_neighbours {
                            break 'window;
                        }
                    }
                }
            }
            out[i] = found < params.min_neighbours;
        }
    }
}

/// The frame's angular step between neighbouring columns, radians: the median of `|p_j - p_i| /
/// r_i` over neighbouring valid cells of a ring (every fourth cell sampled). 0 when there are none.
fn angular_step(points: &[Vec3], range: &[f32], rows: usize, cols: usize, valid: &impl Fn(usize) -> bool) -> f32 {
    let mut steps: Vec<f32> = Vec::with_capacity(rows * cols / 4 + 1);
    for row in 0..rows {
        for col in (0..cols.saturating_sub(1)).step_by(4) {
            let (i, j) = (row * cols + col, row * cols + col + 1);
            if valid(i) && valid(j) {
                steps.push(points[i].distance(points[j]) / range[i]);
            }
        }
    }
    if steps.is_empty() {
        return 0.0;
    }
    let mid = steps.len() / 2;
    *steps.select_nth_unstable_by(mid, f32::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ring grid on a flat floor 1.8 m below the sensor; `speck` cells replaced by returns at
    /// `speck_range_m` along their beams.
    fn floor(rows: usize, cols: usize, specks: &[(usize, usize)], speck_range_m: f32) -> sim::OrderedCloud {
        let mut cloud = sim::OrderedCloud::empty(rows, cols, 1);
        for r in 0..rows {
            let elevation = (-8.0f32 + r as f32 * 0.4).to_radians();
            for c in 0..cols {
                let azimuth = std::f32::consts::TAU * c as f32 / cols as f32;
                let dir = Vec3::new(elevation.cos() * azimuth.cos(), elevation.cos() * azimuth.sin(), elevation.sin());
                let ground = 1.8 / -dir.z;
                let range = if specks.contains(&(r, c)) { speck_range_m } else { ground };
                let i = r * cols + c;
                cloud.point_in_vehicle[i] = dir * range + Vec3::new(0.0, 0.0, 1.8);
                cloud.range_m[i] = range;
            }
        }
        cloud
    }

    #[test]
    fn specks_are_isolated_and_the_floor_is_not() {
        let specks = [(3, 100), (5, 700), (9, 1500), (0, 0), (11, 2169)];
        let cloud = floor(12, 2170, &specks, 6.0);
        let mut out = Vec::new();
        isolated_returns(&cloud, &IsolationParams::default(), &mut out);
        for (i, &iso) in out.iter().enumerate() {
            let (r, c) = (i / cloud.cols, i % cloud.cols);
            assert_eq!(iso, specks.contains(&(r, c)), "cell ({r}, {c})");
        }
    }

    #[test]
    fn the_angular_step_is_measured_on_the_frame() {
        let cloud = floor(4, 1024, &[], 0.0);
        let valid = |i: usize| cloud.range_m[i] > 0.0;
        let alpha = angular_step(&cloud.point_in_vehicle, &cloud.range_m, 4, 1024, &valid);
        // Chord over range of a ring at elevation e: 2 sin(pi / cols) cos(e); e = -8 .. -6.8 deg.
        let expected = 2.0 * (std::f32::consts::PI / 1024.0).sin();
        assert!((alpha / expected - 0.99).abs() < 0.01, "{alpha} vs {expected}");
    }

    #[test]
    fn empty_and_missing_returns_are_not_isolated() {
        let mut out = vec![true; 3];
        isolated_returns(&sim::OrderedCloud::empty(0, 0, 1), &IsolationParams::default(), &mut out);
        assert!(out.is_empty());
        let cloud = sim::OrderedCloud::empty(2, 8, 1);
        isolated_returns(&cloud, &IsolationParams::default(), &mut out);
        assert_eq!(out, vec![false; 16]);
    }
}
