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
//! - The pair normals enter Eq. 2 as the paper writes them, `d_i x d_(i-1)` (not unit vectors).
//!   Unit pair normals were tried (the text's aim is to "rely more on physically closer points")
//!   and rejected: nearly collinear pairs of far neighbours then get a full vote, which lost a
//!   quarter of the far-side terrain in the basin test.
//! - Occlusion (tested): a neighbour whose measured range is less than `1 - ratio` times the
//!   cell's is an occluder in front of it (a car's bumper above ground seen under the car) and is
//!   left out. This is a ratio of ranges, so unlike the fixed distance threshold the paper rejects
//!   it does not depend on the mounting height, the pitch or the range. Only the neighbours in the
//!   row above (`d8`, `d1`, `d2`) are tested by default (`upper_occlusion_ratio` 0.05): on ground
//!   they are farther than the cell, on a wall below the horizon nearer by well under 5 %, so an
//!   upper neighbour nearer than that is an occluder (measured: ground seen under cars on `city`
//!   with `lux-roof-4`). The same test on all neighbours (`occlusion_ratio`, 0 = off, the default)
//!   drops the lower neighbours of far ground, which are naturally nearer by about
//!   `range * beam gap / height`.

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
    /// A neighbour whose range is below `(1 - occlusion_ratio)` times the cell's range occludes
    /// it and is missing (0 = off).
    pub occlusion_ratio: f32,
    /// The same for the neighbours in the row above (`d8`, `d1`, `d2`), which on any surface the
    /// beam does not graze from below are never nearer than the cell by more than a few percent.
    pub upper_occlusion_ratio: f32,
}

impl Default for FeatureParams {
    fn default() -> Self {
        Self {
            min_valid_pairs: 2,
            max_neighbour_distance_m: f32::INFINITY,
            occlusion_ratio: 0.0,
            upper_occlusion_ratio: 0.05,
        }
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
        if !(self.occlusion_ratio.is_finite() && (0.0..1.0).contains(&self.occlusion_ratio)) {
            return Err(ClassifyError::invalid("occlusion_ratio", self.occlusion_ratio, "0 ..< 1"));
        }
        if !(self.upper_occlusion_ratio.is_finite() && (0.0..1.0).contains(&self.upper_occlusion_ratio)) {
            return Err(ClassifyError::invalid("upper_occlusion_ratio", self.upper_occlusion_ratio, "0 ..< 1"));
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
    // Ratio 0 switches the test off (keep every neighbour: factor 0).
    let factor = |ratio: f32| if ratio > 0.0 { 1.0 - ratio } else { 0.0 };
    let (up, other) = (factor(params.upper_occlusion_ratio), factor(params.occlusion_ratio));
    let keep = [up, up, other, other, other, other, other, up];
    for r in 0..rows {
        for c in 0..cols {
            let i = r * cols + c;
            let p = view.points[i];
            let (n, n_rho) = if is_valid(p) {
                cell_features(view, i, p, view.neighbours(r, c), max_d2, keep, min_pairs)
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
///
/// Written branch-free over 8 lanes (`[f32; 8]` per coordinate) so the compiler vectorizes it:
/// missing neighbours and degenerate pairs get weight 0 instead of a branch.
#[inline]
fn cell_features(
    view: &GridView<'_>,
    i: usize,
    p: Vec3,
    nb: [Option<usize>; 8],
    max_d2: f32,
    keep: [f32; 8],
    min_pairs: usize,
) -> (Vec3, f32) {
    let (mut dx, mut dy, mut dz, mut ok) = ([0f32; 8], [0f32; 8], [0f32; 8], [0f32; 8]);
    // Neighbours nearer than `keep[k] * range` occlude the cell (NaN ranges compare false: kept).
    let range = view.ranges[i];
    for k in 0..8 {
        if let Some(j) = nb[k] {
            let d = view.points[j] - p;
            let l2 = d.length_squared();
            if l2 <= max_d2
                && l2 > 0.0
                && view.ranges[j].partial_cmp(&(keep[k] * range)) != Some(std::cmp::Ordering::Less)
            {
                (dx[k], dy[k], dz[k], ok[k]) = (d.x, d.y, d.z, 1.0);
            }
        }
    }
    pair_features(&dx, &dy, &dz, &ok, min_pairs)
}

/// Eq. 1-3 from the neighbour offsets (lane k = `d_(k+1)`; `ok` 1 where the neighbour exists).
#[inline]
fn pair_features(dx: &[f32; 8], dy: &[f32; 8], dz: &[f32; 8], ok: &[f32; 8], min_pairs: usize) -> (Vec3, f32) {
    // The previous neighbour of lane k is lane k - 1 (lane 7 for lane 0): Eq. 1's d_(i-1) and d_8.
    let prev = |a: &[f32; 8]| [a[7], a[0], a[1], a[2], a[3], a[4], a[5], a[6]];
    let (px, py, pz, pok) = (prev(dx), prev(dy), prev(dz), prev(ok));
    let mut len = [0f32; 8];
    for k in 0..8 {
        len[k] = (dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k]).sqrt();
    }
    let plen = prev(&len);
    let (mut nx, mut ny, mut nz, mut w, mut inv) = ([0f32; 8], [0f32; 8], [0f32; 8], [0f32; 8], [0f32; 8]);
    for k in 0..8 {
        // Eq. 1: n_i = d_i x d_(i-1).
        nx[k] = dy[k] * pz[k] - dz[k] * py[k];
        ny[k] = dz[k] * px[k] - dx[k] * pz[k];
        nz[k] = dx[k] * py[k] - dy[k] * px[k];
        let nl = (nx[k] * nx[k] + ny[k] * ny[k] + nz[k] * nz[k]).sqrt();
        // A pair exists when both neighbours do and the cross product is not degenerate.
        let valid = ok[k] * pok[k] * f32::from(u8::from(nl > 1e-12 * len[k] * plen[k]));
        // Eq. 2 weight 1 / (|d_i| + |d_(i-1)|); Eq. 3 needs 1 / |n_i|.
        inv[k] = valid / nl.max(f32::MIN_POSITIVE);
        w[k] = valid / (len[k] + plen[k]).max(f32::MIN_POSITIVE);
    }
    let (mut sx, mut sy, mut sz, mut pairs) = (0f32, 0f32, 0f32, 0f32);
    for k in 0..8 {
        sx += nx[k] * w[k];
        sy += ny[k] * w[k];
        sz += nz[k] * w[k];
        pairs += f32::from(u8::from(inv[k] > 0.0));
    }
    let sum_len = (sx * sx + sy * sy + sz * sz).sqrt();
    if (pairs as usize) < min_pairs || !(sum_len > 0.0 && sum_len.is_finite()) {
        return (Vec3::ZERO, 0.0);
    }
    let n = Vec3::new(sx, sy, sz) / sum_len;
    // Eq. 3: mean cosine similarity between n and its generating normals.
    let mut cos_sum = 0.0;
    for k in 0..8 {
        cos_sum += (n.x * nx[k] + n.y * ny[k] + n.z * nz[k]) * inv[k];
    }
    (n, cos_sum / pairs)
}
