//! Firing order: the lasers of one firing, then the next (the drivers' point order).
//!
//! Such a cloud turns about once in azimuth over the file, and successive points lie close in
//! azimuth (the lasers of a firing, at most their azimuth offsets apart): at least
//! [`CLOSE_FRACTION`] of the steps are under [`CLOSE_STEP_DEG`]. Its table is a known one that fits
//! the points ([`super::matching::match_points`]); else the clusters of the points' elevations, where
//! the elevation sequence repeats with their count (or twice it: dual returns) as its period. Rows
//! are each point's nearest beam, columns its beam azimuth ([`PathChoice::BeamTable`]).

use std::f32::consts::TAU;

use super::matching::{fit_rows, match_points, row_of};
use super::{
    DUAL_FRACTION, RecoveredOrder, RecoveredSensor, Recovery, cell_in, chosen_table, columns_from_steps, given_table,
    median, unnamed_table, wrap_pi,
};
use crate::ordering::beam_table::{BeamTable, TableRows};
use crate::ordering::{InputPoint, PathChoice};

/// Fraction of successive points that must lie within [`CLOSE_STEP_DEG`] in azimuth.
pub const CLOSE_FRACTION: f64 = 0.9;

/// Largest azimuth step between successive points of one firing or the next, degrees (the
/// lasers' azimuth offsets: -8.5 to +9.9 deg on an HDL-64E; a shuffled cloud's steps fall within
/// it one time in six).
pub const CLOSE_STEP_DEG: f32 = 30.0;

/// Points sampled to fit the known tables.
const FIT_SAMPLES: usize = 4096;

/// Points read in order for the columns and the period.
const WINDOW: usize = 60_000;

/// Recovers a firing-order cloud (`az`: the usable points' azimuths, `usable` their indices where
/// some points are not usable), or says why the points are not in firing order.
pub(crate) fn recover_firing<P: InputPoint>(
    points: &[P],
    usable: Option<&[u32]>,
    az: &[f32],
    given: Option<&BeamTable>,
) -> Result<Recovery, String> {
    let n = az.len();
    let index = |i: usize| usable.map_or(i as u32, |u| u[i]);
    let (mut close, mut turned) = (0usize, 0f32);
    for w in az.windows(2) {
        let step = wrap_pi(w[1] - w[0]);
        close += usize::from(step.abs() < CLOSE_STEP_DEG.to_radians());
        turned += step;
    }
    let turns = turned.abs() / TAU;
    let close_fraction = close as f64 / (n - 1) as f64;
    if close_fraction < CLOSE_FRACTION || turns > 3.0 {
        return Err(format!(
            "{:.0} % of successive points within {CLOSE_STEP_DEG} deg of azimuth, the azimuth turning {turns:.1} times",
            100.0 * close_fraction
        ));
    }
    let stride = n.div_ceil(FIT_SAMPLES).max(1);
    let sample: Vec<u32> = (0..n).step_by(stride).map(index).collect();
    let matched = if given.is_some() { None } else { match_points(points, &sample) };
    let (rows, matched_rows, rings, mean_error_deg) = match (given, &matched) {
        (Some(g), _) => {
            let rows = g.rows().map_err(|e| e.to_string())?;
            let mean = fit_rows(points, &sample, &rows).2;
            (rows, true, 0, Some(mean))
        }
        (None, Some(m)) => (m.sensor.rows.clone(), true, m.sensor.rows.len(), Some(m.mean_error_deg)),
        (None, None) => {
            let tan = unnamed_elevations(points, usable, n)?;
            let rows = unnamed_table(&tan, 2).rows().map_err(|e| e.to_string())?;
            (rows, false, tan.len(), None)
        }
    };
    let point_rows = rows_of_points(points, usable, n, &rows, matched_rows);
    let rings = if given.is_some() { rows_with_points(&point_rows, usable, n, rows.len()) } else { rings };
    // Columns: the azimuth step between successive points of one row.
    let window = n.min(WINDOW);
    let mut last = vec![f32::NAN; rows.len()];
    let mut steps = Vec::with_capacity(window);
    for i in 0..window {
        let row = usize::from(point_rows[index(i) as usize]);
        if last[row].is_finite() {
            steps.push(wrap_pi(az[i] - last[row]).abs());
        }
        last[row] = az[i];
    }
    let cols_estimate = columns_from_steps(steps).ok_or("no laser fires twice")?;
    let (table, columns, model) = chosen_table(given, matched.as_ref(), &rows.tan_elevation, cols_estimate);
    let second_echoes = second_echoes(points, usable, n, &table, &point_rows)?;
    Ok(Recovery {
        sensor: RecoveredSensor {
            model,
            rings,
            rows: table.elevations_rad.len(),
            columns,
            order: RecoveredOrder::Firing,
            echoes: if second_echoes.is_empty() { 1 } else { 2 },
            mean_error_deg,
            calibrated: given.is_some(),
        },
        table,
        choice: PathChoice::BeamTable,
        second_echoes,
        point_rows: Some(point_rows),
    })
}

/// A cloud in no order recovery knows (shuffled, merged, thinned) whose lasers are `given` (a
/// calibration file's table): each point's row from its elevation, seen from its beam's origin;
/// columns from the azimuth gaps within the four fullest rows, their azimuths sorted (any order
/// will do); second echoes as in firing order.
pub(crate) fn any_order<P: InputPoint>(
    points: &[P],
    usable: Option<&[u32]>,
    az: &[f32],
    given: &BeamTable,
) -> Result<Recovery, String> {
    let n = az.len();
    let index = |i: usize| usable.map_or(i as u32, |u| u[i]);
    let rows = given.rows().map_err(|e| e.to_string())?;
    let point_rows = rows_of_points(points, usable, n, &rows, true);
    let mut by_row: Vec<Vec<f32>> = vec![Vec::new(); rows.len()];
    for (i, &a) in az.iter().enumerate() {
        by_row[usize::from(point_rows[index(i) as usize])].push(a);
    }
    by_row.sort_by_key(|a| std::cmp::Reverse(a.len()));
    let mut gaps = Vec::new();
    for a in by_row.iter_mut().take(4) {
        a.sort_by(f32::total_cmp);
        gaps.extend(a.windows(2).map(|w| w[1] - w[0]));
    }
    let cols = columns_from_steps(gaps).ok_or("no laser holds two points apart in azimuth")?;
    let (table, model) = given_table(given, cols);
    let second_echoes = second_echoes(points, usable, n, &table, &point_rows)?;
    let stride = n.div_ceil(FIT_SAMPLES).max(1);
    let sample: Vec<u32> = (0..n).step_by(stride).map(index).collect();
    Ok(Recovery {
        sensor: RecoveredSensor {
            model,
            rings: rows_with_points(&point_rows, usable, n, rows.len()),
            rows: rows.len(),
            columns: cols,
            order: RecoveredOrder::Elevations,
            echoes: if second_echoes.is_empty() { 1 } else { 2 },
            mean_error_deg: Some(fit_rows(points, &sample, &rows).2),
            calibrated: true,
        },
        table,
        choice: PathChoice::BeamTable,
        second_echoes,
        point_rows: Some(point_rows),
    })
}

/// How many of the `rows` rows hold one of the `n` usable points.
fn rows_with_points(point_rows: &[u16], usable: Option<&[u32]>, n: usize, rows: usize) -> usize {
    let mut held = vec![false; rows];
    for i in 0..n {
        held[usize::from(point_rows[usable.map_or(i, |u| u[i] as usize)])] = true;
    }
    held.iter().filter(|&&h| h).count()
}

/// Each usable point's row in `rows` (of `n` usable ones; the others 0): its nearest beam, seen
/// from the beam's origin where `from_origins`.
fn rows_of_points<P: InputPoint>(
    points: &[P],
    usable: Option<&[u32]>,
    n: usize,
    rows: &TableRows,
    from_origins: bool,
) -> Vec<u16> {
    let mut point_rows = vec![0u16; points.len()];
    for i in 0..n {
        let k = usable.map_or(i, |u| u[i] as usize);
        point_rows[k] = row_of(rows, from_origins.then_some(&rows.along_m[..]), points[k].xyz()).0 as u16;
    }
    point_rows
}

/// The points (of `n` usable ones) that fall into a cell an earlier point holds, where they are at
/// least [`DUAL_FRACTION`] of the points (dual returns); none otherwise.
fn second_echoes<P: InputPoint>(
    points: &[P],
    usable: Option<&[u32]>,
    n: usize,
    table: &BeamTable,
    point_rows: &[u16],
) -> Result<Vec<u32>, String> {
    let rows = table.rows().map_err(|e| e.to_string())?;
    let mut held = vec![false; rows.len() * rows.cols];
    let mut second = Vec::new();
    for i in 0..n {
        let k = usable.map_or(i as u32, |u| u[i]);
        let row = usize::from(point_rows[k as usize]);
        let cell = cell_in(&rows, row, points[k as usize].xyz()) as usize;
        if held[cell] {
            second.push(k);
        }
        held[cell] = true;
    }
    if (second.len() as f64) < DUAL_FRACTION * n as f64 {
        second.clear();
    }
    Ok(second)
}

/// An unnamed sensor's elevations (`tan`, sorted up) from a firing-order cloud: the clusters of
/// the sampled points' elevations (gaps of more than about 0.04 deg between them, each holding at
/// least 0.2 % of the points), accepted where successive points mostly change cluster (the
/// lasers of a firing, one after another).
fn unnamed_elevations<P: InputPoint>(points: &[P], usable: Option<&[u32]>, n: usize) -> Result<Vec<f32>, String> {
    let index = |i: usize| usable.map_or(i, |u| u[i] as usize);
    let tan_of = |i: usize| {
        let p = points[index(i)].xyz();
        p.z / (p.x * p.x + p.y * p.y).sqrt().max(1e-6)
    };
    let stride = n.div_ceil(20_000).max(1);
    let mut sample: Vec<f32> = (0..n).step_by(stride).map(tan_of).collect();
    sample.sort_by(f32::total_cmp);
    let min_size = (sample.len() / 500).max(3);
    let mut clusters = Vec::new();
    let mut start = 0;
    for i in 1..=sample.len() {
        if i == sample.len() || sample[i] - sample[i - 1] > 7e-4 {
            if i - start >= min_size {
                clusters.push(median(&mut sample[start..i].to_vec()));
            }
            start = i;
        }
    }
    let count = clusters.len();
    if !(2..=256).contains(&count) {
        return Err(format!("{count} elevation clusters"));
    }
    // A laser seldom fires twice in a row: successive points of the first ones mostly change
    // cluster (a cloud sorted by azimuth alone would not).
    let rows = unnamed_table(&clusters, 2).rows().map_err(|e| e.to_string())?;
    let window = n.min(WINDOW);
    let row_of = |i: usize| rows.nearest_row(points[index(i)].xyz()).0;
    let changes = (1..window).filter(|&i| row_of(i) != row_of(i - 1)).count();
    if (changes as f64) < 0.5 * (window - 1) as f64 {
        return Err(format!(
            "the elevations form {count} clusters, but only {changes} of {} successive points change cluster",
            window - 1
        ));
    }
    Ok(clusters)
}
