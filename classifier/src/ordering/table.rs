//! The beam-table path, for clouds whose point order says nothing (shuffled, merged): each point's
//! row is the beam that passes closest to it once the row's origin offsets are undone
//! ([`TableRows::nearest_row`]); its column is the beam azimuth ([`TableRows::beam_azimuth`]).
//! Points beyond the table's lowest or highest beam stay in the edge row and are counted.

use glam::Vec3;

use super::beam_table::TableRows;
use super::placement::Wish;
use super::report::OrderingReport;

/// The wish of every point in `valid` (indices of usable points) from the table alone.
pub(crate) fn table_wishes(points: &[Vec3], valid: &[u32], rows: &TableRows, report: &mut OrderingReport) -> Vec<Wish> {
    let mut wishes = Vec::with_capacity(valid.len());
    for &k in valid {
        let p = points[k as usize];
        let (row, _, outside) = rows.nearest_row(p);
        report.outside += usize::from(outside);
        let steps = rows.column_steps(rows.beam_azimuth(p, row));
        wishes.push(Wish { point: k, row: row as u32, steps });
    }
    wishes
}
