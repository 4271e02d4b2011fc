//! The learned method's features: per cell of echo plane 0, numbers that do not depend on where
//! the frame's origin lies or which way the vehicle faces (heights are measured against the
//! frame's own ground, angles between returns), computed from the ordered grid, the returns' x-y
//! cells and a first classification by Nitsch et al. (its normal, normal and ground quality, its
//! decision and cluster).
//!
//! | feature | what |
//! |---|---|
//! | `normal_z` | the vertical part of Nitsch's normal (0 where the cell has none) |
//! | `n_rho`, `g_rho` | Nitsch's normal quality and ground quality (Eq. 3, 4) |
//! | `nitsch` | Nitsch's decision (0 or 1) |
//! | `cluster_size` | points of the cell's Nitsch cluster (0 for non-candidates) |
//! | `range_m` | the measured range |
//! | `height_above_ground_m` | height above the ground map's level under the return ([`super::ground_map`]) |
//! | `height_above_coarse_ground_m` | the same against the 8 m cells' level |
//! | `height_above_frame_ground_m` | the same against the frame's ground level (median of Nitsch's ground within 20 m) |
//! | `height_above_cell_lowest_m` | height above the lowest return of its 1 m cell |
//! | `cell_span_m` | highest minus lowest return of its 1 m cell |
//! | `cell_ground_share` | share of its 1 m cell's returns Nitsch called ground |
//! | `gradient_below`, `gradient_above` | the steepness of the step to the next return below and above it in its column (within 3 rows; [`NO_NEIGHBOUR`] where none): `rise * abs(rise) / run^2`, the squared tangent with its sign. The trees split on order, so any monotone measure of the slope does, and this one needs no arctangent or square root |
//! | `row_step_m` | mean height step to its left and right neighbours in its row (within 1 m; [`NO_NEIGHBOUR`] where none) |

use super::ground_map::GroundMap;
use crate::nitsch::Nitsch;

/// Number of features.
pub const FEATURE_COUNT: usize = 15;

/// The features' names, in order (the model file lists them).
pub const FEATURE_NAMES: [&str; FEATURE_COUNT] = [
    "normal_z",
    "n_rho",
    "g_rho",
    "nitsch",
    "cluster_size",
    "range_m",
    "height_above_ground_m",
    "height_above_coarse_ground_m",
    "height_above_frame_ground_m",
    "height_above_cell_lowest_m",
    "cell_span_m",
    "cell_ground_share",
    "gradient_below",
    "gradient_above",
    "row_step_m",
];

/// The value of a feature that needs a neighbour where there is none.
pub const NO_NEIGHBOUR: f32 = 100.0;

/// Rows searched for the neighbour below or above in a column.
const COLUMN_SEARCH_ROWS: usize = 3;

/// Largest horizontal distance of a row neighbour, metres.
const ROW_NEIGHBOUR_M: f32 = 1.0;

/// The features of the returns of plane 0, one column per feature: `columns[k][j]` is feature `k`
/// of the return in cell `cells[j]` (the cells with a return, in grid order). Each column is
/// padded with zeros to a multiple of [`super::LANES`] (the trees read whole lanes). Buffers are
/// reused between frames.
#[derive(Clone, Debug, Default)]
pub struct FeatureColumns {
    /// The cells with a return, in grid order.
    pub cells: Vec<u32>,
    /// `columns[k][j]`: feature `k` of the return in cell `cells[j]`.
    pub columns: Vec<Vec<f32>>,
    /// The ground map the heights were measured against.
    pub map: GroundMap,
    grid: GridSteps,
}

/// Per grid cell of plane 0: its coordinates and steps (buffers reused between frames).
#[derive(Clone, Debug, Default)]
struct GridSteps {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    below: Vec<f32>,
    above: Vec<f32>,
    row_step: Vec<f32>,
}

/// The steepness of the step from each cell of `row` to the cell of `other` in its column, as
/// `sign * rise * abs(rise) / run^2` (the squared tangent with its sign: the same order as the
/// tangent, with no square root or arctangent; clamped to `+-NO_NEIGHBOUR / 2`), written to `out`
/// where `other`'s cell holds a return (its coordinates are finite) and left as it is elsewhere.
#[inline(always)]
fn steepest(
    x: &[f32],
    y: &[f32],
    z: &[f32],
    row: std::ops::Range<usize>,
    other: std::ops::Range<usize>,
    sign: f32,
    out: &mut [f32],
) {
    let half = 0.5 * NO_NEIGHBOUR;
    let (xr, yr, zr) = (&x[row.clone()], &y[row.clone()], &z[row.clone()]);
    let (xo, yo, zo) = (&x[other.clone()], &y[other.clone()], &z[other]);
    for (k, o) in out[row].iter_mut().enumerate() {
        let (dx, dy, dz) = (xo[k] - xr[k], yo[k] - yr[k], zo[k] - zr[k]);
        let d2 = (dx * dx + dy * dy).max(1e-8);
        let g = (sign * dz * dz.abs() / d2).clamp(-half, half);
        // NaN (no return there) compares false: keep what is there.
        *o = if zo[k].is_nan() { *o } else { g };
    }
}

/// Per cell of one row: the mean height step to its left and right neighbours that hold a return
/// within [`ROW_NEIGHBOUR_M`] (horizontally), [`NO_NEIGHBOUR`] where neither does.
#[inline(always)]
fn row_steps(x: &[f32], y: &[f32], z: &[f32], out: &mut [f32]) {
    let cols = z.len();
    let near = |a: usize, b: usize| {
        let (dx, dy) = (x[a] - x[b], y[a] - y[b]);
        // False for NaN.
        dx * dx + dy * dy <= ROW_NEIGHBOUR_M * ROW_NEIGHBOUR_M
    };
    for c in 0..cols {
        let (mut sum, mut count) = (0.0f32, 0.0f32);
        if c > 0 && near(c, c - 1) {
            sum += (z[c - 1] - z[c]).abs();
            count += 1.0;
        }
        if c + 1 < cols && near(c, c + 1) {
            sum += (z[c + 1] - z[c]).abs();
            count += 1.0;
        }
        out[c] = if count > 0.0 { sum / count } else { NO_NEIGHBOUR };
    }
}

impl FeatureColumns {
    /// Returns described.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// Whether no return is described.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Computes the features of plane 0 of `cloud` after `nitsch` classified it (its features and
    /// clusters are those of the same cloud, its rows not reordered) with plane-0 decisions
    /// `nitsch_ground`. The grid's steps (gradients, row steps) are computed a row at a time over
    /// coordinate arrays, branch-free, and the rest per return; both as code compiled for AVX-512
    /// or AVX2 where the CPU has it (the same operations: the same bits).
    pub fn compute(&mut self, cloud: &sim::OrderedCloud, nitsch: &Nitsch, nitsch_ground: &[bool]) {
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::avx512() {
            // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ, AVX2, BMI1 and BMI2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.compute_avx512(cloud, nitsch, nitsch_ground);
            }
        }
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::avx2_bmi() {
            // SAFETY: the CPU supports AVX2, BMI1 and BMI2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.compute_avx2(cloud, nitsch, nitsch_ground);
            }
        }
        self.compute_body(cloud, nitsch, nitsch_ground);
    }

    /// [`FeatureColumns::compute_body`] compiled for AVX-512.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
    fn compute_avx512(&mut self, cloud: &sim::OrderedCloud, nitsch: &Nitsch, nitsch_ground: &[bool]) {
        self.compute_body(cloud, nitsch, nitsch_ground);
    }

    /// [`FeatureColumns::compute_body`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2")]
    fn compute_avx2(&mut self, cloud: &sim::OrderedCloud, nitsch: &Nitsch, nitsch_ground: &[bool]) {
        self.compute_body(cloud, nitsch, nitsch_ground);
    }

    #[inline(always)]
    fn compute_body(&mut self, cloud: &sim::OrderedCloud, nitsch: &Nitsch, nitsch_ground: &[bool]) {
        let (rows, cols) = (cloud.rows, cloud.cols);
        let n = rows * cols;
        let points = &cloud.point_in_vehicle[..n];
        self.map.build(points, &nitsch_ground[..n]);
        // The grid's steps, per cell.
        let g = &mut self.grid;
        for v in [&mut g.x, &mut g.y, &mut g.z, &mut g.below, &mut g.above, &mut g.row_step] {
            v.resize(n, 0.0);
        }
        for (k, p) in points.iter().enumerate() {
            (g.x[k], g.y[k], g.z[k]) = (p.x, p.y, p.z);
        }
        for r in 0..rows {
            let row = r * cols..(r + 1) * cols;
            // The nearest return below within COLUMN_SEARCH_ROWS rows: the farthest candidate
            // first, each nearer one replacing it where it holds a return.
            g.below[row.clone()].fill(NO_NEIGHBOUR);
            for k in (1..=COLUMN_SEARCH_ROWS.min(r)).rev() {
                let other = (r - k) * cols..(r - k + 1) * cols;
                steepest(&g.x, &g.y, &g.z, row.clone(), other, -1.0, &mut g.below);
            }
            g.above[row.clone()].fill(NO_NEIGHBOUR);
            for k in (1..=COLUMN_SEARCH_ROWS.min(rows - 1 - r)).rev() {
                let other = (r + k) * cols..(r + k + 1) * cols;
                steepest(&g.x, &g.y, &g.z, row.clone(), other, 1.0, &mut g.above);
            }
            row_steps(&g.x[row.clone()], &g.y[row.clone()], &g.z[row.clone()], &mut g.row_step[row]);
        }
        // Per return.
        self.cells.clear();
        self.cells.extend((0..n as u32).filter(|&i| points[i as usize].is_finite()));
        let count = self.cells.len();
        let padded = count.div_ceil(super::LANES) * super::LANES;
        self.columns.resize_with(FEATURE_COUNT, Vec::new);
        for c in &mut self.columns {
            c.resize(padded, 0.0);
            c[count..].fill(0.0);
        }
        let ws = &nitsch.workspace;
        let f = &nitsch.features;
        let map = &self.map;
        let g = &self.grid;
        let [
            normal_z,
            n_rho,
            g_rho,
            decided,
            cluster_size,
            range,
            above_ground,
            above_coarse,
            above_frame,
            above_lowest,
            span,
            share,
            gradient_below,
            gradient_above,
            row_step,
        ] = &mut self.columns[..]
        else {
            unreachable!("FEATURE_COUNT columns")
        };
        let has_features = f.g_rho.len() == n && f.n_rho.len() == n && f.normal.len() == n;
        let (cells, points, ground) = (&self.cells[..count], &points[..n], &nitsch_ground[..n]);
        // Four passes over the returns, each writing a few columns as slices of exactly `count`
        // values (no bounds check per store, the column pointers in registers).
        {
            let (normal_z, n_rho, g_rho, decided) =
                (&mut normal_z[..count], &mut n_rho[..count], &mut g_rho[..count], &mut decided[..count]);
            if has_features {
                let (normal, nr, gr) = (&f.normal[..n], &f.n_rho[..n], &f.g_rho[..n]);
                for (j, &cell) in cells.iter().enumerate() {
                    let i = cell as usize;
                    (normal_z[j], n_rho[j], g_rho[j]) = (normal[i].z, nr[i], gr[i]);
                }
            } else {
                normal_z.fill(0.0);
                n_rho.fill(0.0);
                g_rho.fill(0.0);
            }
            for (j, &cell) in cells.iter().enumerate() {
                decided[j] = f32::from(u8::from(ground[cell as usize]));
            }
        }
        {
            let (range, above_ground, above_coarse, above_frame) = (
                &mut range[..count],
                &mut above_ground[..count],
                &mut above_coarse[..count],
                &mut above_frame[..count],
            );
            let (above_lowest, span, share) = (&mut above_lowest[..count], &mut span[..count], &mut share[..count]);
            let (point_cells, range_m) = (&map.point_cells()[..n], &cloud.range_m[..n]);
            let global_level = map.global_level;
            for (j, &cell) in cells.iter().enumerate() {
                let i = cell as usize;
                let p = points[i];
                let rm = range_m[i];
                range[j] = if rm.is_finite() { rm } else { p.length() };
                let m = map.summary(point_cells[i] as usize);
                above_ground[j] = p.z - m.level;
                above_coarse[j] = p.z - m.coarse_level;
                above_frame[j] = p.z - global_level;
                above_lowest[j] = p.z - m.lowest;
                span[j] = m.span;
                share[j] = m.ground_share;
            }
        }
        {
            let (gradient_below, gradient_above, row_step) =
                (&mut gradient_below[..count], &mut gradient_above[..count], &mut row_step[..count]);
            let (below, above, row_steps) = (&g.below[..n], &g.above[..n], &g.row_step[..n]);
            for (j, &cell) in cells.iter().enumerate() {
                let i = cell as usize;
                (gradient_below[j], gradient_above[j], row_step[j]) = (below[i], above[i], row_steps[i]);
            }
        }
        // Cluster sizes: a walk up the union-find forest per candidate (scalar; most cells are not
        // candidates).
        for (size, &cell) in cluster_size[..count].iter_mut().zip(cells) {
            *size = ws.cluster_of(cell as usize).map_or(0.0, |root| ws.cluster_size(root) as f32);
        }
    }

    /// The features of the `j`-th return, in [`FEATURE_NAMES`] order.
    pub fn row(&self, j: usize) -> [f32; FEATURE_COUNT] {
        std::array::from_fn(|k| self.columns[k][j])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NitschParams;
    use glam::Vec3;

    #[test]
    fn heights_do_not_depend_on_the_frames_origin() {
        let cloud = crate::synthetic::noisy_cars_frame(0.0, 1, true, 0.0);
        let mut lifted = cloud.clone();
        for p in &mut lifted.point_in_vehicle {
            *p += Vec3::new(0.0, 0.0, 1.7);
        }
        let mut out = Vec::new();
        for c in [&cloud, &lifted] {
            let mut m = Nitsch::new(NitschParams { fix_row_order: false, ..Default::default() }).unwrap();
            let g = m.classify(c).unwrap();
            let mut f = FeatureColumns::default();
            f.compute(c, &m, &g);
            out.push(f);
        }
        assert_eq!(out[0].cells, out[1].cells);
        assert!(out[0].len() > 1000);
        for j in 0..out[0].len() {
            let (a, b) = (out[0].row(j), out[1].row(j));
            for k in 0..FEATURE_COUNT {
                assert!((a[k] - b[k]).abs() < 1e-4, "return {j} {}: {} vs {}", FEATURE_NAMES[k], a[k], b[k]);
            }
        }
        // On the flat ground, heights above the ground are 0, slopes along the ground near 0.
        let ground_cells: Vec<usize> = (0..out[0].len()).filter(|&j| cloud.ground[out[0].cells[j] as usize]).collect();
        let mean = |k: usize| {
            ground_cells.iter().map(|&i| out[0].columns[k][i].abs()).sum::<f32>() / ground_cells.len() as f32
        };
        assert!(mean(6) < 0.02, "height above ground {}", mean(6));
        // Gradients to the return below, where there is one: the ground's, 0 (the exact flat ground).
        let mut slopes: Vec<f32> =
            ground_cells.iter().map(|&i| out[0].columns[12][i]).filter(|&s| s != NO_NEIGHBOUR).collect();
        slopes.sort_by(f32::total_cmp);
        assert!(slopes[slopes.len() / 2].abs() < 0.01, "median gradient below {}", slopes[slopes.len() / 2]);
    }
}
