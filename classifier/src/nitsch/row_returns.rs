//! The general neighbour search ([`GridView::neighbours`]) of cells that lack a direct neighbour,
//! for features and clustering, by table lookups. Every answer of the search is made of three
//! questions about one row: the first return to the right of a column within `max_col_gap`, the
//! first to the left, and the return nearest to the column. Per plane, one byte per cell answers
//! each ([`RowReturns::build`]: passes over the rows that vectorize), so a cell's 8 neighbours are a
//! dozen byte loads and selects instead of a search (real recordings send about 16 % of their cells here: the
//! empty cells of an HDL-64E turn are scattered over every ring).
//!
//! The result is [`GridView::neighbours`]' for every cell, wrap and row skipping included (tested on
//! random grids). Grids narrower than `2 max_col_gap + 2` columns, where a wrapped search may come
//! back to its own column, take [`GridView::neighbours`] itself.

use crate::nitsch::neighbours::{GridView, MAX_ROW_GAP};

/// A missing neighbour in the tests' answers.
#[cfg(test)]
const NONE: u32 = u32::MAX;

/// No return near the column ([`RowReturns`]' `near`).
const FAR: i8 = i8::MIN;

/// Largest `max_col_gap` whose tables are built by shifted passes (one per column of reach); wider
/// searches (up to the 64 that the parameters allow) scan each row once in either direction.
const SHIFTED_GAP: usize = 8;

/// Per cell of a plane: where the returns nearest to it lie in its own row. Buffers are reused
/// between frames.
#[derive(Clone, Debug, Default)]
pub(crate) struct RowReturns {
    rows: usize,
    cols: usize,
    gap: usize,
    wrap: bool,
    /// Columns from the cell to the first return right of it (`c + 1 ..= c + gap`), 0 if none.
    right: Vec<u8>,
    /// Columns from the cell to the first return left of it (`c - 1 ..= c - gap`), 0 if none.
    left: Vec<u8>,
    /// Offset of the return nearest to the cell's column (`c`, `c + 1`, `c - 1`, ... within `gap`,
    /// the `+` side first), [`FAR`] if none.
    near: Vec<i8>,
}

impl RowReturns {
    /// Builds the tables of `view`'s grid from `valid` (whether each cell holds a return).
    pub(crate) fn build(&mut self, view: &GridView<'_>, valid: &[bool]) {
        let (rows, cols, gap) = (view.rows, view.cols, view.max_col_gap.clamp(1, 64));
        (self.rows, self.cols, self.gap, self.wrap) = (rows, cols, gap, view.wrap);
        let n = rows * cols;
        if self.narrow() {
            return;
        }
        self.right.resize(n, 0);
        self.left.resize(n, 0);
        self.near.resize(n, FAR);
        let tables = self
            .right
            .chunks_exact_mut(cols)
            .zip(self.left.chunks_exact_mut(cols))
            .zip(self.near.chunks_exact_mut(cols));
        for (v, ((right, left), near)) in valid[..n].chunks_exact(cols).zip(tables) {
            if gap <= SHIFTED_GAP {
                shifted(v, gap, right, left);
            } else {
                scanned(v, gap, right, left);
            }
            if view.wrap {
                wrapped_edges(v, gap, right, left);
            }
            for (c, ((&r, &l), o)) in right.iter().zip(left.iter()).zip(near.iter_mut()).enumerate() {
                // Itself, else the nearer side (the right on a tie).
                let side = if r != 0 && (l == 0 || r <= l) {
                    r as i8
                } else if l != 0 {
                    -(l as i8)
                } else {
                    FAR
                };
                *o = if v[c] { 0 } else { side };
            }
        }
    }

    /// Whether the grid is too narrow for the tables (a wrapped search may return to its column).
    fn narrow(&self) -> bool {
        self.cols < 2 * self.gap + 2
    }

    /// Column `c + k` (`|k| <= gap < cols`), wrapped (selects, no branches) where `EDGE` (a cell
    /// within `2 gap` columns of the grid's edges); plain `c + k` elsewhere, where it is in range.
    #[inline(always)]
    fn col<const EDGE: bool>(&self, c: usize, k: isize) -> usize {
        let cc = c as isize + k;
        if !EDGE {
            return cc as usize;
        }
        let cols = self.cols as isize;
        let cc = if cc < 0 { cc + cols } else { cc };
        (if cc >= cols { cc - cols } else { cc }) as usize
    }

    /// The first return right (`step` +1) or left (-1) of column `c` in row `row`, within the gap;
    /// `missing` if none.
    #[inline(always)]
    fn along<const EDGE: bool>(&self, row: usize, c: usize, step: isize, missing: usize) -> usize {
        let i = row * self.cols + c;
        let k = if step > 0 { self.right[i] as isize } else { -(self.left[i] as isize) };
        let j = row * self.cols + self.col::<EDGE>(c, k);
        if k == 0 { missing } else { j }
    }

    /// The centre, right and left neighbours of column `c` in row `row` (`missing` where there are
    /// none), if the row has a return near the column.
    #[inline(always)]
    fn side<const EDGE: bool>(&self, row: usize, c: usize, missing: usize) -> Option<[usize; 3]> {
        let k = self.near[row * self.cols + c];
        if k == FAR {
            return None;
        }
        let cc = self.col::<EDGE>(c, k as isize);
        Some([row * self.cols + cc, self.along::<EDGE>(row, cc, 1, missing), self.along::<EDGE>(row, cc, -1, missing)])
    }

    /// [`GridView::neighbours`] of cell `(r, c)` of `view` (the grid the tables were built from),
    /// as cell indices in the order `d1..d8`, `missing` where there is none.
    #[inline(always)]
    pub(crate) fn neighbours_or(&self, view: &GridView<'_>, r: usize, c: usize, missing: usize) -> [usize; 8] {
        if self.narrow() {
            return view.neighbours(r, c).map(|j| j.unwrap_or(missing));
        }
        // A search from a column at least `2 gap` from both edges (the centre neighbour up to `gap`
        // away, the diagonal ones `gap` beyond it) never wraps: no wrap selects there.
        if c >= 2 * self.gap && c + 2 * self.gap < self.cols {
            self.search::<false>(r, c, missing)
        } else {
            self.search::<true>(r, c, missing)
        }
    }

    /// [`RowReturns::neighbours_or`] on a grid wide enough for the tables, wrapping columns where
    /// `EDGE`.
    #[inline(always)]
    fn search<const EDGE: bool>(&self, r: usize, c: usize, missing: usize) -> [usize; 8] {
        let mut out = [missing; 8];
        out[2] = self.along::<EDGE>(r, c, 1, missing);
        out[6] = self.along::<EDGE>(r, c, -1, missing);
        // The nearest row above (below) with a return near the column, skipping empty rows (plain
        // loops: iterator adaptors here were left as calls).
        for up in r + 1..self.rows.min(r + 1 + MAX_ROW_GAP) {
            if let Some([centre, right, left]) = self.side::<EDGE>(up, c, missing) {
                (out[0], out[1], out[7]) = (centre, right, left);
                break;
            }
        }
        let mut dn = r;
        while dn > r.saturating_sub(MAX_ROW_GAP) {
            dn -= 1;
            if let Some([centre, right, left]) = self.side::<EDGE>(dn, c, missing) {
                (out[4], out[3], out[5]) = (centre, right, left);
                break;
            }
        }
        out
    }

    /// [`RowReturns::neighbours_or`] with [`NONE`] for a missing neighbour.
    #[cfg(test)]
    fn neighbours(&self, view: &GridView<'_>, r: usize, c: usize) -> [u32; 8] {
        self.neighbours_or(view, r, c, usize::MAX).map(|j| if j == usize::MAX { NONE } else { j as u32 })
    }
}

/// `right` and `left` of one row (returns `v`) without wrapping, by one shifted pass per column of
/// reach, farthest first so that the nearest return is the one left.
fn shifted(v: &[bool], gap: usize, right: &mut [u8], left: &mut [u8]) {
    let cols = v.len();
    right.fill(0);
    left.fill(0);
    for k in (1..=gap.min(cols.saturating_sub(1))).rev() {
        let kk = k as u8;
        for (r, &x) in right[..cols - k].iter_mut().zip(&v[k..]) {
            *r = if x { kk } else { *r };
        }
        for (l, &x) in left[k..].iter_mut().zip(&v[..cols - k]) {
            *l = if x { kk } else { *l };
        }
    }
}

/// [`shifted`] by one scan in either direction (any gap).
fn scanned(v: &[bool], gap: usize, right: &mut [u8], left: &mut [u8]) {
    let cols = v.len();
    // The nearest return at or after (before) the column being looked at.
    let mut next = usize::MAX;
    for c in (0..cols).rev() {
        right[c] = if next != usize::MAX && next - c <= gap { (next - c) as u8 } else { 0 };
        if v[c] {
            next = c;
        }
    }
    let mut prev = usize::MAX;
    for c in 0..cols {
        left[c] = if prev != usize::MAX && c - prev <= gap { (c - prev) as u8 } else { 0 };
        if v[c] {
            prev = c;
        }
    }
}

/// The searches of the first and last `gap` columns again, wrapping round the row.
fn wrapped_edges(v: &[bool], gap: usize, right: &mut [u8], left: &mut [u8]) {
    let cols = v.len();
    let first = |c: usize, step: isize| -> u8 {
        (1..=gap)
            .find(|&k| v[(c as isize + step * k as isize).rem_euclid(cols as isize) as usize])
            .map_or(0, |k| k as u8)
    };
    for c in (0..gap).chain(cols - gap..cols) {
        right[c] = first(c, 1);
        left[c] = first(c, -1);
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    use super::*;

    /// Every cell of random grids (holes from 0 to 90 %, empty rows, both wraps, gaps 1 to 12 and
    /// 64, narrow grids): the tables find exactly what `GridView::neighbours` finds.
    #[test]
    fn same_neighbours_as_the_grid_search() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let mut tables = RowReturns::default();
        for case in 0..80 {
            let (rows, cols) = (1 + case % 7, 1 + (case * 37) % 150);
            let hole = (case % 10) as f64 * 0.1;
            let mut points = vec![Vec3::NAN; rows * cols];
            let empty_row = rng.random_range(0..rows.max(1));
            for (i, p) in points.iter_mut().enumerate() {
                if i / cols != empty_row && !rng.random_bool(hole) {
                    *p = Vec3::new(i as f32, 1.0, 0.0);
                }
            }
            let ranges = vec![1.0; rows * cols];
            let valid: Vec<bool> = points.iter().map(|p| p.is_finite()).collect();
            for wrap in [false, true] {
                for max_col_gap in (1..=12).chain([64]) {
                    let view = GridView { points: &points, ranges: &ranges, rows, cols, wrap, max_col_gap };
                    tables.build(&view, &valid);
                    for r in 0..rows {
                        for c in 0..cols {
                            let want = view.neighbours(r, c).map(|j| j.map_or(NONE, |j| j as u32));
                            assert_eq!(
                                tables.neighbours(&view, r, c),
                                want,
                                "case {case}, cell ({r}, {c}), gap {max_col_gap}, wrap {wrap}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn tables_of_a_row() {
        // Returns at columns 0, 5, 6 and 9 of a 10-column row, gap 2.
        let mut v = vec![false; 10];
        for c in [0, 5, 6, 9] {
            v[c] = true;
        }
        let (mut right, mut left) = (vec![0; 10], vec![0; 10]);
        shifted(&v, 2, &mut right, &mut left);
        assert_eq!(right, [0, 0, 0, 2, 1, 1, 0, 2, 1, 0]);
        assert_eq!(left, [0, 1, 2, 0, 0, 0, 1, 1, 2, 0]);
        let (mut r2, mut l2) = (vec![0; 10], vec![0; 10]);
        scanned(&v, 2, &mut r2, &mut l2);
        assert_eq!((r2, l2), (right.clone(), left.clone()));
        // Wrapped: column 9 finds column 0 to its right, column 0 finds column 9 to its left.
        wrapped_edges(&v, 2, &mut right, &mut left);
        assert_eq!((right[9], left[0], right[8], left[1]), (1, 1, 1, 1));
    }
}
