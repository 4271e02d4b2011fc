//! Scan unfolding (Triess et al., 2020, "Scan-based semantic segmentation of LiDAR point clouds"):
//! a cloud stored in scan order, laser by laser, each laser one turn of azimuth (a KITTI `.bin`),
//! gives its rings back from the turns of its azimuth.
//!
//! Each point's progress through its laser's turn is its azimuth measured from the cut, the
//! azimuth where the frame was cut and every laser's turn starts (`cut_azimuth_rad`; KITTI and our
//! writer cut at the front, 0), in the direction the file turns (counter-clockwise in KITTI, found
//! from the summed azimuth steps). Within a ring the progress grows; a ring ends where it drops.
//! The jump of the azimuth from +pi to -pi at the back is no drop (progress is continuous there),
//! so the few extra wraps of points jittering about +-pi start no ring. A drop larger than
//! `backward_step_rad` (plus `parallax_m / d` for points at horizontal distance `d`: off-axis beam
//! origins step back on the vehicle's own body) outside the cut window is a boundary (a laser with
//! no returns near the cut);
//! inside the window (`cut_window_rad` either side of the cut, where one laser's last points and
//! the next one's first points mix) a run of points that contains a drop holds one boundary, put at
//! the largest elevation step in the direction the rings go (the elevation seen from the origin of
//! each point's nearest beam), or where the progress restarts when there is no step. A ring may
//! hold no more points than the table's columns (plus 5 %): the expected count per ring.
//!
//! The rings found are matched to the table's rows in order (top-first or bottom-first) by a
//! monotone alignment of their median elevations to the rows' that minimises the differences, so a
//! laser without any return skips its row. Unfolding is refused (and [`super::order_cloud`] falls
//! back to the beam table) where the file is not in scan order: fewer than 2 rings, more rings than
//! rows, a ring with more points than a turn holds, or rings whose medians do not step through the
//! table.
//!
//! Work per point is done in passes the compiler vectorizes: azimuths and elevations
//! ([`super::polar`]), the flags that the ring rules read ([`rings`]), and the columns
//! ([`columns`]); the serial walks visit only flagged points or run one add per point.

mod columns;
mod rings;

use super::beam_table::TableRows;
use super::input_point::InputPoint;
use super::placement::Wish;
use super::report::OrderingReport;
use super::usable::Usable;
use columns::ColumnScratch;
pub(crate) use rings::ring_starts;

/// Parameters of scan unfolding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnfoldParams {
    /// Azimuth at which every laser's turn starts, radians (default 0: the front).
    pub cut_azimuth_rad: f32,
    /// Half-width of the window about the cut in which a ring's boundary is searched, radians of
    /// azimuth (default 4 degrees: per-laser offsets and origin parallax).
    pub cut_window_rad: f32,
    /// A drop of progress larger than this outside the cut window is a ring boundary, radians
    /// (default 2 degrees: origin parallax moves a laser's own points back by less).
    pub backward_step_rad: f32,
    /// Points this close (horizontal distance `d`) may step back by a further `parallax_m / d`
    /// radians inside their own ring (beam origins off the axis, the vehicle's own body close by),
    /// metres (default 0.15).
    pub parallax_m: f32,
    /// Largest elevation error of a ring's median against its matched row, as a multiple of the
    /// table's largest beam gap (default 4).
    pub max_median_error_gaps: f32,
}

impl Default for UnfoldParams {
    fn default() -> Self {
        Self {
            cut_azimuth_rad: 0.0,
            cut_window_rad: 4f32.to_radians(),
            backward_step_rad: 2f32.to_radians(),
            parallax_m: 0.15,
            max_median_error_gaps: 4.0,
        }
    }
}

/// [`super::beam_table::wrap_into`] for `x` within one period of `[0, period)`: one add or
/// subtract, as a select.
#[inline(always)]
fn wrap_once(x: f32, period: f32) -> f32 {
    let x = if x < 0.0 { x + period } else { x };
    if x >= period { x - period } else { x }
}

/// Most values [`sampled_median`] selects from. A ring's points lie on one cone (their elevations
/// spread only where a near point's beam origin differs from the sensor's), so the median of 128
/// evenly spaced ones is the whole ring's to far less than a beam gap, which is all the row match
/// and the direction test need (the same rows and decisions on every test and reference file as
/// with every point, 512 or 128 samples; KITTI frames, ordering, min of 6 x 20 side by side: every
/// point 2.69 ms, 512 samples 2.54 ms, then 128 samples 1.625 -> 1.570 ms).
const MEDIAN_SAMPLES: usize = 128;

/// The median of at most [`MEDIAN_SAMPLES`] evenly spaced values of `v` (every value of a shorter
/// slice), selected in `scratch`.
pub(crate) fn sampled_median(v: &[f32], scratch: &mut Vec<f32>) -> f32 {
    let stride = v.len().div_ceil(MEDIAN_SAMPLES).max(1);
    scratch.clear();
    scratch.extend(v.iter().step_by(stride));
    median(scratch)
}

fn median(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return f32::NAN;
    }
    let m = v.len() / 2;
    *v.select_nth_unstable_by(m, f32::total_cmp).1
}

/// What unfolding found.
pub(crate) enum Unfolded {
    /// A full-turn table: ring `r` holds the usable points `bounds[r] .. bounds[r + 1]` and goes to
    /// row `row_of_ring[r]` (rows differ from ring to ring); every usable point has a whole column
    /// (`column`), and `spans_turn[r]` says whether two points of ring `r` may share one.
    Rings { bounds: Vec<usize>, row_of_ring: Vec<usize>, column: Vec<u32>, spans_turn: Vec<bool> },
    /// A table short of a full turn: each usable point's row and fractional column.
    Wishes(Vec<Wish>),
}

/// Matches rings (in file order) to table rows by their median `tan(elevation)`: a monotone alignment
/// (top-first or bottom-first, whichever fits better) minimising the summed absolute differences.
pub(crate) fn match_rows(medians: &[f32], rows: &TableRows, params: &UnfoldParams) -> Result<Vec<usize>, String> {
    let (k, r) = (medians.len(), rows.len());
    if k > r {
        return Err(format!("{k} rings but the table has {r} rows"));
    }
    let max_gap = rows.tan_elevation.windows(2).map(|w| w[1] - w[0]).fold(0.0f32, f32::max);
    let mut best: Option<(f32, Vec<usize>)> = None;
    for top_first in [true, false] {
        // Table rows in the rings' order.
        let table: Vec<f32> =
            if top_first { rows.tan_elevation.iter().rev().copied().collect() } else { rows.tan_elevation.clone() };
        // cost[i][j]: rings 0..=i matched with ring i at table position j.
        let inf = f32::INFINITY;
        let mut cost = vec![inf; k * r];
        let mut from = vec![usize::MAX; k * r];
        for j in 0..r {
            cost[j] = (medians[0] - table[j]).abs();
        }
        for i in 1..k {
            let mut run = (inf, usize::MAX);
            for j in i..r {
                let c = cost[(i - 1) * r + j - 1];
                if c < run.0 {
                    run = (c, j - 1);
                }
                if run.0.is_finite() {
                    cost[i * r + j] = run.0 + (medians[i] - table[j]).abs();
                    from[i * r + j] = run.1;
                }
            }
        }
        let (mut j, total) =
            (0..r).map(|j| (j, cost[(k - 1) * r + j])).min_by(|a, b| a.1.total_cmp(&b.1)).unwrap_or((0, inf));
        if !total.is_finite() {
            continue;
        }
        let mut path = vec![0usize; k];
        for i in (0..k).rev() {
            path[i] = if top_first { r - 1 - j } else { j };
            if i > 0 {
                j = from[i * r + j];
            }
        }
        let worst =
            medians.iter().zip(&path).map(|(m, &row)| (m - rows.tan_elevation[row]).abs()).fold(0.0f32, f32::max);
        if worst > params.max_median_error_gaps * max_gap {
            continue;
        }
        if best.as_ref().is_none_or(|b| total < b.0) {
            best = Some((total, path));
        }
    }
    best.map(|b| b.1).ok_or_else(|| "the rings' median elevations do not step through the beam table".to_string())
}

/// Unfolds the usable points (`usable`, of `points`, whose [`super::polar::polar`] values are
/// `polar`): their rings, rows and columns, or why the order does not unfold.
pub(crate) fn unfold<P: InputPoint>(
    points: &[P],
    usable: &Usable,
    polar: super::polar::Polar,
    rows: &TableRows,
    params: &UnfoldParams,
    report: &mut OrderingReport,
) -> Result<Unfolded, String> {
    let (az, dist, mut fine) = polar;
    if rows.horizontal_m.iter().chain(&rows.vertical_m).any(|&x| x != 0.0) {
        // With origin offsets, the elevation seen from the nearest beam's origin; without them the
        // elevation seen from the sensor origin is exact enough.
        rows.fine_tans(points, usable.indices(), &dist, &mut fine);
    }
    let (mut bounds, dir) = ring_starts(&az, &dist, &fine, rows, params)?;
    bounds.push(usable.len());
    let mut scratch = Vec::with_capacity(MEDIAN_SAMPLES);
    let medians: Vec<f32> = bounds.windows(2).map(|w| sampled_median(&fine[w[0]..w[1]], &mut scratch)).collect();
    let row_of_ring = match_rows(&medians, rows, params)?;
    report.rings_found = bounds.len() - 1;
    if !rows.full_turn {
        let mut wishes = Vec::with_capacity(usable.len());
        let mut steps = Vec::new();
        for (w, &row) in bounds.windows(2).zip(&row_of_ring) {
            columns::column_steps(rows, row, &az[w[0]..w[1]], &dist[w[0]..w[1]], &mut steps);
            wishes.extend(steps.iter().map(|&s| Wish { row: row as u32, steps: s }));
        }
        return Ok(Unfolded::Wishes(wishes));
    }
    // Grown ring by ring, each ring's part zeroed just before it is written (in the level-1
    // cache), rather than the whole of it zeroed first.
    let mut column = Vec::with_capacity(usable.len());
    let mut scratch = ColumnScratch::default();
    let spans_turn = bounds
        .windows(2)
        .zip(&row_of_ring)
        .map(|(w, &row)| {
            let (az, dist) = (&az[w[0]..w[1]], &dist[w[0]..w[1]]);
            column.resize(w[1], 0);
            columns::ring_columns(rows, row, az, dist, dir, &mut scratch, &mut column[w[0]..w[1]])
        })
        .collect();
    Ok(Unfolded::Rings { bounds, row_of_ring, column, spans_turn })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ring of 2,000 `tan(elevation)` values about 0.1 whose first 600 points (near points at the
    /// start of the turn) lie 0.05 above: the sampled median is the whole ring's to within 1e-4, far
    /// less than the HDL-64E's smallest beam gap (0.0058), and exact for a short slice.
    #[test]
    fn sampled_median_is_the_rings_median() {
        let ring: Vec<f32> =
            (0..2_000).map(|i| if i < 600 { 0.15 } else { 0.1 + ((i * 37) % 101) as f32 * 1e-6 - 5e-5 }).collect();
        let mut scratch = Vec::new();
        let exact = median(&mut ring.clone());
        let sampled = sampled_median(&ring, &mut scratch);
        assert!(scratch.len() <= MEDIAN_SAMPLES && scratch.len() >= MEDIAN_SAMPLES / 2);
        assert!((sampled - exact).abs() < 1e-4, "sampled {sampled}, exact {exact}");
        assert!((sampled - 0.1).abs() < 1e-4);
        let short = &ring[500..500 + MEDIAN_SAMPLES];
        assert_eq!(sampled_median(short, &mut scratch), median(&mut short.to_vec()));
    }
}
