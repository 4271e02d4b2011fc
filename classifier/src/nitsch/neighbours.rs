//! The 8-neighbourhood of a cell on the ordered grid, enumerated as in Fig. 3 of Nitsch et al. so
//! that flat horizontal ground below the sensor gives normals pointing to `+z`.
//!
//! Grid convention (see `sim::OrderedCloud`): row 0 is the lowest beam and rows go up in elevation
//! (on ground: farther away); column 0 is left-most and azimuth decreases with the column index
//! (clockwise seen from above). With `d_i = P_i - P` and `n_i = d_i x d_(i-1)` the neighbours must
//! be visited clockwise seen from above, which in grid offsets `(row, col)` is
//!
//! ```text
//!   d8 (+1,-1)   d1 (+1, 0)   d2 (+1,+1)
//!   d7 ( 0,-1)       P        d3 ( 0,+1)
//!   d6 (-1,-1)   d5 (-1, 0)   d4 (-1,+1)
//! ```
//!
//! (for ground ahead, `d1` points forward, `d3` to the right; `d3 x d2`, `d2 x d1`, ... are `+z`).
//!
//! Missing neighbours (decision, tested): a neighbour is the nearest *return* in its direction,
//! searched up to `max_col_gap` columns away along the row, because merged multi-sensor grids and
//! dropouts leave empty cells between physical neighbours. In the rows above and below, the centre
//! neighbour (`d1`, `d5`) is the return nearest to the cell's column (within `max_col_gap`, `+` side
//! first on ties), and the diagonal neighbours are the next returns beyond it on either side. A row
//! with no return within `max_col_gap` of the column is skipped, up to [`MAX_ROW_GAP`] rows away: on
//! the merged `lux-roof-4` grid two of every four layers have a narrower field of view (85 instead
//! of 110 degrees), so near the left and right edges every other pair of rows is empty and the
//! physical neighbour of a ring lies two rows further (measured on `rural`: without the skip, far
//! terrain at the edges had neighbours only along its own row, no normal and no ground). With a
//! dense grid this is exactly the plain 8-neighbourhood. Beyond the grid's top and bottom rows there
//! is nothing; beyond its left and right columns the search wraps only for 360-degree sensors
//! ([`Wrap`]). A neighbour farther than `max_distance_m` from the cell is dropped (the paper uses no
//! such threshold, so the default is infinity).

use glam::Vec3;

use crate::error::is_valid;
use crate::ordering::polar::atan2_lane;

/// How many rows up or down [`GridView::neighbours`] looks for a row with a return near the
/// column (module docs): 3 skips the two empty rows at the edges of the merged `lux-roof-4` grid.
/// On grids without empty rows it changes nothing.
pub const MAX_ROW_GAP: usize = 3;

/// Whether column 0 and column `cols - 1` are neighbours (a sensor that spins all the way round).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// Decide from the data with [`detect_wrap`].
    #[default]
    Auto,
    /// Always wrap (360-degree sensor).
    Always,
    /// Never wrap (sensor with a limited field of view).
    Never,
}

/// How neighbours are looked up on the grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeighbourParams {
    /// How far along a row to look for the nearest return, columns (>= 1; 1 = direct neighbours only).
    pub max_col_gap: usize,
    /// Neighbours farther than this from the cell are missing, metres (infinity = no threshold, as in the paper).
    pub max_distance_m: f32,
    /// Column wrap-around.
    pub wrap: Wrap,
}

impl Default for NeighbourParams {
    fn default() -> Self {
        Self { max_col_gap: 2, max_distance_m: f32::INFINITY, wrap: Wrap::Auto }
    }
}

/// A view of one echo plane of a cloud as a rows x cols grid of points.
#[derive(Clone, Copy, Debug)]
pub struct GridView<'a> {
    /// Points of the plane, row-major, NaN where no return.
    pub points: &'a [Vec3],
    /// Measured range per cell, metres (NaN where unknown: the occlusion test is then skipped).
    pub ranges: &'a [f32],
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// Whether columns wrap around (resolved, not `Auto`).
    pub wrap: bool,
    /// Column search distance, >= 1.
    pub max_col_gap: usize,
}

impl<'a> GridView<'a> {
    /// Column `c + k` (k may be negative) in range, wrapping if the grid wraps.
    #[inline]
    fn col(&self, c: usize, k: isize) -> Option<usize> {
        let cc = c as isize + k;
        if cc >= 0 && (cc as usize) < self.cols {
            Some(cc as usize)
        } else if self.wrap {
            Some(cc.rem_euclid(self.cols as isize) as usize)
        } else {
            None
        }
    }

    /// The first return in row `r` starting one step from `c` in direction `step` (+1 / -1).
    #[inline]
    fn first_along(&self, r: usize, c: usize, step: isize) -> Option<usize> {
        let base = r * self.cols;
        for k in 1..=self.max_col_gap as isize {
            let cc = self.col(c, k * step)?;
            if is_valid(self.points[base + cc]) {
                return Some(cc);
            }
        }
        None
    }

    /// The return in row `r` nearest to column `c` (`c` itself, then `c+1`, `c-1`, `c+2`, ...).
    #[inline]
    fn nearest_in_row(&self, r: usize, c: usize) -> Option<usize> {
        let base = r * self.cols;
        if is_valid(self.points[base + c]) {
            return Some(c);
        }
        for k in 1..=self.max_col_gap as isize {
            for kk in [k, -k] {
                if let Some(cc) = self.col(c, kk)
                    && is_valid(self.points[base + cc])
                {
                    return Some(cc);
                }
            }
        }
        None
    }

    /// Fast path: the 8 direct neighbours (order `d1..d8`) of an interior cell when all hold
    /// returns; then they are exactly what [`GridView::neighbours`] returns, and each of them has
    /// the cell among its own neighbours (the relation is symmetric).
    #[inline]
    pub fn direct_neighbours(&self, r: usize, c: usize) -> Option<[usize; 8]> {
        let cols = self.cols;
        if r > 0 && r + 1 < self.rows && c > 0 && c + 1 < cols {
            let i = r * cols + c;
            let idx = [i + cols, i + cols + 1, i + 1, i - cols + 1, i - cols, i - cols - 1, i - 1, i + cols - 1];
            if idx.iter().all(|&j| is_valid(self.points[j])) {
                return Some(idx);
            }
        }
        None
    }

    /// Cell indices (within the plane) of the 8 neighbours of `(r, c)` in the order `d1..d8` of the
    /// module docs; `None` where missing (distance threshold not applied here).
    #[inline]
    pub fn neighbours(&self, r: usize, c: usize) -> [Option<usize>; 8] {
        let cols = self.cols;
        if let Some(idx) = self.direct_neighbours(r, c) {
            return idx.map(Some);
        }
        let mut out = [None; 8];
        // The nearest row above (below) with a return near the column, skipping empty rows.
        let gap = MAX_ROW_GAP;
        if let Some((up, cc)) =
            (r + 1..self.rows.min(r + 1 + gap)).find_map(|up| Some((up, self.nearest_in_row(up, c)?)))
        {
            out[0] = Some(up * cols + cc);
            out[1] = self.first_along(up, cc, 1).map(|x| up * cols + x);
            out[7] = self.first_along(up, cc, -1).map(|x| up * cols + x);
        }
        out[2] = self.first_along(r, c, 1).map(|x| r * cols + x);
        out[6] = self.first_along(r, c, -1).map(|x| r * cols + x);
        if let Some((dn, cc)) = (r.saturating_sub(gap)..r).rev().find_map(|dn| Some((dn, self.nearest_in_row(dn, c)?)))
        {
            out[4] = Some(dn * cols + cc);
            out[3] = self.first_along(dn, cc, 1).map(|x| dn * cols + x);
            out[5] = self.first_along(dn, cc, -1).map(|x| dn * cols + x);
        }
        out
    }
}

/// Rows [`detect_wrap`] looks at, at most: 32 rows of a 128-row grid judge a turn as well as all of
/// them, at a quarter of the cost (a pass over every point took 0.4 ms of the 6 ms of a frame).
pub const WRAP_ROWS: usize = 32;

/// Decides whether a plane's columns span a full turn, from the data: the azimuths (about the
/// vehicle's z axis) of the returns in the first and last columns must be about one column step
/// apart across the +-pi cut, and the columns together must cover more than 350 degrees.
/// A sensor mounted off the vehicle origin shifts near azimuths, so each column's azimuth is taken
/// from its farthest return among [`WRAP_ROWS`] rows spread over the grid (the top row and every
/// `ceil(rows / WRAP_ROWS)`-th row below it: all rows of a grid that has no more). Returns false
/// when a column has no return to judge from.
pub fn detect_wrap(points: &[Vec3], rows: usize, cols: usize) -> bool {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::avx512() {
        // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ, AVX2, BMI1 and BMI2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return detect_wrap_avx512(points, rows, cols);
        }
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return detect_wrap_avx2(points, rows, cols);
        }
    }
    detect_wrap_body(points, rows, cols)
}

/// [`detect_wrap_body`] compiled for AVX2 (plain IEEE operations: the same result).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn detect_wrap_avx2(points: &[Vec3], rows: usize, cols: usize) -> bool {
    detect_wrap_body(points, rows, cols)
}

/// [`detect_wrap_body`] compiled for AVX-512 ([`crate::cpu::avx512`]) (plain IEEE operations: the same result).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
fn detect_wrap_avx512(points: &[Vec3], rows: usize, cols: usize) -> bool {
    detect_wrap_body(points, rows, cols)
}

/// The farthest return (horizontal distance from the z axis) of every column among [`WRAP_ROWS`]
/// rows spread over the grid (the top row and every `ceil(rows / WRAP_ROWS)`-th row below it), the
/// first of equals going up the rows: per column its squared horizontal distance (-inf where the
/// rows looked at have no return), x and y (0 there).
///
/// One branch-free pass in memory order. It is bound by reading the points (a third of a KITTI
/// frame's grid): measured, not kept, on KITTI frames: a running maximum of `(distance, row)` keys
/// instead of the selects (1.32 % of the samples against 1.13 %), the columns 8 at a time over the
/// rows with the best values in registers (2.2 %).
#[inline(always)]
fn far_returns(points: &[Vec3], rows: usize, cols: usize) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
    let mut far_d2 = vec![f32::NEG_INFINITY; cols];
    let (mut far_x, mut far_y) = (vec![0f32; cols], vec![0f32; cols]);
    if rows == 0 || points.len() < rows * cols {
        return (far_d2, far_x, far_y);
    }
    // Counted from the top row, where far returns are: the sample always includes it.
    let step = rows.div_ceil(WRAP_ROWS);
    let sampled = (0..rows).filter(|r| (rows - 1 - r).is_multiple_of(step));
    for row in sampled.map(|r| &points[r * cols..(r + 1) * cols]) {
        for (((bd, bx), by), p) in far_d2.iter_mut().zip(far_x.iter_mut()).zip(far_y.iter_mut()).zip(row) {
            let d2 = p.x * p.x + p.y * p.y;
            let better = (p.x.is_finite() & p.y.is_finite() & p.z.is_finite()) & (d2 > *bd);
            *bd = if better { d2 } else { *bd };
            (*bx, *by) = if better { (p.x, p.y) } else { (*bx, *by) };
        }
    }
    (far_d2, far_x, far_y)
}

/// The body of [`detect_wrap`], inlined into each instruction-set variant.
#[inline(always)]
fn detect_wrap_body(points: &[Vec3], rows: usize, cols: usize) -> bool {
    if cols < 3 || rows == 0 || points.len() < rows * cols {
        return false;
    }
    let (far_d2, far_x, far_y) = far_returns(points, rows, cols);
    // The columns' azimuths in one pass that vectorizes (a polynomial within 1e-6 rad of libm's
    // `atan2`; sampled on KITTI frames, the test went from 1.5 to 1.05 % of the time of read,
    // order and classify); read only for columns with a return.
    let azimuth: Vec<f32> = far_x.iter().zip(&far_y).map(|(&x, &y)| atan2_lane(y, x)).collect();
    let col_azimuth = |c: usize| -> Option<f32> { (far_d2[c] > f32::NEG_INFINITY).then_some(azimuth[c]) };
    let wrap_diff = |a: f32, b: f32| {
        let mut d = a - b;
        while d > std::f32::consts::PI {
            d -= std::f32::consts::TAU;
        }
        while d < -std::f32::consts::PI {
            d += std::f32::consts::TAU;
        }
        d
    };
    let (Some(first), Some(last)) = (col_azimuth(0), col_azimuth(cols - 1)) else {
        return false;
    };
    let step = std::f32::consts::TAU / cols as f32;
    // Azimuth decreases with the column index, so the last column sits one step "before" column 0.
    let gap = wrap_diff(last, first).abs();
    // Total sweep: walk columns with returns and add up the (decreasing) azimuth differences.
    let mut swept = 0.0f32;
    let mut prev = first;
    for c in 1..cols {
        if let Some(a) = col_azimuth(c) {
            swept += wrap_diff(prev, a).abs();
            prev = a;
        }
    }
    gap < 4.0 * step && swept > 350f32.to_radians()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`far_returns`] against its definition, cell by cell: a grid whose columns are not a
    /// multiple of the vector width, rows sampled every third, bad points, columns without a
    /// return, and ties (equal distances in two rows: the lower row's point).
    #[test]
    fn far_returns_are_each_columns_farthest_sampled_return() {
        let (rows, cols): (usize, usize) = (70, 203);
        let step = rows.div_ceil(WRAP_ROWS);
        assert_eq!(step, 3);
        let mut points = vec![Vec3::NAN; rows * cols];
        for r in 0..rows {
            for c in 0..cols {
                let k = (r * 31 + c * 17) % 101;
                let p = match k {
                    0..=4 => Vec3::new(f32::NAN, 1.0, 1.0),
                    5..=9 => Vec3::new(1.0, 1.0, f32::INFINITY),
                    // The same horizontal distance (5 m) in many rows, mirrored in x and y.
                    10..=39 if r % 2 == 0 => Vec3::new(3.0, 4.0, r as f32),
                    10..=39 => Vec3::new(4.0, -3.0, r as f32),
                    _ => Vec3::new(k as f32 * 0.04, (c % 7) as f32 - 3.0, -1.5),
                };
                points[r * cols + c] = if c % 50 == 7 { Vec3::NAN } else { p };
            }
        }
        let (d2, x, y) = far_returns(&points, rows, cols);
        let mut ties = 0;
        for c in 0..cols {
            let mut want = (f32::NEG_INFINITY, 0.0, 0.0);
            for r in (0..rows).filter(|r| (rows - 1 - r) % step == 0) {
                let p = points[r * cols + c];
                let e = p.x * p.x + p.y * p.y;
                if p.is_finite() && e > want.0 {
                    want = (e, p.x, p.y);
                } else if p.is_finite() && e == want.0 && (p.x, p.y) != (want.1, want.2) {
                    ties += 1;
                }
            }
            assert_eq!((d2[c], x[c], y[c]), want, "column {c}");
        }
        assert!(ties > 100, "{ties} ties");
        let none: Vec<usize> = (0..cols).filter(|&c| d2[c] == f32::NEG_INFINITY).collect();
        assert_eq!(none, [7, 57, 107, 157]);
    }
}
