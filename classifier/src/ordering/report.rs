//! What ordering did with a cloud's points: the path taken, the cell of every input point, and how
//! many points each step placed.

use serde::Serialize;

use super::RecoveredSensor;

/// How a cloud was put into rows and columns.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OrderingPath {
    /// Scan unfolding: rings from the file's scan order (azimuth turns), columns from azimuth.
    Unfolded,
    /// The beam table: each point's row from its elevation, column from its azimuth.
    #[default]
    BeamTable,
    /// A `ring` field per point: rows from the field, columns from azimuth.
    RingField,
    /// An organized cloud: its own grid, rows put in elevation order.
    Organized,
}

impl OrderingPath {
    /// The path's name as reports print it.
    pub fn name(self) -> &'static str {
        match self {
            OrderingPath::Unfolded => "unfolded",
            OrderingPath::BeamTable => "beam-table",
            OrderingPath::RingField => "ring-field",
            OrderingPath::Organized => "organized",
        }
    }
}

/// What ordering did with the points.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct OrderingReport {
    /// The path taken.
    pub path: OrderingPath,
    /// Why the preferred path (unfolding) was not taken, where it was tried.
    pub fallback: Option<String>,
    /// Cell index (over all planes) of each input point; `None` only for skipped bad points.
    #[serde(skip)]
    pub cell_of_point: Vec<Option<u32>>,
    /// Rings found: unfolded from the scan order, or the rings that hold points of an organized
    /// cloud or of a cloud with a `ring` field (0 on the beam-table path).
    pub rings_found: usize,
    /// Points placed in the cell their row and azimuth name.
    pub placed: usize,
    /// Points whose cell was taken and that moved to a free column nearby (the adjacent one on their
    /// side, else within `placement::NEAR_COLUMNS`).
    pub moved: usize,
    /// Points with no free cell nearby, kept on a further plane of their own cell.
    pub stacked: usize,
    /// Points with no free cell nearby that share their cell (and its decision) with its point:
    /// fewer than `placement::MAX_SHARED_FRACTION` of the cloud (a turn overlapping its start).
    pub shared: usize,
    /// Points beyond the beam table's lowest or highest beam (placed in the edge row, counted here
    /// as well).
    pub outside: usize,
    /// Bad points skipped (NaN or infinite coordinates, a ring value out of range): decision 0.
    pub skipped: usize,
    /// No-return points skipped: decision 0. At (0, 0, 0), or nearer than the sensor's minimum
    /// range ([`OrderingReport::too_near`]).
    pub no_returns: usize,
    /// Of the no-returns, points nearer than the sensor's minimum range
    /// ([`super::BeamTable::min_range_m`], kept in [`OrderingReport::min_range_m`]) but not at
    /// (0, 0, 0): the sensor reports nothing there (nuScenes' motion-compensated no-returns).
    pub too_near: usize,
    /// The minimum range the points were read with, metres (0: none known).
    pub min_range_m: f32,
    /// The sensor recovered from the data, where none was given (no rig, no calibration file):
    /// named when its table matched a known one ([`super::recover`]).
    pub sensor: Option<RecoveredSensor>,
}

impl OrderingReport {
    /// Points that got a cell (placed + moved + stacked + shared).
    pub fn kept(&self) -> usize {
        self.placed + self.moved + self.stacked + self.shared
    }

    /// The line `groundtruth classify` prints for a frame ordered into `rows x cols x planes`:
    /// `ordered into R x C x P: ` and [`OrderingReport::summary`].
    pub fn grid_line(&self, rows: usize, cols: usize, planes: usize) -> String {
        format!("ordered into {rows} x {cols} x {planes}: {}", self.summary())
    }

    /// One line for the command line.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "path {}: {} points: {} in their cell, {} moved to a free column nearby, {} on a further plane, {} sharing a cell, {} skipped (bad), {} no-returns",
            self.path.name(),
            self.cell_of_point.len(),
            self.placed,
            self.moved,
            self.stacked,
            self.shared,
            self.skipped,
            self.no_returns
        );
        if self.too_near > 0 {
            s.push_str(&format!(
                " ({} of them nearer than the sensor's minimum range of {} m, not at 0, 0, 0)",
                self.too_near, self.min_range_m
            ));
        }
        if self.rings_found > 0 {
            let what = if self.path == OrderingPath::Unfolded { "rings unfolded" } else { "rings with points" };
            s.push_str(&format!(", {} {what}", self.rings_found));
        }
        if self.outside > 0 {
            s.push_str(&format!(", {} beyond the beam table (kept in the edge row)", self.outside));
        }
        if let Some(sensor) = &self.sensor {
            s.push_str(&format!("; sensor {}", sensor.summary()));
        }
        if let Some(f) = &self.fallback {
            s.push_str(&format!(" (not unfolded: {f})"));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The summary says how the rings were found: unfolded from the scan order, or read.
    #[test]
    fn summary_names_how_rings_were_found() {
        let mut report =
            OrderingReport { path: OrderingPath::Unfolded, rings_found: 64, placed: 10, ..Default::default() };
        assert!(report.summary().ends_with(", 64 rings unfolded"), "{}", report.summary());
        (report.path, report.rings_found) = (OrderingPath::Organized, 128);
        assert!(report.summary().ends_with(", 128 rings with points"), "{}", report.summary());
        (report.path, report.rings_found) = (OrderingPath::BeamTable, 0);
        assert!(!report.summary().contains("rings"), "{}", report.summary());
    }
}
