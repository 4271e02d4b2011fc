//! Stage 1, the local minimum-z filter: the returns are divided into square vertical columns
//! (`i = floor(x / cell_m)`, `j = floor(y / cell_m)`, vehicle frame) and the lowest return of each
//! column (min z) is its ground candidate `P_ij`.
//!
//! The columns live on a dense 2-D grid over the bounding box of the returns. To keep the grid
//! bounded, returns with `|x|` or `|y|` beyond [`FeatureParams::max_extent_m`] take no part in stage 1
//! (they are never candidates, so never ground; their beams still count in the ray-tracing
//! feature). Ties in z go to the lowest cell index of the cloud.

use glam::Vec3;
use rayon::prelude::*;

use super::FeatureParams;

/// Marks "no candidate" / "no column" in the index arrays.
pub const NONE: u32 = u32::MAX;

/// The column grid of one cloud and its ground candidates (the min-z return of every occupied
/// column), ordered by grid index `gi * nj + gj` (`gi = i - i0`, `gj = j - j0`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Columns {
    /// Column (and voxel) edge, metres.
    pub cell_m: f32,
    /// Column index `i` of grid row 0.
    pub i0: i32,
    /// Column index `j` of grid column 0.
    pub j0: i32,
    /// Grid extent along `i` (x).
    pub ni: usize,
    /// Grid extent along `j` (y).
    pub nj: usize,
    /// Per grid column (`gi * nj + gj`), the index of its candidate, or [`NONE`] when empty.
    pub candidate_of_column: Vec<u32>,
    /// Per candidate, the cloud cell of its return.
    pub cell: Vec<u32>,
    /// Per candidate, its grid column index (`gi * nj + gj`).
    pub column: Vec<u32>,
    /// Per candidate, its point in the vehicle frame.
    pub point_in_vehicle: Vec<Vec3>,
    /// Per cloud cell, the grid column index of its return, or [`NONE`] (no return, or outside the
    /// extent).
    pub column_of_cell: Vec<u32>,
}

impl Columns {
    /// Stage 1 on `cloud` (every return of every echo plane).
    pub fn build(cloud: &sim::OrderedCloud, params: &FeatureParams) -> Self {
        let cell_m = params.cell_m;
        let lim = params.max_extent_m;
        let n = cloud.len();
        // Column indices of every usable return (parallel; i32::MIN marks the others), and their
        // bounding box (an exact integer reduction: independent of the thread count).
        let ij: Vec<(i32, i32)> = (0..n)
            .into_par_iter()
            .with_min_len(4096)
            .map(|c| {
                let p = cloud.point_in_vehicle[c];
                if !cloud.has_return(c) || !p.is_finite() || p.x.abs() > lim || p.y.abs() > lim {
                    (i32::MIN, i32::MIN)
                } else {
                    ((p.x / cell_m).floor() as i32, (p.y / cell_m).floor() as i32)
                }
            })
            .collect();
        let (imin, imax, jmin, jmax) = ij
            .par_iter()
            .with_min_len(4096)
            .filter(|(i, _)| *i != i32::MIN)
            .fold(
                || (i32::MAX, i32::MIN, i32::MAX, i32::MIN),
                |(a, b, c, d), &(i, j)| (a.min(i), b.max(i), c.min(j), d.max(j)),
            )
            .reduce(
                || (i32::MAX, i32::MIN, i32::MAX, i32::MIN),
                |x, y| (x.0.min(y.0), x.1.max(y.1), x.2.min(y.2), x.3.max(y.3)),
            );
        if imin > imax {
            return Self { cell_m, column_of_cell: vec![NONE; n], ..Default::default() };
        }
        let ni = (imax - imin + 1) as usize;
        let nj = (jmax - jmin + 1) as usize;
        let mut best = vec![NONE; ni * nj];
        let mut column_of_cell = vec![NONE; n];
        for (c, &(i, j)) in ij.iter().enumerate() {
            if i == i32::MIN {
                continue;
            }
            let g = (i - imin) as usize * nj + (j - jmin) as usize;
            column_of_cell[c] = g as u32;
            let b = best[g];
            // Strictly lower wins: on a tie the earlier (lower) cell index stays.
            if b == NONE || cloud.point_in_vehicle[c].z < cloud.point_in_vehicle[b as usize].z {
                best[g] = c as u32;
            }
        }
        let mut candidate_of_column = vec![NONE; ni * nj];
        let mut cell = Vec::new();
        let mut column = Vec::new();
        let mut point_in_vehicle = Vec::new();
        for (g, &b) in best.iter().enumerate() {
            if b != NONE {
                candidate_of_column[g] = cell.len() as u32;
                cell.push(b);
                column.push(g as u32);
                point_in_vehicle.push(cloud.point_in_vehicle[b as usize]);
            }
        }
        Self { cell_m, i0: imin, j0: jmin, ni, nj, candidate_of_column, cell, column, point_in_vehicle, column_of_cell }
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.cell.len()
    }

    /// Whether there is no candidate.
    pub fn is_empty(&self) -> bool {
        self.cell.is_empty()
    }

    /// The column indices `(i, j)` of candidate `k`.
    pub fn ij(&self, k: usize) -> (i32, i32) {
        let g = self.column[k] as usize;
        ((g / self.nj) as i32 + self.i0, (g % self.nj) as i32 + self.j0)
    }

    /// The candidate in column `(i, j)`, if the column is on the grid and occupied.
    pub fn candidate_at(&self, i: i32, j: i32) -> Option<usize> {
        let gi = i.checked_sub(self.i0)?;
        let gj = j.checked_sub(self.j0)?;
        if gi < 0 || gj < 0 || gi as usize >= self.ni || gj as usize >= self.nj {
            return None;
        }
        let k = self.candidate_of_column[gi as usize * self.nj + gj as usize];
        (k != NONE).then_some(k as usize)
    }

    /// The voxel layer of height `z_m`: `floor(z_m / cell_m)` (layer 0 spans `0 <= z < cell_m`
    /// above the vehicle frame's ground plane z = 0).
    pub fn layer(&self, z_m: f32) -> i32 {
        (z_m / self.cell_m).floor() as i32
    }
}
