//! Local features of Nitsch et al. (Sec. III-A) per cell of one echo plane: the inverse-distance
//! weighted surface normal `n` (Eq. 1-2), the normal quality `n_rho` (Eq. 3) and the ground quality
//! `g_rho = n . z * n_rho` (Eq. 4).
//!
//! Decisions where the paper is silent (tested below):
//! - A pair normal `n_i = d_i x d_(i-1)` exists only where both neighbours exist (see
//!   [`crate::neighbours`] for what counts as a neighbour) and the cross product is not degenerate.
//! - `n_rho` averages the cosine similarity over the pairs that exist rather than always dividing by
//!   8 (identical when all 8 neighbours exist); otherwise the lowest ring, which always lacks the
//!   three neighbours below it, could never exceed `n_rho = 0.5` and never be ground.
//! - A cell with fewer than `min_valid_pairs` pair normals (isolated returns, a corner of the grid)
//!   gets `n = 0`, `n_rho = 0` and `g_rho = 0`: it is never a ground candidate.
//! - Cells without a return get the same zeros.

use glam::Vec3;

use crate::error::{ClassifyError, Result, is_valid};
use crate::neighbours::GridView;

/// Parameters of the feature computation besides the neighbourhood.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeatureParams {
    /// Fewest pair normals a cell needs to get features (>= 1).
    pub min_valid_pairs: usize,
    /// Neighbours farther than this are missing, metres (infinity: the paper's choice).
    pub max_neighbour_distance_m: f32,
}

impl Default for FeatureParams {
    fn default() -> Self {
        Self { min_valid_pairs: 2, max_neighbour_distance_m: f32::INFINITY }
    }
}

impl FeatureParams {
    /// Refuses values outside their ranges.
    pub fn validate(&self) -> Result<()> {
        if !(1..=8).contains(&self.min_valid_pairs) {
            return Err(ClassifyError::invalid("min_valid_pairs", self.min_valid_pairs, "1 ..= 8"));
        }
        if self.max_neighbour_distance_m.is_nan() || self.max_neighbour_distance_m <= 0.0 {
            return Err(ClassifyError::invalid("max_neighbour_distance_m", self.max_neighbour_distance_m, "> 0"));
        }
        Ok(())
    }
}

/// Per-cell features of one echo plane (row-major, `rows * cols`). Buffers are reused between frames.
#[derive(Clone, Debug, Default)]
pub struct Features {
    /// Unit surface normal `n` (Eq. 2); zero where the cell has no features.
    pub normal: Vec<Vec3>,
    /// Normal quality `n_rho` (Eq. 3), in `[-1, 1]`; 0 where the cell has no features.
    pub n_rho: Vec<f32>,
    /// Ground quality `g_rho` (Eq. 4), in `[-1, 1]`; 0 where the cell has no features.
    pub g_rho: Vec<f32>,
}

impl Features {
    /// Resizes the buffers to `n` cells (no reallocation when the size is unchanged).
    fn resize(&mut self, n: usize) {
        self.normal.resize(n, Vec3::ZERO);
        self.n_rho.resize(n, 0.0);
        self.g_rho.resize(n, 0.0);
    }
}

/// Computes the features of every cell of `view` into `out`.
pub fn compute_features(view: &GridView<'_>, params: &FeatureParams, out: &mut Features) {
    let (rows, cols) = (view.rows, view.cols);
    out.resize(rows * cols);
    let max_d2 = params.max_neighbour_distance_m * params.max_neighbour_distance_m;
    let min_pairs = params.min_valid_pairs;
    for r in 0..rows {
        for c in 0..cols {
            let i = r * cols + c;
            let p = view.points[i];
            let (n, n_rho) = if is_valid(p) {
                cell_features(view, p, view.neighbours(r, c), max_d2, min_pairs)
            } else {
                (Vec3::ZERO, 0.0)
            };
            out.normal[i] = n;
            out.n_rho[i] = n_rho;
            out.g_rho[i] = n.z * n_rho;
        }
    }
}

/// Eq. 1-3 for one cell at `p` with neighbour cells `nb` (order `d1..d8`).
#[inline]
fn cell_features(view: &GridView<'_>, p: Vec3, nb: [Option<usize>; 8], max_d2: f32, min_pairs: usize) -> (Vec3, f32) {
    let mut d = [Vec3::ZERO; 8];
    let mut len = [0f32; 8];
    let mut ok = [false; 8];
    for k in 0..8 {
        if let Some(j) = nb[k] {
            let dk = view.points[j] - p;
            let l2 = dk.length_squared();
            if l2 <= max_d2 && l2 > 0.0 {
                d[k] = dk;
                len[k] = l2.sqrt();
                ok[k] = true;
            }
        }
    }
    // Eq. 1: n_i = d_i x d_(i-1) for i = 2..8, n_1 = d_1 x d_8 (0-based: k and k-1, 0 and 7).
    let mut ni = [Vec3::ZERO; 8];
    let mut ni_len = [0f32; 8];
    let mut sum = Vec3::ZERO;
    let mut pairs = 0usize;
    for k in 0..8 {
        let prev = if k == 0 { 7 } else { k - 1 };
        if ok[k] && ok[prev] {
            let n = d[k].cross(d[prev]);
            let l = n.length();
            // Degenerate pair (collinear neighbours): no direction, skip it.
            if l > 1e-12 * len[k] * len[prev] {
                // Eq. 2 weight: inverse of the summed neighbour distances.
                sum += n / (len[k] + len[prev]);
                ni[k] = n;
                ni_len[k] = l;
                pairs += 1;
            }
        }
    }
    if pairs < min_pairs {
        return (Vec3::ZERO, 0.0);
    }
    let sum_len = sum.length();
    if sum_len <= 0.0 || !sum_len.is_finite() {
        return (Vec3::ZERO, 0.0);
    }
    let n = sum / sum_len;
    // Eq. 3: mean cosine similarity between n and its generating normals.
    let mut cos_sum = 0.0;
    for k in 0..8 {
        if ni_len[k] > 0.0 {
            cos_sum += n.dot(ni[k]) / ni_len[k];
        }
    }
    (n, cos_sum / pairs as f32)
}
