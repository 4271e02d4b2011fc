//! Feature f7, the pyramid filter (McDaniel et al., Fig. 3; a discretised form of the downward cone
//! of Lalonde et al.): the number of other candidates inside the pyramid of cubic voxels under a
//! candidate `P_ij`.
//!
//! Voxels are `cell_m` cubes aligned with the columns; vertically, layer `k` spans
//! `k * cell_m <= z < (k + 1) * cell_m` in the vehicle frame (z = 0 on the ground under the vehicle
//! origin). The apex is the voxel of `P_ij` (column `(i, j)`, layer `k`); the layer `d` below it
//! (`1 <= d <=` [`super::FeatureParams::pyramid_layers`]) spans the `(2d + 1) x (2d + 1)` voxels of
//! columns `i - d ..= i + d`, `j - d ..= j + d` at layer `k - d`. A candidate `Q` in column
//! `(a, b)`, layer `k_Q`, is inside iff `d = k - k_Q` is in `1..=layers` and
//! `max(|a - i|, |b - j|) <= d`. The apex voxel holds no other candidate (one per column), so the
//! count runs over the layers below it.

use rayon::prelude::*;

use super::columns::Columns;

/// f7 of candidate `k` with a pyramid `layers` voxel layers deep.
pub fn pyramid_count(columns: &Columns, k: usize, layers: u32) -> u32 {
    let (i, j) = columns.ij(k);
    let apex = columns.layer(columns.point_in_vehicle[k].z);
    let r = layers as i32;
    let mut count = 0;
    for di in -r..=r {
        for dj in -r..=r {
            if di == 0 && dj == 0 {
                continue;
            }
            if let Some(q) = columns.candidate_at(i + di, j + dj) {
                let d = apex - columns.layer(columns.point_in_vehicle[q].z);
                if d >= 1 && d <= r && di.abs().max(dj.abs()) <= d {
                    count += 1;
                }
            }
        }
    }
    count
}

/// f7 of every candidate, in candidate order (parallel, independent per candidate).
pub fn all_pyramid_counts(columns: &Columns, layers: u32) -> Vec<u32> {
    (0..columns.len()).into_par_iter().with_min_len(256).map(|k| pyramid_count(columns, k, layers)).collect()
}
