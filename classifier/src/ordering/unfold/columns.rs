//! Columns of an unfolded ring: each point's beam azimuth in column steps, unwrapped along the ring
//! and kept strictly moving in the scan direction (a counter-clockwise turn goes down the columns):
//! a point whose column is taken by its predecessor takes the next one, the nearest free cell in
//! scan order. A step back of more than [`MAX_BACK_COLUMNS`] (jitter, parallax) is a gap going
//! forward the long way round.
//!
//! The steps and their unwrapping increments are vectorized passes; the running sum, its rounding
//! and the step that keeps columns moving are one serial pass, the latter on integers (columns are whole
//! numbers there, so the float comparisons of the rule are exact integer ones). A ring whose
//! unwrapped columns could leave the range where that holds (beyond `2^23`: only for absurd input)
//! takes the float rule instead ([`columns_by_float_rule`]), which gives the same columns wherever
//! both apply (tested).

use super::super::beam_table::{TableRows, round_fast, wrap_into};
use super::wrap_once;

/// Within a ring, a step of the columns against the scan direction by more than this is a gap
/// going forward the long way round, not a step back.
pub(crate) const MAX_BACK_COLUMNS: f32 = 8.0;

/// Largest unwrapped column (absolute) for the integer rule: well inside the integers that `f32`
/// holds exactly, with room for a ring's worth of steps.
const EXACT_COLUMNS: f32 = (1u32 << 23) as f32;

/// [`wrap_into`] of every value, in place: one add or subtract (a select that vectorizes) where
/// every value lies within a turn of `[0, period)`, else [`wrap_into`] itself.
#[inline(always)]
fn wrap_all(v: &mut [f32], period: f32) {
    let (lo, hi) = (-period, 2.0 * period);
    let outside = v.iter().fold(0u32, |n, &x| n + u32::from((x < lo) | (x >= hi)));
    if outside == 0 {
        v.iter_mut().for_each(|x| *x = wrap_once(*x, period));
    } else {
        v.iter_mut().for_each(|x| *x = wrap_into(*x, period));
    }
}

/// [`round_fast`] of every value, in place (selects that vectorize); values are column counts,
/// far inside the `i32` range where this equals `round_fast`.
#[inline(always)]
fn round_all(v: &mut [f32]) {
    for x in v {
        let y = *x + 0.5;
        let t = y as i32 as f32;
        *x = if t > y { t - 1.0 } else { t };
    }
}

/// Fractional column steps of the beam azimuths of points with azimuths `az` and horizontal
/// distances `dist` in row `row` ([`TableRows::column_steps`] of [`TableRows::beam_azimuth`]),
/// into `steps`.
#[inline(always)]
pub(crate) fn column_steps(rows: &TableRows, row: usize, az: &[f32], dist: &[f32], steps: &mut Vec<f32>) {
    let (h, offset) = (rows.horizontal_m[row], rows.column_offset[row]);
    let (left, step) = (rows.azimuth_left_rad, rows.azimuth_step_rad);
    steps.clear();
    if h == 0.0 {
        steps.extend(az.iter().map(|&a| (left - a) / step - offset));
    } else {
        // The operations of `column_steps(a - asin(h / d))` in passes: the ratios and the steps
        // vectorize, only libm's `asin` is a call per point (one pass of calls took 0.8 ms of a
        // KITTI frame ordered with origin offsets).
        steps.extend(dist.iter().map(|&d| h / d.max(h.abs() * 1.0001)));
        steps.iter_mut().for_each(|x| *x = x.asin());
        for (s, &a) in steps.iter_mut().zip(az) {
            *s = (left - (a - *s)) / step - offset;
        }
    }
    if rows.full_turn {
        wrap_all(steps, std::f32::consts::TAU / step);
    }
}

/// Reusable buffers of [`ring_columns`].
#[derive(Default)]
pub(crate) struct ColumnScratch {
    steps: Vec<f32>,
    unwrapped: Vec<f32>,
    moved: Vec<i32>,
}

crate::cpu::dispatch_by_isa! {
    /// The whole columns (in `[0, cols)`) of one ring's points in a full-turn grid, from their
    /// azimuths and distances, into `out`; the scan goes down the columns when `dir` (the turn's
    /// direction) is +1. Returns whether the ring's columns span a full turn, so that two of its
    /// points may share a column.
    pub(crate) fn ring_columns(
        rows: &TableRows,
        row: usize,
        az: &[f32],
        dist: &[f32],
        dir: f32,
        scratch: &mut ColumnScratch,
        out: &mut [u32],
    ) -> bool;
    body: ring_columns_body, avx2: "avx2" if std::arch::is_x86_feature_detected!("avx2")
}

/// The body of [`ring_columns`], inlined into each instruction-set variant.
#[inline(always)]
fn ring_columns_body(
    rows: &TableRows,
    row: usize,
    az: &[f32],
    dist: &[f32],
    dir: f32,
    scratch: &mut ColumnScratch,
    out: &mut [u32],
) -> bool {
    let ColumnScratch { steps, unwrapped, .. } = scratch;
    column_steps(rows, row, az, dist, steps);
    let (cols, col_dir) = (rows.cols as f32, -dir);
    // Progress in the scan direction, in columns: the increments as one pass, the sum in point
    // order.
    unwrapped.clear();
    unwrapped.push(steps[0]);
    unwrapped.extend(
        steps.windows(2).map(|pair| {
            (wrap_once((pair[1] - pair[0]) * col_dir + MAX_BACK_COLUMNS, cols) - MAX_BACK_COLUMNS) * col_dir
        }),
    );
    // The running sum, the rounding and the rule `c' = c` unless `(c - last) * col_dir < 1`, then
    // `last + col_dir`, in one serial pass: on whole numbers the rule is a running maximum (scan
    // going up the columns) or minimum, a chain of its own beside the sum's (the two overlap).
    // Columns beyond the integers that `f32` holds exactly (NaN included) take the float rule.
    let cols_i = rows.cols as i32;
    let first = round_i32(unwrapped[0]);
    let moved = &mut scratch.moved;
    moved.clear();
    let exact = if col_dir > 0.0 {
        unwrap_and_move::<true>(unwrapped, first - 1, moved)
    } else {
        unwrap_and_move::<false>(unwrapped, first + 1, moved)
    };
    if !exact {
        round_all(unwrapped);
        return columns_by_float_rule(unwrapped, rows.cols, col_dir, out);
    }
    let last = *moved.last().expect("a ring has points");
    // The wrap into `[0, cols)` is a second pass that vectorizes: a whole number of turns off the
    // first column, then a turn either way at most (a remainder for the rare ring that strays further).
    let base = first - first.rem_euclid(cols_i);
    let mut strays = 0u32;
    for (o, &c) in out.iter_mut().zip(moved.iter()) {
        let w = c - base;
        let w = if w >= cols_i { w - cols_i } else { w };
        let w = if w < 0 { w + cols_i } else { w };
        strays += u32::from(!(0..cols_i).contains(&w));
        *o = w as u32;
    }
    if strays > 0 {
        for (o, &c) in out.iter_mut().zip(moved.iter()) {
            *o = c.rem_euclid(cols_i) as u32;
        }
    }
    (last - first).abs() >= cols_i
}

/// [`round_fast`] of `x` as a whole number (`x` well inside the `i32` range; others give some
/// number, for columns that [`unwrap_and_move`] reports as not exact).
#[inline(always)]
fn round_i32(x: f32) -> i32 {
    let y = x + 0.5;
    let t = y as i32;
    if t as f32 > y { t - 1 } else { t }
}

/// Replaces the increments `unwrapped[1..]` by the running sum from `unwrapped[0]`, and appends to
/// `moved` each rounded sum moved to at least one column past the last (`UP`) or at most one
/// column before it, starting from `last`. Returns whether every sum lies within
/// [`EXACT_COLUMNS`] (else `moved` is meaningless).
#[inline(always)]
fn unwrap_and_move<const UP: bool>(unwrapped: &mut [f32], mut last: i32, moved: &mut Vec<i32>) -> bool {
    let mut u = unwrapped[0];
    let mut exact = u.abs() < EXACT_COLUMNS;
    let mut step = |u: f32| {
        let c = round_i32(u);
        last = if UP { c.max(last + 1) } else { c.min(last - 1) };
        last
    };
    moved.push(step(u));
    for x in &mut unwrapped[1..] {
        u += *x;
        *x = u;
        exact &= u.abs() < EXACT_COLUMNS;
        moved.push(step(u));
    }
    exact
}

/// The moving rule in floats as first written (for unwrapped columns beyond [`EXACT_COLUMNS`]).
fn columns_by_float_rule(unwrapped: &[f32], cols: usize, col_dir: f32, out: &mut [u32]) -> bool {
    let mut last = unwrapped[0] - col_dir;
    for (o, &c) in out.iter_mut().zip(unwrapped) {
        let c = if (c - last) * col_dir < 1.0 { last + col_dir } else { c };
        last = c;
        // A whole number in [0, cols) (the wrap of a whole number of columns is one).
        *o = round_fast(wrap_into(c, cols as f32)) as u32;
    }
    // Not known to stay clear of its own start: placed with the check of every cell.
    true
}

#[cfg(test)]
mod tests {
    use super::super::super::beam_table::BeamTable;
    use super::*;

    /// The rule as first written, per point, for comparison.
    fn reference(rows: &TableRows, az: &[f32], dir: f32) -> Vec<u32> {
        let (cols, col_dir) = (rows.cols as f32, -dir);
        let steps: Vec<f32> = az.iter().map(|&a| rows.column_steps(a, 0)).collect();
        let mut u = steps[0];
        let mut unwrapped = vec![u];
        for pair in steps.windows(2) {
            u += (wrap_once((pair[1] - pair[0]) * col_dir + MAX_BACK_COLUMNS, cols) - MAX_BACK_COLUMNS) * col_dir;
            unwrapped.push(u);
        }
        let mut out = vec![0; az.len()];
        round_all(&mut unwrapped);
        columns_by_float_rule(&unwrapped, rows.cols, col_dir, &mut out);
        out
    }

    #[test]
    fn columns_equal_the_float_rule() {
        let rows = BeamTable::hdl64e(2170).rows().unwrap();
        let mut scratch = ColumnScratch::default();
        for (case, dir) in [(0usize, 1.0f32), (1, -1.0), (2, 1.0), (3, -1.0)] {
            // A ring with jitter, repeated azimuths, half steps and a step back, and (cases 2, 3)
            // more than a full turn.
            let n = if case < 2 { 2_000 } else { 2_300 };
            let az: Vec<f32> = (0..n)
                .map(|i| {
                    let a =
                        dir * (i as f32 * 0.002_95 + ((i * 7) % 5) as f32 * 4e-4 - if i == 700 { 0.02 } else { 0.0 });
                    (a + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI
                })
                .collect();
            let dist = vec![10.0; n];
            let mut out = vec![0u32; n];
            let spans = ring_columns(&rows, 0, &az, &dist, dir, &mut scratch, &mut out);
            assert_eq!(out, reference(&rows, &az, dir), "case {case}");
            assert_eq!(spans, case >= 2, "case {case}");
            assert!(out.iter().all(|&c| (c as usize) < rows.cols));
        }
    }

    /// The one serial pass: the running sum in place, each sum rounded and moved one column past
    /// the last at least (or before it, scanning down), and whether every sum is an exact integer
    /// range (else the caller takes the float rule).
    #[test]
    fn unwrap_and_move_sums_rounds_and_moves() {
        let increments = [10.2f32, 0.4, 0.4, -0.3, 2.0];
        let mut sums = vec![increments[0]];
        for x in &increments[1..] {
            sums.push(sums.last().unwrap() + x);
        }
        for (up, start, want) in [(true, 9, [10, 11, 12, 13, 14]), (false, 11, [10, 9, 8, 7, 6])] {
            let (mut v, mut moved) = (increments.to_vec(), Vec::new());
            let exact = if up {
                unwrap_and_move::<true>(&mut v, start, &mut moved)
            } else {
                unwrap_and_move::<false>(&mut v, start, &mut moved)
            };
            assert!(exact);
            assert_eq!(v, sums);
            assert_eq!(moved, want);
        }
        // 1e6 + 8e6 columns lie past 2^23: not exact.
        let (mut v, mut moved) = (vec![1e6f32, 8e6], Vec::new());
        assert!(!unwrap_and_move::<true>(&mut v, 0, &mut moved));
        assert_eq!(v, [1e6, 9e6]);
    }

    /// The batch steps are bit for bit `column_steps(beam_azimuth(p, row), row)` per point, with and
    /// without a horizontal origin offset and a column offset, over a full turn and short of one.
    #[test]
    fn batch_steps_equal_the_per_point_definition() {
        for full_turn in [true, false] {
            let mut table = BeamTable::hdl64e(2083);
            let n = table.elevations_rad.len();
            table.horizontal_offsets_m = (0..n).map(|i| 0.026 * ((i % 5) as f32 - 2.0)).collect();
            table.column_offsets = (0..n).map(|i| 0.25 * ((i % 3) as f32 - 1.0)).collect();
            let mut rows = table.rows().unwrap();
            rows.full_turn = full_turn;
            let points: Vec<glam::Vec3> = (0..5_000)
                .map(|i| {
                    let (a, r) = (i as f32 * 0.0131 - 3.2, 0.01 + (i % 613) as f32 * 0.13);
                    glam::Vec3::new(r * a.cos(), r * a.sin(), -1.0)
                })
                .collect();
            let (az, dist, _) = super::super::super::polar::polar(&points, None);
            let mut steps = Vec::new();
            for row in [0, 1, 2, 3, 4] {
                column_steps(&rows, row, &az, &dist, &mut steps);
                for (k, (s, p)) in steps.iter().zip(&points).enumerate() {
                    let want = rows.column_steps(rows.beam_azimuth(*p, row), row);
                    assert_eq!(s.to_bits(), want.to_bits(), "row {row} point {k} full turn {full_turn}");
                }
            }
        }
    }
}
