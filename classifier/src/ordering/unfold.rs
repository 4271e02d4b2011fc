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

use glam::Vec3;

use super::beam_table::{TableRows, wrap_into};
use super::placement::Wish;
use super::report::OrderingReport;

/// Within a ring, a step of the columns against the scan direction by more than this is a gap
/// going forward the long way round, not a step back.
const MAX_BACK_COLUMNS: f32 = 8.0;

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

/// [`wrap_into`] for `x` within one period of `[0, period)`: one add or subtract, as a select.
#[inline(always)]
fn wrap_once(x: f32, period: f32) -> f32 {
    let x = if x < 0.0 { x + period } else { x };
    if x >= period { x - period } else { x }
}

/// [`round_fast`](super::beam_table::round_fast) of every value, in place (a loop of selects that vectorizes); values are column
/// counts, far inside the `i32` range where this equals `round_fast`.
fn round_all(v: &mut [f32]) {
    for x in v {
        let y = *x + 0.5;
        let t = y as i32 as f32;
        *x = if t > y { t - 1.0 } else { t };
    }
}

fn wrap_pi(a: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    if a > PI {
        a - TAU
    } else if a <= -PI {
        a + TAU
    } else {
        a
    }
}

fn median(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return f32::NAN;
    }
    let m = v.len() / 2;
    *v.select_nth_unstable_by(m, f32::total_cmp).1
}

/// Splits the usable points (file order; `az` their azimuths, `fine` their `tan(elevation)` from
/// their nearest beam's origin) into rings; returns the start of each ring, or why the order does
/// not unfold, with the direction of the turn (+1 counter-clockwise).
pub(crate) fn ring_starts(
    az: &[f32],
    dist: &[f32],
    fine: &[f32],
    rows: &TableRows,
    params: &UnfoldParams,
) -> Result<(Vec<usize>, f32), String> {
    use std::f32::consts::{PI, TAU};
    let n = az.len();
    if n < 2 {
        return Err(format!("{n} usable points"));
    }
    let total: f32 = az.windows(2).map(|w| wrap_pi(w[1] - w[0])).sum();
    let dir = if total >= 0.0 { 1.0 } else { -1.0 };
    let turns = total.abs() / TAU;
    if turns > rows.len() as f32 + 1.0 {
        return Err(format!("the azimuth turns {turns:.0} times, more than the table's {} rows", rows.len()));
    }
    let q: Vec<f32> = az.iter().map(|&a| wrap_into(dir * (a - params.cut_azimuth_rad), TAU)).collect();
    let w = params.cut_window_rad;
    let in_window = |j: usize| q[j] < w || q[j] > TAU - w;
    // Which way the rings go in elevation: compare the first and last 1/8 of the points.
    let m = (n / 8).max(1);
    let mut head: Vec<f32> = fine[..m].to_vec();
    let mut tail: Vec<f32> = fine[n - m..].to_vec();
    let down = median(&mut head) >= median(&mut tail);
    let min_gap = rows.tan_elevation.windows(2).map(|w| w[1] - w[0]).fold(f32::INFINITY, f32::min);
    let drop = |a: usize, b: usize| {
        q[b] < q[a] - params.backward_step_rad - params.parallax_m / dist[a].min(dist[b]).max(1e-3)
    };
    let mut starts = vec![0usize];
    // The file's first points are the first ring's, window or not.
    let mut j = 1;
    while j < n && in_window(j - 1) && in_window(j) {
        j += 1;
    }
    while j < n {
        if in_window(j) {
            // The run a..b of window points; a boundary if progress drops across prev..=b.
            let a = j;
            let mut b = j;
            while b < n && in_window(b) {
                b += 1;
            }
            let hi = b.min(n - 1);
            let has_drop = (a..=hi).any(|k| drop(k - 1, k));
            if has_drop {
                let mut best = (0.1 * min_gap, None);
                for s in a..=hi {
                    let step = if down { fine[s - 1] - fine[s] } else { fine[s] - fine[s - 1] };
                    if step > best.0 {
                        best = (step, Some(s));
                    }
                }
                let s = best.1.or_else(|| (a..=hi).find(|&k| q[k] < PI)).unwrap_or(hi);
                starts.push(s);
            }
            j = b + 1;
            continue;
        }
        if !in_window(j - 1) && drop(j - 1, j) {
            starts.push(j);
        }
        j += 1;
    }
    starts.dedup();
    // A tiny ring (fewer than 1 % of a turn's points) next to a ring at the same elevation is a
    // laser's few points on the wrong side of a boundary: merged.
    let tiny = (rows.cols / 100).max(2);
    let mut k = 0;
    while starts.len() > 1 && k < starts.len() {
        let end = starts.get(k + 1).copied().unwrap_or(n);
        if end - starts[k] < tiny {
            let med = |a: usize, b: usize| median(&mut fine[a..b].to_vec());
            let own = med(starts[k], end);
            let prev = (k > 0).then(|| (med(starts[k - 1], starts[k]) - own).abs());
            let next = starts.get(k + 1).map(|&s1| (med(s1, starts.get(k + 2).copied().unwrap_or(n)) - own).abs());
            match (prev, next) {
                (Some(p), nx) if p < 0.5 * min_gap && nx.is_none_or(|x| p <= x) => {
                    starts.remove(k);
                    continue;
                }
                (_, Some(x)) if x < 0.5 * min_gap => {
                    starts.remove(k + 1);
                    continue;
                }
                _ => {}
            }
        }
        k += 1;
    }
    let max_per_ring = rows.cols + rows.cols / 20 + 1;
    let mut bounds = starts.clone();
    bounds.push(n);
    if let Some(w) = bounds.windows(2).find(|w| w[1] - w[0] > max_per_ring) {
        return Err(format!("a ring would hold {} points, more than a turn's {}", w[1] - w[0], rows.cols));
    }
    if starts.len() > rows.len() {
        return Err(format!("{} rings, more than the table's {} rows", starts.len(), rows.len()));
    }
    if starts.len() < 2 {
        return Err("fewer than 2 rings".into());
    }
    Ok((starts, dir))
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

/// The wish of every point in `valid` by unfolding, or why the order does not unfold.
pub(crate) fn unfold_wishes(
    points: &[Vec3],
    valid: &[u32],
    rows: &TableRows,
    params: &UnfoldParams,
    report: &mut OrderingReport,
) -> Result<Vec<Wish>, String> {
    let (az, dist, mut fine) = super::polar::polar(points, valid);
    if rows.horizontal_m.iter().chain(&rows.vertical_m).any(|&x| x != 0.0) {
        // With origin offsets, the elevation seen from the nearest beam's origin; without them the
        // elevation seen from the sensor origin is exact enough.
        rows.fine_tans(points, valid, &dist, &mut fine);
    }
    let (starts, dir) = ring_starts(&az, &dist, &fine, rows, params)?;
    let mut bounds = starts.clone();
    bounds.push(valid.len());
    let medians: Vec<f32> = bounds.windows(2).map(|w| median(&mut fine[w[0]..w[1]].to_vec())).collect();
    let row_of_ring = match_rows(&medians, rows, params)?;
    report.rings_found = starts.len();
    let mut wishes = Vec::with_capacity(valid.len());
    let (mut steps, mut unwrapped) = (Vec::new(), Vec::new());
    for (ring, w) in bounds.windows(2).enumerate() {
        let row = row_of_ring[ring];
        let (idx, h) = (&valid[w[0]..w[1]], rows.horizontal_m[row]);
        // Fractional column steps of each point's beam azimuth.
        steps.clear();
        steps.extend(az[w[0]..w[1]].iter().zip(&dist[w[0]..w[1]]).map(|(&a, &d)| {
            let beam = if h == 0.0 { a } else { a - (h / d.max(h.abs() * 1.0001)).asin() };
            rows.column_steps(beam)
        }));
        // Columns from azimuth, unwrapped along the ring and kept strictly moving in the scan
        // direction (a counter-clockwise turn goes down the columns): a point whose column is
        // taken by its predecessor takes the next one, the nearest free cell in scan order.
        let cols = rows.cols as f32;
        let col_dir = if rows.full_turn { -dir } else { 0.0 };
        if col_dir == 0.0 {
            wishes.extend(idx.iter().zip(&steps).map(|(&k, &s)| Wish { point: k, row: row as u32, steps: s }));
            continue;
        }
        // Progress in the scan direction, in columns: a ring only moves forward, so a step back of
        // more than `MAX_BACK_COLUMNS` (jitter, parallax) is a gap the long way round. The sum runs
        // in point order; the rounding and the step that keeps columns moving are separate passes
        // written as selects (their branches were mispredicted on every other point).
        unwrapped.clear();
        let mut u = steps[0];
        unwrapped.push(u);
        for pair in steps.windows(2) {
            u += (wrap_once((pair[1] - pair[0]) * col_dir + MAX_BACK_COLUMNS, cols) - MAX_BACK_COLUMNS) * col_dir;
            unwrapped.push(u);
        }
        round_all(&mut unwrapped);
        let mut last = unwrapped[0] - col_dir;
        for (&k, &c) in idx.iter().zip(&unwrapped) {
            let c = if (c - last) * col_dir < 1.0 { last + col_dir } else { c };
            last = c;
            wishes.push(Wish { point: k, row: row as u32, steps: wrap_into(c, cols) });
        }
    }
    Ok(wishes)
}
