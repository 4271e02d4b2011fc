//! Rings and columns recovered from the data, for a flat cloud with no ring field whose sensor was
//! not given (no rig, no calibration file): the sensor's own elevation table and columns, matched
//! against every known spinning sensor ([`known`]) and named in the report, or used as an unnamed
//! sensor where none matches. Never the HDL-64E table by default: a cloud whose order cannot be
//! recovered is refused ([`RecoveryError`]).
//!
//! The point orders recovered ([`RecoveredOrder`]):
//! - **ring-major** (KITTI `.bin`, our writer): each laser one turn of azimuth, top laser first. The
//!   turns are found by scan unfolding ([`super::unfold`]) with a provisional table of 256 fine
//!   rows, so any count from 2 to 256 turns unfolds; each turn is a ring and its median elevation
//!   a row of the table. A second echo plane written after the first (dual returns: the rings'
//!   elevations start again from the top) is a second run of rings.
//! - **firing order** (the drivers: the lasers of one firing, then the next): the azimuth turns
//!   once over the file and moves little from point to point ([`firing`]). The known tables are
//!   fitted to the points' elevations ([`matching`]); without a fit, the elevations' clusters give
//!   the table (where successive points mostly change cluster). A point whose
//!   cell an earlier point of the file already holds, in a file where that happens to at least
//!   [`DUAL_FRACTION`] of the points, is a second echo (dual returns: a driver writes both echoes
//!   of a firing, or repeats the point where they agree).
//!
//! Columns per turn come from the azimuth step between a laser's successive points; a named sensor
//! takes the column count of its rotation rate (or lidar mode) nearest to it. The table of a named
//! sensor is its nominal one with its beam origins (what its rig gives); the HDL-64E's is the
//! nominal KITTI table ([`super::KITTI_COLUMNS`] columns), as ordered before recovery existed, so
//! real KITTI frames keep their decisions. Second echoes share the cell (and the decision) of the
//! first echo of their beam.

mod firing;
pub mod known;
mod matching;
pub mod ring_field;

use std::f32::consts::{PI, TAU};
use std::sync::OnceLock;

use glam::Affine3A;
use serde::Serialize;

pub use known::matched_models;
pub use matching::{FIT_FRACTION, MATCH_MAX_DEG, MATCH_MEAN_DEG};

use super::beam_table::{BeamTable, TableRows, round_fast, wrap_into};
use super::unfold::{ring_starts, sampled_median};
use super::{
    CloudBuffer, InputPoint, OrderingPath, OrderingReport, PathChoice, PointAttributes, UnfoldParams, order_cloud_into,
    polar,
};
use crate::error::Result;

/// Fraction of a firing-order cloud's points that must fall into a cell an earlier point holds for
/// the cloud to be read as dual returns.
pub const DUAL_FRACTION: f64 = 0.01;

/// Rings of the provisional table that ring-major unfolding may find (dual returns of 128 lasers).
const MAX_RINGS: usize = 256;

/// Columns of the provisional table: a turn of up to 8,192 points (5 Hz at 40 k points per second
/// per laser is 8,000).
const MAX_COLUMNS: usize = 8192;

/// Relative difference within which an estimated column count is exactly one of a model's.
const EXACT_COLUMNS: f64 = 0.005;

/// The order the points of a recovered cloud came in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RecoveredOrder {
    /// Laser by laser, each one turn of azimuth (KITTI).
    RingMajor,
    /// Firing by firing, the lasers of one firing then the next (the drivers).
    Firing,
    /// Any order: each point's laser from the cloud's ring field ([`ring_field`]).
    RingField,
    /// A headerless file holding a whole sensor image, row by row (a row is one laser:
    /// ouster-ros): each point's laser from its row ([`super::OrganizedLayout`]).
    ImageRows,
    /// A headerless file holding a whole sensor image column by column (a column is one firing:
    /// RELLIS-3D, nuScenes): each point's laser from its place in the firing.
    ImageColumns,
    /// No order recovery knows (shuffled, merged or thinned) but the lasers given by a
    /// calibration file: each point's laser from its elevation.
    Elevations,
}

impl RecoveredOrder {
    /// The order's name as reports print it.
    pub fn name(self) -> &'static str {
        match self {
            RecoveredOrder::RingMajor => "ring-major",
            RecoveredOrder::Firing => "firing",
            RecoveredOrder::RingField => "ring-field",
            RecoveredOrder::ImageRows => "image-rows",
            RecoveredOrder::ImageColumns => "image-columns",
            RecoveredOrder::Elevations => "elevations",
        }
    }
}

/// The sensor recovered from a cloud's data.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RecoveredSensor {
    /// The known model whose table the data matched (`sim` model name), `None` for an unnamed
    /// sensor ordered on the rings it shows; with [`RecoveredSensor::calibrated`], the model
    /// whose firing times the calibration file's lasers took (a unit of that model), if any.
    pub model: Option<&'static str>,
    /// Rings the data shows (lasers with returns).
    pub rings: usize,
    /// Rows of the table used.
    pub rows: usize,
    /// Columns per turn of the table used.
    pub columns: usize,
    /// The point order the rings were recovered from.
    pub order: RecoveredOrder,
    /// Echoes per beam (2: dual returns).
    pub echoes: usize,
    /// Mean elevation error of the data against the matched table, degrees.
    pub mean_error_deg: Option<f32>,
    /// The table is the sensor's own calibration file (which gives no column count): only the
    /// point order, the echoes and the columns were recovered from the data.
    pub calibrated: bool,
}

impl RecoveredSensor {
    /// One phrase for the ordering report: `matched: hdl32e (...)` or `unnamed sensor: ...`.
    pub fn summary(&self) -> String {
        let order = match self.order {
            RecoveredOrder::RingField => "lasers from the ring field".to_string(),
            RecoveredOrder::ImageRows => "lasers from the rows of a whole image stored row by row".to_string(),
            RecoveredOrder::ImageColumns => "lasers from the rows of a whole image stored firing by firing".to_string(),
            RecoveredOrder::Elevations => "no point order: lasers from the elevations".to_string(),
            o => format!("{} order", o.name()),
        };
        let how = format!(
            "{} rings x {} columns, {order}{}",
            self.rows,
            self.columns,
            if self.echoes > 1 { ", dual returns" } else { "" }
        );
        if self.calibrated {
            let fit =
                self.mean_error_deg.map_or(String::new(), |e| format!("; elevations within {e:.2} deg on average"));
            let dual = if self.echoes > 1 { ", dual returns" } else { "" };
            let times = self.model.map_or(String::new(), |m| format!("; firing times of {m}, whose unit it is"));
            return format!(
                "from the calibration file: {} lasers x {} columns ({order}{dual}; columns from the data{times}{fit})",
                self.rows, self.columns
            );
        }
        match (self.model, self.mean_error_deg) {
            (Some(m), Some(e)) => format!("matched: {m} ({how}; elevations within {e:.2} deg on average)"),
            (Some(m), None) => format!("matched: {m} ({how})"),
            (None, _) => format!(
                "unnamed sensor: no known table within {MATCH_MEAN_DEG} deg of the {} rings it shows ({how})",
                self.rings
            ),
        }
    }
}

/// Why a cloud's rings cannot be recovered.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RecoveryError {
    /// Neither scan order nor firing order, no ring field, no sensor given.
    #[error(
        "no ring order can be recovered from {points} points ({why}): they are neither in scan order (each laser one turn of azimuth) nor in firing order (the lasers of one firing, then the next), and have no ring field; name the sensor (a rig or a calibration file)"
    )]
    NoOrder {
        /// Usable points of the cloud.
        points: usize,
        /// What the data showed.
        why: String,
    },
}

/// What recovery found: the table and path to order with, the sensor, and the second echoes.
pub(crate) struct Recovery {
    /// The table to order with.
    pub table: BeamTable,
    /// The path: unfolding for ring-major order, the beam table for firing order.
    pub choice: PathChoice,
    /// The sensor, for the report.
    pub sensor: RecoveredSensor,
    /// Indices (into the points) of second echoes, increasing.
    pub second_echoes: Vec<u32>,
    /// Firing order: each point's row (0 lowest), given to ordering as its ring.
    pub point_rows: Option<Vec<u16>>,
}

/// The provisional table of ring-major unfolding: [`MAX_RINGS`] rows 0.05 deg apart (the smallest
/// gap sets how small an elevation step may end a ring), [`MAX_COLUMNS`] columns.
fn provisional_rows() -> &'static TableRows {
    static ROWS: OnceLock<TableRows> = OnceLock::new();
    ROWS.get_or_init(|| {
        let e = (0..MAX_RINGS).map(|i| (i as f32 * 0.05).to_radians()).collect();
        BeamTable::spinning(e, MAX_COLUMNS).rows().expect("a valid provisional table")
    })
}

/// `a` wrapped into `(-pi, pi]` (`a` within a turn of it).
#[inline]
fn wrap_pi(a: f32) -> f32 {
    if a > PI {
        a - TAU
    } else if a <= -PI {
        a + TAU
    } else {
        a
    }
}

/// The median of `v` (NaN for none), reordering it.
fn median(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return f32::NAN;
    }
    let m = v.len() / 2;
    *v.select_nth_unstable_by(m, f32::total_cmp).1
}

/// Columns per turn from azimuth steps between a laser's successive points (steps under 1e-4 rad,
/// repeated points, left out): a turn over the median step.
fn columns_from_steps(mut steps: Vec<f32>) -> Option<usize> {
    steps.retain(|&s| s > 1e-4);
    let step = median(&mut steps);
    (step.is_finite() && step > 0.0).then(|| ((TAU / step).round() as usize).clamp(2, 1 << 20))
}

/// The usable points (finite, not at the origin) of `points`: their indices where some are not.
fn usable_indices<P: InputPoint>(points: &[P]) -> Option<Vec<u32>> {
    let ok = |p: &P| {
        let v = p.xyz();
        v.is_finite() && v != glam::Vec3::ZERO
    };
    if points.iter().all(ok) {
        return None;
    }
    Some((0..points.len() as u32).filter(|&k| ok(&points[k as usize])).collect())
}

/// A table from recovered elevations (`tan`, sorted up) and columns: an unnamed sensor's.
fn unnamed_table(tan_sorted: &[f32], cols: usize) -> BeamTable {
    let mut e: Vec<f32> = tan_sorted.iter().map(|t| t.atan()).collect();
    // Strictly increasing (the table refuses two beams at one elevation).
    for i in 1..e.len() {
        if e[i] <= e[i - 1] {
            e[i] = e[i - 1].next_up();
        }
    }
    BeamTable::spinning(e, cols)
}

/// Largest difference, degrees, between a calibration file's laser and a known model's for the
/// file to be read as a unit of that model (a unit's calibration differs from the nominal table
/// by hundredths of a degree; neighbouring lasers lie 0.1 deg or more apart).
const SAME_LASER_DEG: f32 = 0.05;

/// A given table (a calibration file's lasers, which give no column count) over `cols` columns
/// per turn: its elevations, azimuth and origin offsets kept. Where every laser is within
/// [`SAME_LASER_DEG`] of one of a known model's (a unit of that model) and `cols` is one of the
/// model's column counts, the lasers' firing-time column offsets come from the model: the file
/// gives angles, not firing times, which are the model's.
/// Returns the table and the model whose firing times it took, if any.
fn given_table(given: &BeamTable, cols: usize) -> (BeamTable, Option<&'static str>) {
    let step = TAU / cols as f32;
    let mut t = given.clone();
    (t.cols, t.azimuth_step_rad, t.azimuth_left_rad) = (cols, step, PI - 0.5 * step);
    let (offsets, model) =
        model_column_offsets(&t.elevations_rad, cols).map_or((Vec::new(), None), |(o, m)| (o, Some(m)));
    t.column_offsets = offsets;
    (t, model)
}

/// The column offsets of the known model with `cols` columns whose lasers are `elevations_rad`
/// (each within [`SAME_LASER_DEG`] of a distinct laser of the model), in their order.
fn model_column_offsets(elevations_rad: &[f32], cols: usize) -> Option<(Vec<f32>, &'static str)> {
    let tolerance = SAME_LASER_DEG.to_radians();
    known::known_sensors().iter().filter(|k| k.rows.len() == elevations_rad.len()).find_map(|k| {
        let table = k.table(cols)?;
        if table.column_offsets.len() != elevations_rad.len() {
            return None;
        }
        let mut taken = vec![false; elevations_rad.len()];
        let mut offsets = Vec::with_capacity(elevations_rad.len());
        for &e in elevations_rad {
            let (j, d) =
                table.elevations_rad.iter().map(|&m| (m - e).abs()).enumerate().min_by(|a, b| a.1.total_cmp(&b.1))?;
            if d > tolerance || std::mem::replace(&mut taken[j], true) {
                return None;
            }
            offsets.push(table.column_offsets[j]);
        }
        Some((offsets, k.model))
    })
}

/// The mean elevation error, degrees, of rings at `tan_sorted` (sorted up) and median distances
/// `dist_sorted` against `table`'s rows, where they align.
fn given_fit(table: &BeamTable, tan_sorted: &[f32], dist_sorted: &[f32]) -> Option<f32> {
    let rows = table.rows().ok()?;
    matching::align(tan_sorted, dist_sorted, &rows).map(|a| a.sum_deg / tan_sorted.len().max(1) as f32)
}

/// The table to order with, its columns and the model named in the report: the `given` table over
/// `cols_estimate` columns (named: the model whose firing times it took, if any), else the
/// `matched` sensor's, else an unnamed sensor's of the elevations `tan_sorted`.
fn chosen_table(
    given: Option<&BeamTable>,
    matched: Option<&matching::Matched>,
    tan_sorted: &[f32],
    cols_estimate: usize,
) -> (BeamTable, usize, Option<&'static str>) {
    match (given, matched) {
        (Some(g), _) => {
            let (t, firing_times) = given_table(g, cols_estimate);
            (t, cols_estimate, firing_times)
        }
        (None, Some(m)) => {
            let (t, cols) = named_table(m.sensor, cols_estimate);
            (t, cols, Some(m.sensor.model))
        }
        (None, None) => (unnamed_table(tan_sorted, cols_estimate), cols_estimate, None),
    }
}

/// The table of a matched known sensor with about `cols_estimate` columns. An HDL-64E whose
/// columns are not exactly one of its rates' (within [`EXACT_COLUMNS`]: real KITTI frames, whose
/// head turns a little slower than 10 Hz, hold about 2,160) takes the nominal KITTI table, as
/// before recovery existed.
fn named_table(sensor: &known::KnownSensor, cols_estimate: usize) -> (BeamTable, usize) {
    let exact = sensor
        .columns_near(cols_estimate as f64)
        .filter(|&c| (c as f64 - cols_estimate as f64).abs() <= EXACT_COLUMNS * cols_estimate as f64);
    if sensor.model == "hdl64e" && exact.is_none() {
        let t = BeamTable { min_range_m: sensor.min_range_m, ..BeamTable::hdl64e(super::KITTI_COLUMNS) };
        return (t, super::KITTI_COLUMNS);
    }
    if let Some(cols) = sensor.columns_near(cols_estimate as f64)
        && let Some(t) = sensor.table(cols)
    {
        return (t, cols);
    }
    // A rate the model does not list: its beams over the columns the data shows.
    let factory = sensor.options.first().and_then(|o| sensor.table(o.0));
    let mut t = factory.unwrap_or_else(|| unnamed_table(&sensor.rows.tan_elevation, cols_estimate));
    let step = TAU / cols_estimate as f32;
    (t.cols, t.azimuth_step_rad, t.azimuth_left_rad) = (cols_estimate, step, PI - 0.5 * step);
    // Its lasers' column offsets are in the listed rate's columns: left out.
    t.column_offsets.clear();
    t.min_range_m = sensor.min_range_m;
    (t, cols_estimate)
}

/// Recovers the sensor of `points` (sensor frame, file order, no ring field); with `given` (a
/// calibration file's table) only the order, the echoes and the columns, on its lasers.
pub(crate) fn recover<P: InputPoint>(points: &[P], given: Option<&BeamTable>) -> Result<Recovery, RecoveryError> {
    let usable = usable_indices(points);
    let index = |i: usize| usable.as_ref().map_or(i as u32, |u| u[i]);
    let (az, dist, tan) = polar::polar(points, usable.as_deref());
    let n = az.len();
    if n < 64 {
        return Err(RecoveryError::NoOrder { points: n, why: "fewer than 64 usable points".into() });
    }
    let params = UnfoldParams::default();
    let why_not_rings = match ring_starts(&az, &dist, &tan, provisional_rows(), &params) {
        Ok((starts, _)) => return Ok(from_rings(&starts, &az, &dist, &tan, index, given)),
        Err(why) => why,
    };
    let why_not_firing = match firing::recover_firing(points, usable.as_deref(), &az, given) {
        Ok(rec) => return Ok(rec),
        Err(why) => why,
    };
    match given {
        // The lasers are known: each point's row from its elevation, whatever the order.
        Some(g) => firing::any_order(points, usable.as_deref(), &az, g).map_err(|why| RecoveryError::NoOrder {
            points: n,
            why: format!("not scan order: {why_not_rings}; not firing order: {why_not_firing}; {why}"),
        }),
        None => Err(RecoveryError::NoOrder {
            points: n,
            why: format!("not scan order: {why_not_rings}; not firing order: {why_not_firing}"),
        }),
    }
}

/// The recovery of a ring-major cloud whose usable points (`az`, `dist`, `tan`) unfolded into rings
/// starting at `starts`; `index(i)` is usable point `i`'s index among all points.
fn from_rings(
    starts: &[usize],
    az: &[f32],
    dist: &[f32],
    tan: &[f32],
    index: impl Fn(usize) -> u32,
    given: Option<&BeamTable>,
) -> Recovery {
    let n = az.len();
    let mut bounds = starts.to_vec();
    bounds.push(n);
    let mut scratch = Vec::new();
    let medians: Vec<f32> = bounds.windows(2).map(|w| sampled_median(&tan[w[0]..w[1]], &mut scratch)).collect();
    let dists: Vec<f32> = bounds.windows(2).map(|w| sampled_median(&dist[w[0]..w[1]], &mut scratch)).collect();
    // Runs of rings stepping one way in elevation: a jump back by a quarter of the span starts the
    // next echo plane.
    let (lo, hi) = medians.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &m| (a.min(m), b.max(m)));
    let way: f32 = medians.windows(2).map(|w| (w[1] - w[0]).signum()).sum::<f32>().signum();
    let mut run_of_ring = vec![0usize; medians.len()];
    for r in 1..medians.len() {
        let back = (medians[r] - medians[r - 1]) * way < -0.25 * (hi - lo);
        run_of_ring[r] = run_of_ring[r - 1] + usize::from(back);
    }
    let planes = run_of_ring.last().map_or(1, |&r| r + 1);
    // A plane's first ring starts where the elevation jumps back: unfolding puts a boundary in
    // the cut window at a step in the rings' direction, so the new plane's first points near the
    // cut may end the previous ring. They go back to the ring nearer their elevation.
    for r in 1..medians.len() {
        if run_of_ring[r] > run_of_ring[r - 1] {
            while bounds[r] > bounds[r - 1] + 1
                && (tan[bounds[r] - 1] - medians[r]).abs() < (tan[bounds[r] - 1] - medians[r - 1]).abs()
            {
                bounds[r] -= 1;
            }
        }
    }
    // The first plane's rings that hold a few points at least (a split-off ring's few points are
    // left out of the match).
    let sizes: Vec<usize> = bounds.windows(2).map(|w| w[1] - w[0]).collect();
    let largest = sizes.iter().copied().max().unwrap_or(0);
    let mut first: Vec<(f32, f32)> = (0..medians.len())
        .filter(|&r| run_of_ring[r] == 0 && sizes[r] >= (largest / 50).max(8))
        .map(|r| (medians[r], dists[r]))
        .collect();
    first.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (tan_sorted, dist_sorted): (Vec<f32>, Vec<f32>) = first.into_iter().unzip();
    // Columns from the azimuth steps within the four fullest rings of the first plane.
    let mut fullest: Vec<usize> = (0..medians.len()).filter(|&r| run_of_ring[r] == 0).collect();
    fullest.sort_by_key(|&r| std::cmp::Reverse(sizes[r]));
    let steps: Vec<f32> = fullest
        .iter()
        .take(4)
        .flat_map(|&r| az[bounds[r]..bounds[r + 1]].windows(2).map(|w| wrap_pi(w[1] - w[0]).abs()))
        .collect();
    let cols_estimate = columns_from_steps(steps).unwrap_or(largest.max(2));
    let matched = if given.is_some() { None } else { matching::match_rings(&tan_sorted, &dist_sorted) };
    let (table, columns, model) = chosen_table(given, matched.as_ref(), &tan_sorted, cols_estimate);
    let mean_error_deg = match &matched {
        Some(m) => Some(m.mean_error_deg),
        None => given.and_then(|_| given_fit(&table, &tan_sorted, &dist_sorted)),
    };
    let second_echoes: Vec<u32> =
        (0..medians.len()).filter(|&r| run_of_ring[r] > 0).flat_map(|r| bounds[r]..bounds[r + 1]).map(&index).collect();
    Recovery {
        sensor: RecoveredSensor {
            model,
            rings: tan_sorted.len(),
            rows: table.elevations_rad.len(),
            columns,
            order: RecoveredOrder::RingMajor,
            echoes: planes.min(2),
            mean_error_deg,
            calibrated: given.is_some(),
        },
        table,
        choice: PathChoice::Auto,
        second_echoes,
        point_rows: None,
    }
}

/// The plane-0 cell of `p` in the grid of `rows`: its nearest row and the column of its beam
/// azimuth.
pub(crate) fn cell_of(rows: &TableRows, p: glam::Vec3) -> u32 {
    cell_in(rows, rows.nearest_row(p).0, p)
}

/// The plane-0 cell of `p` in row `row` of the grid of `rows`: the column of its beam azimuth.
pub(crate) fn cell_in(rows: &TableRows, row: usize, p: glam::Vec3) -> u32 {
    let steps = rows.column_steps(rows.beam_azimuth(p, row), row);
    let col = wrap_into(round_fast(steps), rows.cols as f32);
    let col = if col.is_finite() && col >= 0.0 { (col as usize).min(rows.cols - 1) } else { 0 };
    (row * rows.cols + col) as u32
}

/// Orders `points` (sensor frame, no ring field) on the sensor recovered from them (with `given`,
/// a calibration file's table: on its lasers, the order, echoes and columns recovered), into
/// `cloud` and `report` (`report.sensor` says what was recovered); refused where no order can be
/// recovered.
pub(crate) fn order_recovered<P: InputPoint>(
    points: &[P],
    attributes: &PointAttributes<'_>,
    given: Option<&BeamTable>,
    vehicle_from_sensor: Affine3A,
    cloud: &mut CloudBuffer,
    report: &mut OrderingReport,
) -> Result<()> {
    let rec = recover(points, given)?;
    let params = UnfoldParams::default();
    let rings = rec.point_rows.as_deref();
    if rec.second_echoes.is_empty() {
        let attributes = PointAttributes { rings, ..*attributes };
        order_cloud_into(points, &attributes, &rec.table, vehicle_from_sensor, rec.choice, &params, cloud, report)?;
    } else {
        // The first echoes are ordered; each second echo shares the cell of its beam.
        let mut second = vec![false; points.len()];
        for &k in &rec.second_echoes {
            second[k as usize] = true;
        }
        let keep: Vec<usize> = (0..points.len()).filter(|&k| !second[k]).collect();
        let sub_points = pick(&keep, points);
        let labels = attributes.labels.map(|v| pick(&keep, v));
        let intensity = attributes.intensity.map(|v| pick(&keep, v));
        let time_s = attributes.time_s.map(|v| pick(&keep, v));
        let sub_rings = rings.map(|v| pick(&keep, v));
        let sub_attributes = PointAttributes {
            labels: labels.as_deref(),
            intensity: intensity.as_deref(),
            time_s: time_s.as_deref(),
            rings: sub_rings.as_deref(),
        };
        order_cloud_into(
            &sub_points,
            &sub_attributes,
            &rec.table,
            vehicle_from_sensor,
            rec.choice,
            &params,
            cloud,
            report,
        )?;
        let rows = rec.table.rows()?;
        let mut cells = vec![None; points.len()];
        for (i, &k) in keep.iter().enumerate() {
            cells[k] = report.cell_of_point[i];
        }
        for &k in &rec.second_echoes {
            let p = points[k as usize].xyz();
            let cell = match rings {
                Some(r) => cell_in(&rows, usize::from(r[k as usize]), p),
                None => cell_of(&rows, p),
            };
            cells[k as usize] = Some(cell);
        }
        report.cell_of_point = cells;
        report.shared += rec.second_echoes.len();
    }
    if rings.is_some() {
        // Rows from each point's nearest beam: the beam-table path, with the beams' origins undone.
        report.path = OrderingPath::BeamTable;
    }
    report.sensor = Some(rec.sensor);
    Ok(())
}

/// Orders `points` (sensor frame) that carry a ring field (`attributes.rings`) on the table their
/// rings show ([`ring_field`]; with `given`, a calibration file's table: on its lasers, the
/// columns recovered), into `cloud` and `report` (`report.sensor` says what was found); refused
/// where the rings cannot give a table.
pub(crate) fn order_ring_field<P: InputPoint>(
    points: &[P],
    attributes: &PointAttributes<'_>,
    given: Option<&BeamTable>,
    vehicle_from_sensor: Affine3A,
    cloud: &mut CloudBuffer,
    report: &mut OrderingReport,
) -> Result<()> {
    let rings = attributes.rings.unwrap_or_default();
    if rings.len() != points.len() {
        return Err(crate::error::ClassifyError::Ordering("rings and points differ in length".into()));
    }
    let rec = ring_field::recover_ring_field(points, rings, given)?;
    let attributes = PointAttributes { rings: Some(&rec.point_rows), ..*attributes };
    let params = UnfoldParams::default();
    order_cloud_into(points, &attributes, &rec.table, vehicle_from_sensor, PathChoice::Auto, &params, cloud, report)?;
    report.sensor = Some(rec.sensor);
    Ok(())
}

/// The entries `keep` of `v`.
fn pick<T: Copy>(keep: &[usize], v: &[T]) -> Vec<T> {
    keep.iter().map(|&k| v[k]).collect()
}
