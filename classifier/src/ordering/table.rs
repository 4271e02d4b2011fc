//! The beam-table path, for clouds whose point order says nothing (shuffled, merged): each point's
//! row is the beam that passes closest to it once the row's origin offsets are undone
//! ([`TableRows::nearest_row`]); its column is the beam azimuth ([`TableRows::beam_azimuth`]).
//! Points beyond the table's lowest or highest beam stay in the edge row and are counted.

use super::beam_table::TableRows;
use super::input_point::InputPoint;
use super::placement::Wish;
use super::report::OrderingReport;
use super::usable::Usable;

/// The wish of every usable point from the table alone.
pub(crate) fn table_wishes<P: InputPoint>(
    points: &[P],
    usable: &Usable,
    rows: &TableRows,
    report: &mut OrderingReport,
) -> Vec<Wish> {
    let mut wishes = Vec::with_capacity(usable.len());
    for k in usable.iter() {
        let p = points[k as usize].xyz();
        let (row, _, outside) = rows.nearest_row(p);
        report.outside += usize::from(outside);
        let steps = rows.column_steps(rows.beam_azimuth(p, row), row);
        wishes.push(Wish { row: row as u32, steps });
    }
    wishes
}

/// The wish of every usable point from its `ring` field: rows are the rings, bottom-first or
/// top-first as the rings' median elevations go (ring 0 at the bottom for velodyne, at the top for
/// ouster); columns from the beam azimuth. Refused for a ring value beyond the table's rows, or a
/// way up that cannot be told (fewer than two rings with points, or no difference in elevation).
pub(crate) fn ring_wishes<P: InputPoint>(
    points: &[P],
    usable: &Usable,
    rings: &[u16],
    rows: &TableRows,
    report: &mut OrderingReport,
) -> Result<Vec<Wish>, String> {
    let n = rows.len();
    let mut sums = vec![(0.0f64, 0usize); n];
    for k in usable.iter() {
        let g = rings[k as usize] as usize;
        if g >= n {
            return Err(format!("point {k} has ring {g}, out of range 0 ..= {} (the beam table's rows)", n - 1));
        }
        let p = points[k as usize].xyz();
        sums[g].0 += f64::from(rows.rough_tan(p));
        sums[g].1 += 1;
    }
    let means: Vec<(usize, f64)> =
        sums.iter().enumerate().filter(|(_, s)| s.1 > 0).map(|(g, s)| (g, s.0 / s.1 as f64)).collect();
    if means.len() < 2 {
        return Err(format!("{} rings hold points: fewer than two", means.len()));
    }
    // Rank agreement of ring index and mean elevation.
    let (mut up, mut down) = (0usize, 0usize);
    for w in means.windows(2) {
        if w[1].1 > w[0].1 {
            up += 1;
        } else if w[1].1 < w[0].1 {
            down += 1;
        }
    }
    let bottom_first = if up > 3 * down {
        true
    } else if down > 3 * up {
        false
    } else {
        return Err(format!("cannot tell which way the rings go ({up} steps up, {down} down in elevation)"));
    };
    report.rings_found = means.len();
    let mut wishes = Vec::with_capacity(usable.len());
    for k in usable.iter() {
        let g = rings[k as usize] as usize;
        let row = if bottom_first { g } else { n - 1 - g };
        let p = points[k as usize].xyz();
        wishes.push(Wish { row: row as u32, steps: rows.column_steps(rows.beam_azimuth(p, row), row) });
    }
    Ok(wishes)
}
