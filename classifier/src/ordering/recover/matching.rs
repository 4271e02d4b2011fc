//! Naming the sensor: the elevation table the data shows against every known table
//! ([`super::known`]).
//!
//! - **From rings** (scan order): each ring's median `tan(elevation)` seen from the sensor origin
//!   and its median horizontal distance `d`; a known row `j` (elevation `t_j`, beam origin `v_j`
//!   above the sensor origin) is seen at `t_j + v_j / d` from there. The rings, sorted by
//!   elevation, are aligned to the rows by a monotone alignment that may skip rows (a laser
//!   without returns) and minimises the summed error; a table matches where its rows are at most a
//!   quarter more than the rings, the mean error is within [`MATCH_MEAN_DEG`] and the largest
//!   within [`MATCH_MAX_DEG`]. The closest table (mean error plus [`MISSING_ROW_DEG`] per skipped
//!   row) names the sensor.
//! - **From points** (firing order, where rings are not runs of the file): each sampled point's
//!   nearest row of a known table (or a neighbour) with the beam origin offsets undone; a
//!   table fits where at least [`FIT_FRACTION`] of the points lie within a fifth of the local beam
//!   gap of their row and at least three quarters of its rows hold points. The best fit names the
//!   sensor, the table with fewer rows where two fit alike.

use super::known::{KnownSensor, known_sensors};
use crate::ordering::InputPoint;
use crate::ordering::beam_table::TableRows;

/// Largest mean error of the rings' elevations against a matched table, degrees (real units
/// differ from their nominal tables by a few tenths of a degree).
pub const MATCH_MEAN_DEG: f32 = 0.3;

/// Largest error of one ring against its matched row, degrees.
pub const MATCH_MAX_DEG: f32 = 1.5;

/// What a skipped row adds to a table's score, degrees.
const MISSING_ROW_DEG: f32 = 0.01;

/// Fraction of sampled points that must lie within a fifth of their row's beam gap for a table to
/// fit a cloud in firing order.
pub const FIT_FRACTION: f64 = 0.9;

/// A known sensor matched to the data.
#[derive(Clone, Copy)]
pub(crate) struct Matched {
    /// The sensor.
    pub sensor: &'static KnownSensor,
    /// Mean error of the data's rings against its rows, degrees (from points: the mean residual).
    pub mean_error_deg: f32,
}

/// The difference of two `tan(elevation)` values near `t`, degrees.
fn tan_diff_deg(a: f32, b: f32, t: f32) -> f32 {
    ((a - b).abs() / (1.0 + t * t)).to_degrees()
}

/// The monotone alignment of rings to a table's rows with the least summed error
/// ([`align`]): each ring's row and the fit's figures.
pub(crate) struct Alignment {
    /// Per ring (in the order given: sorted up), its row of the table.
    pub rows: Vec<usize>,
    /// Summed error of the rings against their rows, degrees.
    pub sum_deg: f32,
    /// Largest error of one ring against its row, degrees.
    pub worst_deg: f32,
}

/// The monotone alignment of `medians` (`tan(elevation)` seen from the sensor origin, sorted up,
/// with each ring's median distance `dist_m`) to `rows` that may skip rows (a laser without
/// returns) and minimises the summed error; `None` where there are more rings than rows.
pub(crate) fn align(medians: &[f32], dist_m: &[f32], rows: &TableRows) -> Option<Alignment> {
    let (k, r) = (medians.len(), rows.len());
    if k == 0 || k > r {
        return None;
    }
    let err = |i: usize, j: usize| {
        let seen = rows.tan_elevation[j] + rows.vertical_m[j] / dist_m[i].max(0.5);
        tan_diff_deg(medians[i], seen, medians[i])
    };
    // cost[i * r + j]: rings 0..=i aligned, ring i to row j; `worst` the largest error on that
    // path; `from` ring i - 1's row on it.
    let inf = f32::INFINITY;
    let mut cost = vec![inf; k * r];
    let mut worst = vec![inf; k * r];
    let mut from = vec![0usize; k * r];
    for j in 0..=(r - k) {
        cost[j] = err(0, j);
        worst[j] = cost[j];
    }
    for i in 1..k {
        let mut run = (inf, inf, 0usize);
        for j in i..=(r - k + i) {
            let prev = (cost[(i - 1) * r + j - 1], worst[(i - 1) * r + j - 1]);
            if prev.0 < run.0 {
                run = (prev.0, prev.1, j - 1);
            }
            let e = err(i, j);
            cost[i * r + j] = run.0 + e;
            worst[i * r + j] = run.1.max(e);
            from[i * r + j] = run.2;
        }
    }
    let mut j = (k - 1..r).min_by(|&a, &b| cost[(k - 1) * r + a].total_cmp(&cost[(k - 1) * r + b]))?;
    let (sum_deg, worst_deg) = (cost[(k - 1) * r + j], worst[(k - 1) * r + j]);
    let mut out = vec![0usize; k];
    for i in (0..k).rev() {
        out[i] = j;
        if i > 0 {
            j = from[i * r + j];
        }
    }
    Some(Alignment { rows: out, sum_deg, worst_deg })
}

/// The known sensor whose table the rings' `medians` (`tan(elevation)` seen from the origin,
/// sorted up) at median distances `dist_m` match best, if any matches.
pub(crate) fn match_rings(medians: &[f32], dist_m: &[f32]) -> Option<Matched> {
    let k = medians.len();
    let mut best: Option<(f32, Matched)> = None;
    for sensor in known_sensors() {
        let r = sensor.rows.len();
        if k > r || 4 * (r - k) > r {
            continue;
        }
        let Some(fit) = align(medians, dist_m, &sensor.rows) else { continue };
        let mean = fit.sum_deg / k as f32;
        if mean > MATCH_MEAN_DEG || fit.worst_deg > MATCH_MAX_DEG {
            continue;
        }
        let score = mean + MISSING_ROW_DEG * (r - k) as f32;
        if best.as_ref().is_none_or(|b| score < b.0) {
            best = Some((score, Matched { sensor, mean_error_deg: mean }));
        }
    }
    best.map(|b| b.1)
}

/// How well `sensor`'s table fits the sampled points: the fraction within a fifth of their row's
/// beam gap (the nearest row or a neighbour, each seen from its beam origin: up, across and along
/// the beam), the fraction of rows that hold points, and the mean residual in degrees.
/// `None` as soon as the fraction within cannot reach [`FIT_FRACTION`] any more (the sensor is
/// not matched then, whatever the rest of the sample gives).
fn fit<P: InputPoint>(points: &[P], sample: &[u32], sensor: &KnownSensor) -> Option<(f64, f64, f32)> {
    fit_until(points, sample, &sensor.rows, FIT_FRACTION)
}

/// [`fit`] of the table `rows` (its beam origins included), over the whole sample.
pub(crate) fn fit_rows<P: InputPoint>(points: &[P], sample: &[u32], rows: &TableRows) -> (f64, f64, f32) {
    fit_until(points, sample, rows, 0.0).unwrap_or((0.0, 0.0, f32::NAN))
}

/// [`fit_rows`], stopped (`None`) once the fraction within is sure to stay under `floor`.
fn fit_until<P: InputPoint>(points: &[P], sample: &[u32], rows: &TableRows, floor: f64) -> Option<(f64, f64, f32)> {
    let (n, tan) = (rows.len(), &rows.tan_elevation);
    let mut held = vec![false; n];
    let (mut within, mut sum_deg) = (0usize, 0f64);
    let m = sample.len().max(1) as f64;
    // Misses beyond this leave fewer than `floor * m` within.
    let allowed = m - floor * m;
    for (i, &k) in sample.iter().enumerate() {
        let (best_row, best, outside) = row_of(rows, Some(&rows.along_m), points[k as usize].xyz());
        held[best_row] = true;
        within += usize::from(!outside && best < 0.2);
        sum_deg += f64::from((best * rows.row_gap[best_row] / (1.0 + tan[best_row] * tan[best_row])).to_degrees());
        if (i + 1 - within) as f64 > allowed {
            return None;
        }
    }
    Some((within as f64 / m, held.iter().filter(|&&h| h).count() as f64 / n as f64, (sum_deg / m) as f32))
}

/// The row of `p` (sensor frame) in `rows`: of the nearest row ([`TableRows::nearest_row`]) and
/// its neighbours, the one whose beam, seen from its origin (up, across and, with `along_m`, out
/// along the beam), passes closest; with its residual as a fraction of the row's gap, and whether
/// `p` lies beyond the table's edge rows.
pub(crate) fn row_of(rows: &TableRows, along_m: Option<&[f32]>, p: glam::Vec3) -> (usize, f32, bool) {
    let (n, tan) = (rows.len(), &rows.tan_elevation);
    let (row, f, outside) = rows.nearest_row(p);
    let mut best = ((f - tan[row]).abs() / rows.row_gap[row], row);
    if let Some(along) = along_m {
        let d = (p.x * p.x + p.y * p.y).sqrt();
        for r in row.saturating_sub(1)..=(row + 1).min(n - 1) {
            let t = (p.z - rows.vertical_m[r]) / (d - along[r]).max(1e-3);
            let e = (t - tan[r]).abs() / rows.row_gap[r];
            if e < best.0 {
                best = (e, r);
            }
        }
    }
    (best.1, best.0, outside)
}

/// The known sensor whose table fits the points `sample` (indices into `points`) best, if any fits.
pub(crate) fn match_points<P: InputPoint>(points: &[P], sample: &[u32]) -> Option<Matched> {
    let mut best: Option<(f64, usize, Matched)> = None;
    for sensor in known_sensors() {
        let Some((within, held, mean)) = fit(points, sample, sensor) else { continue };
        if within < FIT_FRACTION || held < 0.75 {
            continue;
        }
        let rows = sensor.rows.len();
        let better = best.as_ref().is_none_or(|b| within > b.0 + 0.01 || (within > b.0 - 0.01 && rows < b.1));
        if better {
            best = Some((within, rows, Matched { sensor, mean_error_deg: mean }));
        }
    }
    best.map(|b| b.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The alignment traces back each ring's row: a table's rows without its third and its top
    /// row (lasers without returns) go to their own rows, with no error.
    #[test]
    fn alignment_gives_each_ring_its_row_past_skipped_rows() {
        let rows = &known_sensors()[0].rows;
        let n = rows.len();
        let kept: Vec<usize> = (0..n - 1).filter(|&j| j != 2).collect();
        let medians: Vec<f32> = kept.iter().map(|&j| rows.tan_elevation[j] + rows.vertical_m[j] / 20.0).collect();
        let a = align(&medians, &vec![20.0; kept.len()], rows).expect("aligned");
        assert_eq!(a.rows, kept);
        assert!(a.sum_deg < 1e-3 && a.worst_deg < 1e-3, "{} {}", a.sum_deg, a.worst_deg);
        assert!(align(&vec![0.0; n + 1], &vec![20.0; n + 1], rows).is_none());
    }

    /// Each known table's own elevations (seen from the origin at 20 m) match that table, also
    /// with its two top lasers missing; the same elevations 2 degrees higher match none.
    #[test]
    fn each_known_table_matches_itself() {
        for sensor in known_sensors() {
            let rows = &sensor.rows;
            let dist = vec![20.0f32; rows.len()];
            let medians: Vec<f32> =
                (0..rows.len()).map(|j| rows.tan_elevation[j] + rows.vertical_m[j] / 20.0).collect();
            let m = match_rings(&medians, &dist).unwrap_or_else(|| panic!("{} unmatched", sensor.model));
            assert_eq!(m.sensor.model, sensor.model);
            assert!(m.mean_error_deg < 0.01, "{}: {}", sensor.model, m.mean_error_deg);
            // Two lasers without returns (the top ones): still this sensor.
            let short = rows.len() - 2;
            let m = match_rings(&medians[..short], &dist[..short]).unwrap();
            assert_eq!(m.sensor.model, sensor.model);
            // Every elevation 2 degrees up: nothing matches.
            let shifted: Vec<f32> = medians.iter().map(|t| (t.atan() + 2f32.to_radians()).tan()).collect();
            if let Some(m) = match_rings(&shifted, &dist) {
                panic!("{} shifted matched {}", sensor.model, m.sensor.model);
            }
        }
    }

    /// The fit that stops early rejects exactly the tables whose whole-sample fraction within is
    /// under the floor, and gives the whole-sample figures otherwise: points on each known table's
    /// beams (20 m out, every 7th degree of azimuth, each beam seen from its origin) fitted
    /// against every known table.
    #[test]
    fn a_fit_stopped_early_rejects_what_the_whole_fit_rejects() {
        let mut accepted = 0;
        for truth in known_sensors() {
            let r = &truth.rows;
            let points: Vec<glam::Vec3> = (0..r.len())
                .flat_map(|j| {
                    (0..52).map(move |k| {
                        let az = (k as f32 * 7.0).to_radians();
                        let d = 20.0;
                        glam::Vec3::new(
                            (d + r.along_m[j]) * az.cos(),
                            (d + r.along_m[j]) * az.sin(),
                            r.vertical_m[j] + d * r.tan_elevation[j],
                        )
                    })
                })
                .collect();
            let sample: Vec<u32> = (0..points.len() as u32).collect();
            for table in known_sensors() {
                let whole = fit_rows(&points, &sample, &table.rows);
                match fit(&points, &sample, table) {
                    Some(f) => {
                        assert!(whole.0 >= FIT_FRACTION, "{} on {}", table.model, truth.model);
                        assert_eq!(f, whole);
                        accepted += 1;
                    }
                    None => assert!(whole.0 < FIT_FRACTION, "{} on {}: {}", table.model, truth.model, whole.0),
                }
            }
        }
        // Each table accepts at least its own points; most reject the others'.
        assert!(accepted >= known_sensors().len() && accepted < known_sensors().len().pow(2) / 2, "{accepted}");
    }
}
