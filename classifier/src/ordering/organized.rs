//! Organized clouds (PCD `HEIGHT > 1`) keep their cells; only their rows are put in elevation
//! order (row 0 lowest), whichever way up the file stores them: ouster-ros writes ring 0 = the top
//! beam first, velodyne ring 0 = the bottom beam, our own files bottom-first.
//!
//! With a `ring` field, each file row must hold one ring value below the row count, every row a
//! different one (else the file is refused, naming the value); without, the file row index stands
//! for the ring. Which way the rings go is told from the data: the Spearman rank correlation of the
//! ring index with each row's median `tan(elevation)` (`z / d`) plus that with its median horizontal
//! distance `d` (lower beams hit the ground nearer; both rise with the beam's elevation, in the
//! sensor frame as in the vehicle frame). A sum above +0.5 means ring 0 is the bottom beam, below
//! -0.5 the top beam; in between the layout cannot be told and the cloud is refused with a message,
//! never guessed. Decisions come back in the input's own cell order through
//! [`OrderingReport::cell_of_point`].

use sim::OrderedCloud;

use super::report::{OrderingPath, OrderingReport};
use crate::error::{ClassifyError, Result};

/// How far the rank correlations must lean before the rows' direction counts as told.
pub const MIN_DIRECTION_SCORE: f32 = 0.5;

fn median(v: &mut [f32]) -> Option<f32> {
    if v.is_empty() {
        return None;
    }
    let m = v.len() / 2;
    Some(*v.select_nth_unstable_by(m, f32::total_cmp).1)
}

/// Spearman's rank correlation of `(x, y)` pairs (no tie correction: ties get distinct ranks).
fn spearman(pairs: &[(f32, f32)]) -> f32 {
    let n = pairs.len();
    if n < 2 {
        return 0.0;
    }
    let rank = |key: &dyn Fn(&(f32, f32)) -> f32| {
        let mut idx: Vec<usize> = (0..n).collect();
        idx.sort_by(|&a, &b| key(&pairs[a]).total_cmp(&key(&pairs[b])));
        let mut r = vec![0f32; n];
        for (k, &i) in idx.iter().enumerate() {
            r[i] = k as f32;
        }
        r
    };
    let (rx, ry) = (rank(&|p| p.0), rank(&|p| p.1));
    let d2: f32 = rx.iter().zip(&ry).map(|(a, b)| (a - b) * (a - b)).sum();
    let n = n as f32;
    1.0 - 6.0 * d2 / (n * (n * n - 1.0))
}

/// Puts the rows of an organized `cloud` (one plane, rows in file order) in elevation order.
/// `has_ring`: whether the file had a `ring` field (then `cloud.ring` holds it). Points (and their
/// normals) go to the vehicle frame through `vehicle_from_sensor`; ranges stay the file's (or the
/// distance from the file's origin where it has none).
pub fn order_organized(
    cloud: &OrderedCloud,
    has_ring: bool,
    vehicle_from_sensor: glam::Affine3A,
) -> Result<(OrderedCloud, OrderingReport)> {
    crate::error::check_cloud(cloud)?;
    let (rows, cols) = (cloud.rows, cloud.cols);
    if cloud.planes != 1 {
        return Err(ClassifyError::Ordering(format!(
            "an organized cloud of {} planes: only our own files (which say so) have echo planes",
            cloud.planes
        )));
    }
    // The ring of each file row.
    let mut ring_of_row = vec![0usize; rows];
    let mut seen = vec![false; rows];
    for (k, ring) in ring_of_row.iter_mut().enumerate() {
        let g = if has_ring {
            let cells = &cloud.ring[k * cols..(k + 1) * cols];
            let g = cells[0];
            if let Some(other) = cells.iter().find(|&&x| x != g) {
                return Err(ClassifyError::Ordering(format!(
                    "row {k} holds rings {g} and {other}: the `ring` field does not follow the rows"
                )));
            }
            g as usize
        } else {
            k
        };
        if g >= rows {
            return Err(ClassifyError::Ordering(format!("ring {g} in row {k} is out of range 0 ..= {}", rows - 1)));
        }
        if seen[g] {
            return Err(ClassifyError::Ordering(format!("ring {g} appears in more than one row")));
        }
        seen[g] = true;
        *ring = g;
    }
    // Per ring: median tan(elevation) and median horizontal distance of its returns.
    let (mut el_pairs, mut d_pairs) = (Vec::new(), Vec::new());
    let mut buf_e = Vec::with_capacity(cols);
    let mut buf_d = Vec::with_capacity(cols);
    for (k, &g) in ring_of_row.iter().enumerate() {
        buf_e.clear();
        buf_d.clear();
        for p in &cloud.point_in_vehicle[k * cols..(k + 1) * cols] {
            if p.is_finite() {
                let d = (p.x * p.x + p.y * p.y).sqrt();
                if d > 0.0 {
                    buf_e.push(p.z / d);
                    buf_d.push(d);
                }
            }
        }
        if let (Some(e), Some(d)) = (median(&mut buf_e), median(&mut buf_d)) {
            el_pairs.push((g as f32, e));
            d_pairs.push((g as f32, d));
        }
    }
    if el_pairs.len() < 2 {
        return Err(ClassifyError::Ordering(format!("{} rings hold returns: fewer than two", el_pairs.len())));
    }
    let score = spearman(&el_pairs) + spearman(&d_pairs);
    let bottom_first = if score > MIN_DIRECTION_SCORE {
        true
    } else if score < -MIN_DIRECTION_SCORE {
        false
    } else {
        return Err(ClassifyError::Ordering(format!(
            "cannot tell which way up the rows are stored (rank correlation of ring with elevation and distance {score:.2}, needs beyond +-{MIN_DIRECTION_SCORE})"
        )));
    };
    let new_row: Vec<usize> = ring_of_row.iter().map(|&g| if bottom_first { g } else { rows - 1 - g }).collect();
    let mut out = cloud.clone();
    macro_rules! permute {
        ($($f:ident),*) => {$(
            for (k, &r) in new_row.iter().enumerate() {
                out.$f[r * cols..(r + 1) * cols].copy_from_slice(&cloud.$f[k * cols..(k + 1) * cols]);
            }
        )*};
    }
    permute!(point_in_vehicle, range_m, intensity, ring, column, sensor, time_s, echo, label, instance, ground, normal);
    if vehicle_from_sensor != glam::Affine3A::IDENTITY {
        for p in out.point_in_vehicle.iter_mut().filter(|p| p.is_finite()) {
            *p = vehicle_from_sensor.transform_point3(*p);
        }
        for n in out.normal.iter_mut() {
            *n = vehicle_from_sensor.transform_vector3(*n);
        }
    }
    let mut report = OrderingReport {
        path: OrderingPath::Organized,
        cell_of_point: Vec::with_capacity(rows * cols),
        ..OrderingReport::default()
    };
    for &r in &new_row {
        for c in 0..cols {
            report.cell_of_point.push(Some((r * cols + c) as u32));
        }
    }
    report.placed = cloud.returns();
    report.no_returns = rows * cols - report.placed;
    report.rings_found = el_pairs.len();
    Ok((out, report))
}

/// Whether [`order_organized`] found the file top-first: its first row went to the top.
pub fn is_top_first(report: &OrderingReport, rows: usize, cols: usize) -> bool {
    rows > 1 && report.cell_of_point.first().copied().flatten().is_some_and(|c| c as usize / cols.max(1) == rows - 1)
}
