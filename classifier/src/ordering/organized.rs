//! Organized clouds (PCD `HEIGHT > 1`) keep their cells; only their rows are put in elevation
//! order (row 0 lowest), whichever way up the file stores them: ouster-ros writes ring 0 = the top
//! beam first, velodyne ring 0 = the bottom beam, our own files bottom-first.
//!
//! With a `ring` field, each file row must hold one ring value below the row count, every row a
//! different one (else the file is refused, naming the value); without, the file row index stands
//! for the ring. Which way the rings go is told from the data, by two votes over the pairs of
//! neighbouring rings' points in every `cols / VOTING_COLUMNS`-th column:
//! - **elevation**: seen from the file's origin (the sensor, in the drivers' layouts), the upper
//!   beam's point lies higher, `z / d` larger (`d` the horizontal distance), on any surface;
//! - **surface**: two points on one surface (closer than [`SAME_SURFACE`] of `d`) step from the
//!   lower beam to the upper one outwards on the ground and upwards on a wall, `dz + dd > 0`, in any
//!   frame whose z is up (also a file in a vehicle frame, whose origin lies below the sensor and
//!   sees the ground at elevation 0); it fails under a ceiling (a garage), which the upper beam
//!   meets nearer.
//!
//! Each vote's balance is `(up - down) / (up + down)`. The elevation vote decides where it leans
//! beyond [`MIN_DIRECTION_SCORE`], else the surface vote where it does; above the threshold ring 0
//! is the bottom beam, below its negative the top beam. Where neither is decisive, or the two lean
//! beyond it in opposite directions, the layout cannot be told and the cloud is refused with a
//! message, never guessed. Decisions come back in the input's own cell order through
//! [`OrderingReport::cell_of_point`].
//!
//! Two ways in, with the same result (tested): [`order_organized`] reorders a cloud read as the
//! file stores it, moving every field's rows; [`read_organized_into`] tells the rows' order from
//! single points of a parsed file ([`sim::io::pcd::PcdFrame`]) and then decodes each file row
//! straight into its row, in the vehicle frame (what `classify` does with a driver's file).

use sim::OrderedCloud;

use super::report::{OrderingPath, OrderingReport};
use crate::error::{ClassifyError, Result};

/// How far the votes must lean (`(up - down) / (up + down)`) before the rows' direction counts as
/// told.
pub const MIN_DIRECTION_SCORE: f32 = 0.5;

/// Columns that vote on which way up the rows are, at least (all of them in narrower clouds).
pub const VOTING_COLUMNS: usize = 128;

/// Neighbouring points closer than this fraction of their horizontal distance lie on one surface.
pub const SAME_SURFACE: f32 = 0.2;

/// Puts the rows of an organized `cloud` (one plane, rows in file order) in elevation order.
/// `has_ring`: whether the file had a `ring` field (then `cloud.ring` holds it). Points (and their
/// normals) go to the vehicle frame through `vehicle_from_sensor`; ranges stay the file's (or the
/// distance from the file's origin where it has none).
pub fn order_organized(
    mut cloud: OrderedCloud,
    has_ring: bool,
    vehicle_from_sensor: glam::Affine3A,
) -> Result<(OrderedCloud, OrderingReport)> {
    let mut report = OrderingReport::default();
    order_organized_in_place(&mut cloud, has_ring, vehicle_from_sensor, &mut report)?;
    Ok((cloud, report))
}

/// As [`order_organized`], in place, with the report into `report` (whose buffer is reused). On an
/// error the cloud is unchanged.
pub fn order_organized_in_place(
    cloud: &mut OrderedCloud,
    has_ring: bool,
    vehicle_from_sensor: glam::Affine3A,
    report: &mut OrderingReport,
) -> Result<()> {
    crate::error::check_cloud(cloud)?;
    let (rows, cols) = (cloud.rows, cloud.cols);
    check_one_plane(cloud.planes)?;
    let ring_of_row = rings_of_rows(rows, |k| match has_ring {
        true => one_ring(k, &cloud.ring[k * cols..(k + 1) * cols]),
        false => Ok(k),
    })?;
    let votes = Votes::count(rows, cols, &ring_of_row, |i| cloud.point_in_vehicle[i]);
    let rings_with_returns = rings_with_returns(&cloud.point_in_vehicle, cols)?;
    let new_row = rows_in_order(&ring_of_row, votes.bottom_first()?);
    let out = cloud;
    macro_rules! permute {
        ($($f:ident),*) => {$( permute_rows(&mut out.$f, cols, &new_row); )*};
    }
    permute!(point_in_vehicle, range_m, intensity, ring, column, sensor, time_s, echo, label, instance, ground, normal);
    if vehicle_from_sensor != glam::Affine3A::IDENTITY {
        sim::cloud::transform_returns(vehicle_from_sensor, &mut out.point_in_vehicle);
        // The drivers' layouts carry no normals: zero normals stay zero.
        // A branch-free or over the normals (vectorized): `any` with `!=` cost 0.15 ms a frame.
        let nonzero = |n: &glam::Vec3| (n.x != 0.0) | (n.y != 0.0) | (n.z != 0.0);
        if out.normal.chunks(256).any(|c| c.iter().fold(false, |acc, n| acc | nonzero(n))) {
            for n in out.normal.iter_mut() {
                *n = vehicle_from_sensor.transform_vector3(*n);
            }
        }
    }
    fill_report(report, &new_row, cols, out.returns(), rings_with_returns);
    Ok(())
}

/// Reads an organized PCD `frame` (one plane) into `cloud` with its rows in elevation order and its
/// points in the vehicle frame, in one pass over the file: the rows' rings and which way up they
/// are (the votes of [`order_organized`], on the same points) are told from single points first,
/// then every file row is decoded straight into its row, its points moved by
/// `vehicle_from_sensor` as they are read. The same cloud and report as
/// [`sim::io::pcd::read_bytes_into`] then [`order_organized_in_place`] (tested), without moving
/// every field's rows and every point a second time (0.5 ms of a 128 x 1024 ouster-ros frame).
/// Also refused as there, except that a row holding two rings is found after the reading, so
/// another row's bad ring is named first where a file has both. On an error `cloud` holds no
/// meaningful content.
pub fn read_organized_into(
    frame: &sim::io::pcd::PcdFrame<'_>,
    vehicle_from_sensor: glam::Affine3A,
    cloud: &mut OrderedCloud,
    report: &mut OrderingReport,
) -> Result<sim::io::pcd::PcdInfo> {
    let (rows, cols, planes) = frame.shape();
    if rows < 2 || cols < 2 || planes == 0 {
        return Err(ClassifyError::TooSmall { rows, cols, planes });
    }
    check_one_plane(planes)?;
    let has_ring = frame.info().has_ring;
    let ring_of_row = rings_of_rows(rows, |k| match has_ring {
        true => Ok(usize::from(frame.ring(k * cols).unwrap_or(0))),
        false => Ok(k),
    })?;
    let votes = Votes::count(rows, cols, &ring_of_row, |i| frame.point(i));
    let bottom_first = votes.bottom_first();
    // Read in the file's order where the direction cannot be told: its error comes after the
    // count of rings with returns, as in `order_organized_in_place`.
    let new_row = rows_in_order(&ring_of_row, *bottom_first.as_ref().unwrap_or(&true));
    let info = frame
        .read_into(cloud, Some(&new_row), vehicle_from_sensor)
        .map_err(|e| ClassifyError::Ordering(e.to_string()))?;
    if has_ring {
        for (k, &d) in new_row.iter().enumerate() {
            one_ring(k, &cloud.ring[d * cols..(d + 1) * cols])?;
        }
    }
    let rings_with_returns = rings_with_returns(&cloud.point_in_vehicle, cols)?;
    bottom_first?;
    fill_report(report, &new_row, cols, cloud.returns(), rings_with_returns);
    Ok(info)
}

/// Refuses clouds of more than one echo plane.
fn check_one_plane(planes: usize) -> Result<()> {
    if planes != 1 {
        return Err(ClassifyError::Ordering(format!(
            "an organized cloud of {planes} planes: only our own files (which say so) have echo planes"
        )));
    }
    Ok(())
}

/// The ring of file row `k` from its cells' `ring` values, which must all be one.
fn one_ring(k: usize, cells: &[u16]) -> Result<usize> {
    let g = cells[0];
    // An or over the row (vectorized) first; the search for the message only on a mismatch.
    let differs = cells.iter().fold(0, |acc, &x| acc | (x ^ g)) != 0;
    if let Some(other) = differs.then(|| cells.iter().find(|&&x| x != g)).flatten() {
        return Err(ClassifyError::Ordering(format!(
            "row {k} holds rings {g} and {other}: the `ring` field does not follow the rows"
        )));
    }
    Ok(usize::from(g))
}

/// The ring of each of the `rows` file rows (`ring_of(k)`), each below the row count and every
/// row a different one.
fn rings_of_rows(rows: usize, ring_of: impl Fn(usize) -> Result<usize>) -> Result<Vec<usize>> {
    let mut ring_of_row = vec![0usize; rows];
    let mut seen = vec![false; rows];
    for (k, ring) in ring_of_row.iter_mut().enumerate() {
        let g = ring_of(k)?;
        if g >= rows {
            return Err(ClassifyError::Ordering(format!("ring {g} in row {k} is out of range 0 ..= {}", rows - 1)));
        }
        if seen[g] {
            return Err(ClassifyError::Ordering(format!("ring {g} appears in more than one row")));
        }
        seen[g] = true;
        *ring = g;
    }
    Ok(ring_of_row)
}

/// Rows of `cols` points of which at least one is a return; refused below two.
fn rings_with_returns(points: &[glam::Vec3], cols: usize) -> Result<usize> {
    let n = points.chunks_exact(cols).filter(|row| row.iter().any(|p| p.is_finite())).count();
    if n < 2 {
        return Err(ClassifyError::Ordering(format!("{n} rings hold returns: fewer than two")));
    }
    Ok(n)
}

/// The new row of each file row: its ring, or counted from the top where ring 0 is the top beam.
fn rows_in_order(ring_of_row: &[usize], bottom_first: bool) -> Vec<usize> {
    let rows = ring_of_row.len();
    ring_of_row.iter().map(|&g| if bottom_first { g } else { rows - 1 - g }).collect()
}

/// The two votes on which way up the rows are (see the module docs).
struct Votes {
    /// Neighbouring pairs whose upper ring's point is higher / lower in elevation.
    higher: usize,
    lower: usize,
    /// Pairs on one surface that step up / down from the lower ring to the upper one.
    up: usize,
    down: usize,
}

impl Votes {
    /// The votes over the pairs of neighbouring rings' points (`point(i)`, file order, no-returns
    /// not finite) in every `cols / VOTING_COLUMNS`-th column.
    fn count(rows: usize, cols: usize, ring_of_row: &[usize], point: impl Fn(usize) -> glam::Vec3) -> Self {
        let mut row_of_ring = vec![0usize; rows];
        for (k, &g) in ring_of_row.iter().enumerate() {
            row_of_ring[g] = k;
        }
        let mut votes = Votes { higher: 0, lower: 0, up: 0, down: 0 };
        // Every `stride`-th column votes (at least `VOTING_COLUMNS` of them): tens of thousands of
        // votes decide as well as all 131,072 pairs of a 128 x 1024 frame, at an eighth of the cost.
        let stride = (cols / VOTING_COLUMNS).max(1);
        let m = cols.div_ceil(stride);
        // Each voting point read once, in file order: read from a file's records, two rings at a
        // time, each twice, they cost 0.75 ms of a 128 x 1024 frame in cache misses.
        let mut sampled = Vec::with_capacity(rows * m);
        for k in 0..rows {
            sampled.extend((0..cols).step_by(stride).map(|c| point(k * cols + c)));
        }
        for g in 0..rows.saturating_sub(1) {
            let (a, b) = (row_of_ring[g] * m, row_of_ring[g + 1] * m);
            for j in 0..m {
                let (p, q) = (sampled[a + j], sampled[b + j]);
                if !(p.is_finite() && q.is_finite()) {
                    continue;
                }
                let (dp, dq) = ((p.x * p.x + p.y * p.y).sqrt(), (q.x * q.x + q.y * q.y).sqrt());
                // Elevation seen from the origin: `q.z / dq` against `p.z / dp`, without divisions.
                let (eq, ep) = (q.z * dp, p.z * dq);
                votes.higher += usize::from(eq > ep);
                votes.lower += usize::from(eq < ep);
                if p.distance(q) > SAME_SURFACE * dp.min(dq) {
                    continue;
                }
                let step = (q.z - p.z) + (dq - dp);
                if step > 0.0 {
                    votes.up += 1;
                } else if step < 0.0 {
                    votes.down += 1;
                }
            }
        }
        votes
    }

    /// Whether ring 0 is the bottom beam, as the votes tell; refused where they cannot tell.
    fn bottom_first(&self) -> Result<bool> {
        let Votes { higher, lower, up, down } = *self;
        let balance = |up: usize, down: usize| (up as f32 - down as f32) / (up + down).max(1) as f32;
        let (elevation, surface) = (balance(higher, lower), balance(up, down));
        let lean = |score: f32| {
            if score > MIN_DIRECTION_SCORE {
                Some(true)
            } else if score < -MIN_DIRECTION_SCORE {
                Some(false)
            } else {
                None
            }
        };
        match (lean(elevation), lean(surface)) {
            (Some(a), Some(b)) if a != b => Err(ClassifyError::Ordering(format!(
                "cannot tell which way up the rows are stored: seen from the file's origin the rings rise {} (balance {elevation:.2}), but neighbouring points on one surface step the other way (balance {surface:.2})",
                if a { "upwards" } else { "downwards" }
            ))),
            (Some(a), _) | (None, Some(a)) => Ok(a),
            (None, None) => Err(ClassifyError::Ordering(format!(
                "cannot tell which way up the rows are stored ({higher} neighbouring pairs rise in elevation and {lower} fall, {up} step up on one surface and {down} down; needs a balance beyond +-{MIN_DIRECTION_SCORE})"
            ))),
        }
    }
}

/// The report of an organized cloud whose file row `k` went to row `new_row[k]`.
fn fill_report(report: &mut OrderingReport, new_row: &[usize], cols: usize, placed: usize, rings: usize) {
    let mut cell_of_point = std::mem::take(&mut report.cell_of_point);
    cell_of_point.clear();
    *report = OrderingReport { path: OrderingPath::Organized, cell_of_point, ..OrderingReport::default() };
    for &r in new_row {
        // A range of known length: `extend` writes it without a capacity check per cell.
        report.cell_of_point.extend((r * cols..(r + 1) * cols).map(|i| Some(i as u32)));
    }
    report.placed = placed;
    report.no_returns = new_row.len() * cols - placed;
    report.rings_found = rings;
}

/// Whether [`order_organized`] found the file top-first: its first row went to the top.
pub fn is_top_first(report: &OrderingReport, rows: usize, cols: usize) -> bool {
    rows > 1 && report.cell_of_point.first().copied().flatten().is_some_and(|c| c as usize / cols.max(1) == rows - 1)
}

/// Moves row `k` of `v` (rows of `cols`) to row `new_row[k]`, in place: nothing where every row
/// holds the same values (fields a file does not have: the reader's defaults), swaps of row pairs
/// for a reversal (a top-first file), else cycle by cycle with one row held aside.
fn permute_rows<T: Copy + PartialEq>(v: &mut [T], cols: usize, new_row: &[usize]) {
    let rows = new_row.len();
    if new_row.iter().enumerate().all(|(k, &d)| d == k) {
        return;
    }
    let first = &v[..cols];
    if v[cols..].chunks_exact(cols).all(|row| row == first) {
        return;
    }
    if new_row.iter().enumerate().all(|(k, &d)| d == rows - 1 - k) {
        let (top, bottom) = v.split_at_mut(rows / 2 * cols);
        let bottom = &mut bottom[(rows % 2) * cols..];
        for (a, b) in top.chunks_exact_mut(cols).zip(bottom.chunks_exact_mut(cols).rev()) {
            a.swap_with_slice(b);
        }
        return;
    }
    let mut done = vec![false; rows];
    for start in 0..rows {
        if done[start] {
            continue;
        }
        done[start] = true;
        if new_row[start] == start {
            continue;
        }
        let mut held: Vec<T> = v[start * cols..(start + 1) * cols].to_vec();
        let mut k = start;
        loop {
            let d = new_row[k];
            held.swap_with_slice(&mut v[d * cols..(d + 1) * cols]);
            done[d] = true;
            if d == start {
                break;
            }
            k = d;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_move_to_their_new_rows() {
        let (rows, cols) = (5, 3);
        let v: Vec<u32> = (0..(rows * cols) as u32).collect();
        for new_row in [vec![4, 3, 2, 1, 0], vec![1, 2, 0, 4, 3], vec![0, 1, 2, 3, 4]] {
            let mut w = v.clone();
            permute_rows(&mut w, cols, &new_row);
            for (k, &d) in new_row.iter().enumerate() {
                assert_eq!(&w[d * cols..(d + 1) * cols], &v[k * cols..(k + 1) * cols], "{new_row:?}");
            }
        }
        // An even row count reversed, and rows that all hold the same values (left as they are).
        let mut even: Vec<u32> = (0..8).collect();
        permute_rows(&mut even, 2, &[3, 2, 1, 0]);
        assert_eq!(even, [6, 7, 4, 5, 2, 3, 0, 1]);
        let mut same = vec![7u8, 9, 7, 9, 7, 9];
        permute_rows(&mut same, 2, &[2, 1, 0]);
        assert_eq!(same, [7, 9, 7, 9, 7, 9]);
    }
}
