//! The general neighbour search of cells that lack a direct neighbour (features and clustering),
//! on a bitmask of the plane's returns: [`GridView::neighbours`] looks each candidate up in the points (a branch and three
//! float tests per cell, through calls that do not inline); here a row's returns around the column
//! are one machine word, so finding the nearest return is a few bit operations. The result is the
//! same as [`GridView::neighbours`] for every cell (tested on random masks); cells near the left
//! and right edges, where the search may wrap, and searches wider than [`MAX_FAST_GAP`] columns go
//! to [`GridView::neighbours`] itself.

use crate::nitsch::neighbours::{GridView, MAX_ROW_GAP};

/// Widest column search the bitmask path takes (the default is 2).
const MAX_FAST_GAP: usize = 4;

/// Columns either side of the cell that one window holds: the nearest return up to
/// `MAX_FAST_GAP` away, then the next one up to `MAX_FAST_GAP` beyond it.
const REACH: usize = 2 * MAX_FAST_GAP;

/// One bit per cell of a plane, row by row (`words` 64-bit words a row), set where the cell holds a
/// return. Buffers are reused between frames.
#[derive(Clone, Debug, Default)]
pub(crate) struct ReturnBits {
    bits: Vec<u64>,
    words: usize,
}

impl ReturnBits {
    /// Packs `valid` (row-major, `rows * cols`).
    pub(crate) fn pack(&mut self, valid: &[bool], rows: usize, cols: usize) {
        // One spare word a row, so a window never reads past the row's last word.
        self.words = cols.div_ceil(64) + 1;
        self.bits.clear();
        self.bits.resize(rows * self.words, 0);
        for (row_bits, row) in self.bits.chunks_exact_mut(self.words).zip(valid.chunks_exact(cols.max(1))) {
            for (w, chunk) in row_bits.iter_mut().zip(row.chunks(64)) {
                *w = chunk.iter().enumerate().fold(0u64, |acc, (i, &v)| acc | (u64::from(v) << i));
            }
        }
    }

    /// Bits of row `r`, columns `c0 .. c0 + 2 * REACH + 1` (bit `i` = column `c0 + i`).
    #[inline(always)]
    fn window(&self, r: usize, c0: usize) -> u64 {
        let base = r * self.words + c0 / 64;
        let shift = c0 % 64;
        let lo = self.bits[base] >> shift;
        let hi = if shift == 0 { 0 } else { self.bits[base + 1] << (64 - shift) };
        (lo | hi) & ((1u64 << (2 * REACH + 1)) - 1)
    }
}

/// In window `w` (bit `REACH` = the cell's column): the first return `1 ..= gap` bits from bit `p`
/// in direction `step`.
#[inline(always)]
fn first_along(w: u64, p: usize, step: isize, gap: usize) -> Option<usize> {
    let mask = (1u64 << gap) - 1;
    if step > 0 {
        let m = (w >> (p + 1)) & mask;
        (m != 0).then(|| p + 1 + m.trailing_zeros() as usize)
    } else {
        // Bits p - gap ..= p - 1, the nearest (highest) first.
        let m = (w << gap >> p) & mask;
        (m != 0).then(|| p - gap + 63 - m.leading_zeros() as usize)
    }
}

/// In window `w`: the return nearest to bit `REACH` (itself, then `+1`, `-1`, `+2`, ...), within
/// `gap`. Bit counts rather than a loop of tests: the distances to the nearest return at or above
/// and at or below the bit, the `+` side on a tie.
#[inline(always)]
fn nearest(w: u64, gap: usize) -> Option<usize> {
    // 64 where there is none on that side.
    let up = (w >> REACH).trailing_zeros() as usize;
    let down = (w << (63 - REACH)).leading_zeros() as usize;
    let (d, bit) = if up <= down { (up, REACH + up) } else { (down, REACH.wrapping_sub(down)) };
    (d <= gap).then_some(bit)
}

/// [`GridView::neighbours`] of `(r, c)` through `bits` (the view's returns).
#[inline]
pub(crate) fn neighbours(view: &GridView<'_>, bits: &ReturnBits, r: usize, c: usize) -> [Option<usize>; 8] {
    let (rows, cols, gap) = (view.rows, view.cols, view.max_col_gap);
    if gap > MAX_FAST_GAP || c < REACH || c + REACH >= cols {
        return view.neighbours(r, c);
    }
    let c0 = c - REACH;
    let cell = |row: usize, bit: usize| row * cols + c0 + bit;
    let mut out = [None; 8];
    let own = bits.window(r, c0);
    out[2] = first_along(own, REACH, 1, gap).map(|b| cell(r, b));
    out[6] = first_along(own, REACH, -1, gap).map(|b| cell(r, b));
    // The nearest row above (below) with a return near the column, skipping empty rows.
    let side = |row: usize, out: &mut [Option<usize>; 8], [centre, right, left]: [usize; 3]| -> bool {
        let w = bits.window(row, c0);
        let Some(b) = nearest(w, gap) else { return false };
        out[centre] = Some(cell(row, b));
        out[right] = first_along(w, b, 1, gap).map(|x| cell(row, x));
        out[left] = first_along(w, b, -1, gap).map(|x| cell(row, x));
        true
    };
    for up in r + 1..rows.min(r + 1 + MAX_ROW_GAP) {
        if side(up, &mut out, [0, 1, 7]) {
            break;
        }
    }
    for dn in (r.saturating_sub(MAX_ROW_GAP)..r).rev() {
        if side(dn, &mut out, [4, 3, 5]) {
            break;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    use super::*;

    /// Every cell of random grids (holes from 0 to 90 %, empty rows, both wraps, gaps 1 to 5):
    /// the bitmask search finds exactly what `GridView::neighbours` finds.
    #[test]
    fn same_neighbours_as_the_grid_search() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        for case in 0..60 {
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
            let mut bits = ReturnBits::default();
            bits.pack(&valid, rows, cols);
            for wrap in [false, true] {
                for max_col_gap in 1..=5 {
                    let view = GridView { points: &points, ranges: &ranges, rows, cols, wrap, max_col_gap };
                    for r in 0..rows {
                        for c in 0..cols {
                            assert_eq!(
                                neighbours(&view, &bits, r, c),
                                view.neighbours(r, c),
                                "case {case}, cell ({r}, {c}), gap {max_col_gap}, wrap {wrap}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn bits_in_a_window() {
        // Returns at columns 0, 5, 70 and 129 of a 130-column row.
        let mut valid = vec![false; 130];
        for c in [0, 5, 70, 129] {
            valid[c] = true;
        }
        let mut bits = ReturnBits::default();
        bits.pack(&valid, 1, 130);
        assert_eq!(bits.window(0, 0), 1 | 1 << 5);
        assert_eq!(bits.window(0, 62), 1 << 8);
        assert_eq!(bits.window(0, 120), 1 << 9);
        assert_eq!(first_along(1 << 3 | 1 << 12, 8, 1, 4), Some(12));
        assert_eq!(first_along(1 << 3 | 1 << 13, 8, 1, 4), None);
        assert_eq!(first_along(1 << 5 | 1 << 4, 8, -1, 4), Some(5));
        assert_eq!(first_along(1 << 3, 8, -1, 4), None);
        assert_eq!(nearest(1 << 7 | 1 << 9, 2), Some(9));
        assert_eq!(nearest(1 << 6, 2), Some(6));
        assert_eq!(nearest(1 << 5, 2), None);
    }
}
