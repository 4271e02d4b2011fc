//! What orders files from other tools: the beam table and the mount that takes sensor-frame points
//! to the vehicle frame, from a single-sensor rig or the sensor's own calibration file; without
//! either, a flat cloud's rings and columns are recovered from its data and its sensor named where
//! a known table matches ([`super::recover`]); and the ordering of one KITTI-layout frame with it
//! ([`SensorSetup::order_kitti`]): a scan-ordered or shuffled `.bin`, or an **organized** one, as
//! Ouster clouds converted to `.bin` are stored (every cell of the sensor's image, no-returns as
//! `0, 0, 0`, row by row or column by column).

use std::path::Path;

use glam::{Affine3A, Vec3};
use sim::SemanticClass;

use super::{
    BeamTable, Calibration, CloudBuffer, InputPoint, OrderingReport, PathChoice, PointAttributes, RecoveredOrder,
    UnfoldParams, order_cloud_into,
};
use crate::error::{ClassifyError, Result};

/// Columns of the default KITTI beam table: real HDL-64E frames in KITTI hold up to about 2,160
/// points per laser (the head turns a little slower than 10 Hz), more than the 2,083 of an exact
/// 10 Hz turn, so 2,083 columns would make every ring share cells.
pub const KITTI_COLUMNS: usize = 2170;

/// Beam counts an organized KITTI-layout frame is looked for with when no sensor is given, most
/// first (an image read with too many rows repeats its elevations and is not taken).
const ORGANIZED_BEAMS_UNGIVEN: [usize; 4] = [128, 64, 32, 16];

/// Nearest points whose elevations the organized-layout test reads, metres: nearer, a beam's
/// origin off the spin axis and a motion-compensated cloud's shift (nuScenes: up to half a metre
/// per sweep) move a point's elevation by degrees, and nearer still lie the no-returns that
/// compensation moved off 0, 0, 0.
const ORGANIZED_MIN_RANGE_M: f32 = 1.0;

/// Columns of a candidate organized layout whose points the test reads (every k-th column, over
/// the whole image): 256 points per row are plenty for a row's mean and spread, and a flat cloud
/// mixes its rows all over the file.
const ORGANIZED_SAMPLED_COLUMNS: usize = 256;

/// Largest mean spread of the elevations within the rows of a candidate organized layout, degrees:
/// an organized image's row is one beam (spread about 0.1 deg with the beams' own azimuth offsets
/// and noise), a wrong layout mixes beams (spread of several degrees).
const ORGANIZED_ROW_SPREAD_DEG: f32 = 0.5;

/// The beam table and mount that order files from other tools.
#[derive(Clone, Debug)]
pub struct SensorSetup {
    /// The beam table.
    pub table: BeamTable,
    /// Mount taking the file's sensor-frame points to the vehicle frame (identity without a rig).
    pub vehicle_from_sensor: Affine3A,
    /// Lasers of a calibration file, checked against organized clouds' rows.
    pub calibrated_lasers: Option<usize>,
    /// Whether the sensor was not given (no rig, no calibration file): a flat cloud is then ordered
    /// on the sensor recovered from its data ([`super::recover`]: from its point order, or from its
    /// ring field where it has one), `table` (the HDL-64E nominal one) serving only to detect
    /// organized KITTI-layout frames of 64 rows.
    pub recover: bool,
    /// `table` holds the lasers of a calibration file that gives no column count (Velodyne's
    /// YAML, Hesai's angle-correction CSV), and no rig was given: flat clouds are ordered on its
    /// lasers with the point order, the echoes and the columns recovered from the data
    /// ([`super::recover`]), as for a sensor not given, never on a default column count.
    pub columns_from_data: bool,
}

impl Default for SensorSetup {
    /// No sensor given: flat clouds (with or without a ring field) are ordered on the sensor
    /// recovered from their data; the HDL-64E nominal table with [`KITTI_COLUMNS`] columns orders
    /// organized 64-row KITTI-layout frames; no mount (points stay in the sensor frame).
    fn default() -> Self {
        Self {
            table: BeamTable::hdl64e(KITTI_COLUMNS),
            vehicle_from_sensor: Affine3A::IDENTITY,
            calibrated_lasers: None,
            recover: true,
            columns_from_data: false,
        }
    }
}

impl SensorSetup {
    /// From a single-sensor `rig` (its beam table with origin offsets, and its mount) and a
    /// `calibration` file (the unit's own angles, replacing the rig's or the default table's; the
    /// columns from the file, else the rig, else [`KITTI_COLUMNS`]). Neither: [`SensorSetup::default`].
    ///
    /// ```
    /// use classifier::ordering::SensorSetup;
    /// let rig = sim::Rig::load("vlp16-roof")?;
    /// let setup = SensorSetup::new(Some(&rig), None)?;
    /// assert_eq!(setup.table.elevations_rad.len(), 16);
    /// assert!(setup.vehicle_from_sensor.translation.z > 1.0); // roof mount
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn new(rig: Option<&sim::Rig>, calibration: Option<&Path>) -> Result<Self> {
        let mut setup = match rig {
            Some(rig) => {
                if rig.sensors.len() != 1 {
                    return Err(ClassifyError::Ordering(format!(
                        "the rig has {} sensors; ordering a file from another tool needs a single-sensor rig",
                        rig.sensors.len()
                    )));
                }
                let s = &rig.sensors[0];
                // KITTI files and the drivers' clouds of a single-sensor rig hold sensor-frame points.
                Self {
                    table: BeamTable::from_spec(&s.spec)?,
                    vehicle_from_sensor: s.mount.vehicle_from_sensor(),
                    calibrated_lasers: None,
                    recover: false,
                    columns_from_data: false,
                }
            }
            None => Self::default(),
        };
        if let Some(file) = calibration {
            let expected = rig.map(|_| setup.table.elevations_rad.len());
            let cal = Calibration::load(file, expected).map_err(|e| ClassifyError::Ordering(e.to_string()))?;
            // Columns: the file's, else the rig's, else recovered from each cloud's data (the
            // placeholder count here orders nothing).
            setup.columns_from_data = cal.columns.is_none() && rig.is_none();
            let cols = cal.columns.unwrap_or(if rig.is_some() { setup.table.cols } else { KITTI_COLUMNS });
            setup.calibrated_lasers = Some(cal.lasers.len());
            // The calibration gives the lasers; a rig given beside it, the sensor's minimum range.
            setup.table = BeamTable { min_range_m: setup.table.min_range_m, ..cal.to_table(cols) };
            setup.recover = false;
        }
        Ok(setup)
    }

    /// Orders a flat cloud (KITTI `.bin`, unorganized PCD, PLY) into `cloud` and `report`: by scan
    /// unfolding where the points are in scan order, else by the beam table. Without a sensor
    /// given ([`SensorSetup::recover`]) and without a ring field, on the sensor recovered from the
    /// points (`report.sensor`), refused ([`super::RecoveryError`]) where no order can be
    /// recovered.
    pub fn order_flat<P: InputPoint>(
        &self,
        points: &[P],
        attributes: &PointAttributes<'_>,
        cloud: &mut CloudBuffer,
        report: &mut OrderingReport,
    ) -> Result<()> {
        if self.recover || self.columns_from_data {
            let given = self.columns_from_data.then_some(&self.table);
            let to = self.vehicle_from_sensor;
            match attributes.rings {
                None => super::recover::order_recovered(points, attributes, given, to, cloud, report)?,
                Some(_) => super::recover::order_ring_field(points, attributes, given, to, cloud, report)?,
            }
        } else {
            order_cloud_into(
                points,
                attributes,
                &self.table,
                self.vehicle_from_sensor,
                PathChoice::Auto,
                &UnfoldParams::default(),
                cloud,
                report,
            )?;
        }
        self.check_fit(report)
    }

    /// Refuses an ordering where more than half the points fall in a cell an earlier point
    /// already holds (kept on a further plane, or sharing it as a second echo): a sensor gives at
    /// most two echoes per beam, so the table (a rig's, a calibration file's) is not this
    /// sensor's, or the points are not in its frame. Measured on real frames read with wrong
    /// tables: 58-97 % of their points; with their own: 1-12 %.
    fn check_fit(&self, report: &OrderingReport) -> Result<()> {
        let (kept, crowded) = (report.kept(), report.stacked + report.shared);
        if kept == 0 || 2 * crowded <= kept {
            return Ok(());
        }
        let table = if self.calibrated_lasers.is_some() {
            "the calibration file's table"
        } else if self.recover {
            "the table recovered from the data"
        } else {
            "the rig's beam table"
        };
        Err(ClassifyError::Ordering(format!(
            "{table} ({} rows x {} columns) does not fit the points: {crowded} of {kept} ({:.0} %) fall in a cell an \
             earlier point already holds, and a sensor gives at most two echoes per beam; name this sensor's rig or \
             calibration file (or neither: the sensor is then recovered from the data), with the points in its frame",
            report.sensor.as_ref().map_or(self.table.elevations_rad.len(), |s| s.rows),
            report.sensor.as_ref().map_or(self.table.cols, |s| s.columns),
            100.0 * crowded as f64 / kept as f64
        )))
    }

    /// Orders one KITTI-layout frame (`x y z intensity` records in the sensor frame, optional
    /// labels). An organized frame ([`OrganizedLayout::detect`]: a whole sensor image with
    /// `0, 0, 0` no-returns) gives every record its image row as its ring, and the points are
    /// placed by ring and azimuth in a grid of the image's columns (the ring-field path: the rows go
    /// bottom-first whichever way the file stores them, and a staggered image, whose beams fire at
    /// other azimuths in one column, comes out destaggered). Any other frame is ordered as
    /// [`SensorSetup::order_flat`] does. `report.cell_of_point` gives the cell of every record.
    pub fn order_kitti(
        &self,
        records: &[[f32; 4]],
        labels: Option<&[SemanticClass]>,
        cloud: &mut CloudBuffer,
        report: &mut OrderingReport,
    ) -> Result<()> {
        let beams = self.table.elevations_rad.len();
        // Without a sensor given, an image of any of the usual beam counts.
        let layout = if self.recover {
            OrganizedLayout::detect_first(records, &ORGANIZED_BEAMS_UNGIVEN)
        } else {
            OrganizedLayout::detect(records, beams)
        };
        let Some(layout) = layout else {
            let attributes = PointAttributes { labels, ..PointAttributes::default() };
            return self.order_flat(records, &attributes, cloud, report);
        };
        if let Some(n) = self.calibrated_lasers
            && n != layout.rows
        {
            return Err(ClassifyError::Ordering(format!(
                "an organized frame of {} rows, but the calibration file has {n} lasers",
                layout.rows
            )));
        }
        let rings: Vec<u16> = (0..records.len()).map(|k| (layout.cell_of_record(k) / layout.cols) as u16).collect();
        if self.recover {
            // The image's rows are the rings; the table is the one they show.
            let attributes = PointAttributes { labels, rings: Some(&rings), ..PointAttributes::default() };
            self.order_flat(records, &attributes, cloud, report)?;
            if let Some(sensor) = report.sensor.as_mut() {
                sensor.order =
                    if layout.column_major { RecoveredOrder::ImageColumns } else { RecoveredOrder::ImageRows };
            }
            return Ok(());
        }
        // A spinning sensor's image: its own column count over the turn (the table's beams, offsets
        // kept); another table is used as it is.
        let table = if self.table.full_turn {
            BeamTable { cols: layout.cols, ..BeamTable::spinning(Vec::new(), layout.cols) }
        } else {
            self.table.clone()
        };
        let table = BeamTable {
            elevations_rad: self.table.elevations_rad.clone(),
            azimuth_offsets_rad: self.table.azimuth_offsets_rad.clone(),
            horizontal_offsets_m: self.table.horizontal_offsets_m.clone(),
            vertical_offsets_m: self.table.vertical_offsets_m.clone(),
            min_range_m: self.table.min_range_m,
            ..table
        };
        let attributes = PointAttributes { labels, rings: Some(&rings), ..PointAttributes::default() };
        order_cloud_into(
            records,
            &attributes,
            &table,
            self.vehicle_from_sensor,
            PathChoice::Auto,
            &UnfoldParams::default(),
            cloud,
            report,
        )
    }
}

/// How an organized frame stores its image in a flat file: `rows x cols` cells, row by row (the
/// ouster-ros layout: a row is one beam) or column by column (a column is one firing, as the
/// sensor sends them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OrganizedLayout {
    /// Rows (beams).
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// Whether a column's cells are consecutive in the file.
    pub column_major: bool,
}

impl OrganizedLayout {
    /// The image cell (`row * cols + col`, file rows) of record `k`.
    pub fn cell_of_record(&self, k: usize) -> usize {
        if self.column_major {
            let (col, row) = (k / self.rows, k % self.rows);
            row * self.cols + col
        } else {
            k
        }
    }

    /// Tells whether `records` are a whole `beams`-row sensor image: their count a multiple of
    /// `beams` (at least 16 columns) and, row by row or column by column, every row holding one
    /// beam (the mean spread of its points' elevations beyond [`ORGANIZED_MIN_RANGE_M`] under
    /// [`ORGANIZED_ROW_SPREAD_DEG`], the other reading's well above). Row by row only with some
    /// `0, 0, 0` no-returns among them (a KITTI `.bin` has none); column by column, whole firings
    /// are an image with or without them.
    /// `None` for any other cloud.
    ///
    /// ```
    /// use classifier::ordering::setup::OrganizedLayout;
    /// // 4 beams x 32 columns, column by column, one no-return.
    /// let mut records = Vec::new();
    /// for c in 0..32 {
    ///     let az = c as f32 * 0.05;
    ///     for r in 0..4 {
    ///         let el = (-10.0 + 5.0 * r as f32).to_radians();
    ///         records.push([10.0 * el.cos() * az.cos(), 10.0 * el.cos() * az.sin(), 10.0 * el.sin(), 0.5]);
    ///     }
    /// }
    /// records[5] = [0.0; 4];
    /// let layout = OrganizedLayout::detect(&records, 4).unwrap();
    /// assert!(layout.column_major && layout.rows == 4 && layout.cols == 32);
    /// ```
    pub fn detect(records: &[[f32; 4]], beams: usize) -> Option<Self> {
        Self::detect_first(records, &[beams])
    }

    /// [`OrganizedLayout::detect`] for each of `beams` in turn: the first layout found.
    pub fn detect_first(records: &[[f32; 4]], beams: &[usize]) -> Option<Self> {
        let n = records.len();
        let mut candidates = beams.iter().copied().filter(|&b| b >= 2 && n.is_multiple_of(b) && n / b >= 16).peekable();
        candidates.peek()?;
        // A flat cloud in ring-major order (KITTI) whose count happens to be a multiple of `beams`
        // reads row by row as rows of about one ring each: only a cloud with no-returns in it is
        // taken for a row-by-row image. Column by column, a flat cloud's rows mix its lasers as
        // soon as one point is missing, so a cloud of whole firings is an image as it stands
        // (nuScenes, whose no-returns the ego-motion compensation moved off 0, 0, 0).
        let has_zeros = records.iter().any(|p| p[0] == 0.0 && p[1] == 0.0 && p[2] == 0.0);
        candidates.find_map(|b| Self::detect_beams(records, b, has_zeros))
    }

    /// The record of image cell (`row`, `col`) (file rows).
    fn record_of_cell(&self, row: usize, col: usize) -> usize {
        if self.column_major { col * self.rows + row } else { row * self.cols + col }
    }

    /// The layout of `beams` rows that `records` show, if any, read on up to
    /// [`ORGANIZED_SAMPLED_COLUMNS`] columns spread over the image.
    fn detect_beams(records: &[[f32; 4]], beams: usize, has_zeros: bool) -> Option<Self> {
        let cols = records.len() / beams;
        let stride = cols.div_ceil(ORGANIZED_SAMPLED_COLUMNS).max(1);
        let row_major = Self { rows: beams, cols, column_major: false };
        let column_major = Self { rows: beams, cols, column_major: true };
        // Per row of a reading: the mean and the spread of its points' elevations, degrees.
        let rows_of = |layout: &Self| -> Vec<(f64, f64)> {
            let mut sum = vec![(0.0f64, 0.0f64, 0u32); beams];
            for (row, s) in sum.iter_mut().enumerate() {
                for col in (0..cols).step_by(stride) {
                    let p = records[layout.record_of_cell(row, col)];
                    let v = Vec3::new(p[0], p[1], p[2]);
                    let d = v.length();
                    if !(d > ORGANIZED_MIN_RANGE_M && d.is_finite()) {
                        continue;
                    }
                    let el = f64::from((v.z / d).clamp(-1.0, 1.0).asin().to_degrees());
                    s.0 += el;
                    s.1 += el * el;
                    s.2 += 1;
                }
            }
            sum.iter()
                .filter(|s| s.2 >= 2)
                .map(|&(a, b, c)| {
                    let m = a / f64::from(c);
                    (m, (b / f64::from(c) - m * m).max(0.0).sqrt())
                })
                .collect()
        };
        // The mean spread within the rows; infinite where rows share their elevation (a reading
        // with too many rows: an image of fewer beams puts one beam in several rows), so that each
        // row holds one beam and each beam one row.
        let spread = |layout: &Self| -> f32 {
            let rows = rows_of(layout);
            if rows.len() < 2 {
                return f32::INFINITY;
            }
            let mut means: Vec<f64> = rows.iter().map(|r| r.0).collect();
            means.sort_by(f64::total_cmp);
            let repeated = means.windows(2).filter(|w| w[1] - w[0] < 0.05).count();
            if repeated * 10 > rows.len() {
                return f32::INFINITY;
            }
            (rows.iter().map(|r| r.1).sum::<f64>() / rows.len() as f64) as f32
        };
        // Without no-returns only the column-by-column reading can win: its spread alone decides a
        // layout that fails (the other reading's points are then not read).
        let b = spread(&column_major);
        if !has_zeros && b >= ORGANIZED_ROW_SPREAD_DEG {
            return None;
        }
        let a = spread(&row_major);
        let (best, spread_best, spread_other) =
            if has_zeros && a <= b { (row_major, a, b) } else { (column_major, b, a) };
        (spread_best < ORGANIZED_ROW_SPREAD_DEG && spread_other > 2.0 * ORGANIZED_ROW_SPREAD_DEG).then_some(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `beams x cols` image of a flat floor 1.7 m below and a wall, in `layout` order, with
    /// every 7th cell a no-return.
    fn image(beams: usize, cols: usize, column_major: bool) -> Vec<[f32; 4]> {
        let layout = OrganizedLayout { rows: beams, cols, column_major };
        let mut out = vec![[0.0f32; 4]; beams * cols];
        for (k, record) in out.iter_mut().enumerate() {
            let cell = layout.cell_of_record(k);
            let (row, col) = (cell / cols, cell % cols);
            // Row 0 is the top beam (ouster-ros order).
            let el = (15.0 - 30.0 * row as f32 / (beams - 1) as f32).to_radians();
            // Column centres of a spinning table: from just right of +pi, clockwise.
            let az = std::f32::consts::PI - (col as f32 + 0.5) * std::f32::consts::TAU / cols as f32;
            let dir = Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            let t = if dir.z < -0.01 { (1.7 / -dir.z).min(30.0) } else { 30.0 };
            let p = dir * t;
            if k % 7 != 3 {
                *record = [p.x, p.y, p.z, 0.5];
            }
        }
        out
    }

    #[test]
    fn organized_layouts_are_told_apart_and_flat_clouds_are_not_taken_for_one() {
        for column_major in [false, true] {
            let rec = image(16, 256, column_major);
            let layout = OrganizedLayout::detect(&rec, 16).expect("organized");
            assert_eq!(layout, OrganizedLayout { rows: 16, cols: 256, column_major });
            // The wrong beam count is no organized frame.
            assert_eq!(OrganizedLayout::detect(&rec, 64), None);
        }
        // Without no-returns (a KITTI frame) nothing is organized.
        let full: Vec<[f32; 4]> = image(16, 256, false).into_iter().filter(|p| p[0] != 0.0).collect();
        assert_eq!(OrganizedLayout::detect(&full, 16), None);
        // No-returns moved off 0, 0, 0 (nuScenes' ego-motion compensation): whole firings stored
        // one after another are an image; row by row, only a cloud with no-returns at 0, 0, 0 is.
        let moved = |column_major: bool| -> Vec<[f32; 4]> {
            let off_origin = |p: [f32; 4]| if p[0] == 0.0 { [0.001, -0.3, -0.003, 0.5] } else { p };
            image(16, 256, column_major).into_iter().map(off_origin).collect()
        };
        let firings = OrganizedLayout::detect(&moved(true), 16);
        assert_eq!(firings, Some(OrganizedLayout { rows: 16, cols: 256, column_major: true }));
        assert_eq!(OrganizedLayout::detect(&moved(false), 16), None);
    }

    #[test]
    fn an_image_moved_by_the_ego_motion_compensation_of_a_fast_vehicle_is_an_image() {
        // Firing by firing, every point moved by where the sensor was when it fired (a sweep at
        // 18 m/s and 20 Hz: 0.9 m behind at the first firing, at the origin at the last; the
        // real nuScenes sweep in docs/real-recordings.md moved 0.45 m). At 1.1 m the test's
        // near floor points drift too far for ORGANIZED_ROW_SPREAD_DEG.
        let (beams, cols) = (32, 1000);
        let mut records = image(beams, cols, true);
        for (k, r) in records.iter_mut().enumerate() {
            let behind = 0.9 * (1.0 - (k / beams) as f32 / (cols - 1) as f32);
            r[1] -= behind;
        }
        let found = OrganizedLayout::detect(&records, beams);
        assert_eq!(found, Some(OrganizedLayout { rows: beams, cols, column_major: true }));
    }

    #[test]
    fn firings_whole_only_up_to_a_late_missing_point_are_no_image() {
        // Every beam returns (no 0, 0, 0 anywhere), firing by firing; then two points of each of
        // the last 8 firings are dropped, as a driver drops no-returns: the count is still a
        // multiple of 16, and from there on each 16 points straddle two firings.
        let (beams, cols) = (16, 320);
        let mut records = Vec::new();
        for col in 0..cols {
            let az = std::f32::consts::PI - (col as f32 + 0.5) * std::f32::consts::TAU / cols as f32;
            for row in 0..beams {
                let el = (15.0 - 30.0 * row as f32 / (beams - 1) as f32).to_radians();
                let dir = Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
                let p = dir * if dir.z < -0.01 { (1.7 / -dir.z).min(30.0) } else { 30.0 };
                let dropped = col >= cols - 8 && (row == 5 || row == 11);
                if !dropped {
                    records.push([p.x, p.y, p.z, 0.5]);
                }
            }
        }
        assert_eq!(records.len(), (cols - 1) * beams);
        assert_eq!(OrganizedLayout::detect(&records[..(cols - 8) * beams], beams).map(|l| l.column_major), Some(true));
        assert_eq!(OrganizedLayout::detect(&records, beams), None);
    }

    #[test]
    fn an_organized_frame_is_ordered_by_its_rows_bottom_first() {
        let (beams, cols) = (16, 256);
        let table = BeamTable::spinning(
            (0..beams).map(|r| (-15.0 + 30.0 * r as f32 / (beams - 1) as f32).to_radians()).collect(),
            cols,
        );
        let setup = SensorSetup {
            table,
            vehicle_from_sensor: Affine3A::IDENTITY,
            calibrated_lasers: None,
            recover: false,
            columns_from_data: false,
        };
        for column_major in [false, true] {
            let rec = image(beams, cols, column_major);
            let (mut cloud, mut report) = (CloudBuffer::default(), OrderingReport::default());
            setup.order_kitti(&rec, None, &mut cloud, &mut report).unwrap();
            let c = cloud.cloud();
            assert_eq!((c.rows, c.cols), (beams, cols));
            assert_eq!(report.path, super::super::OrderingPath::RingField);
            let no_returns = rec.iter().filter(|p| p[0] == 0.0).count();
            assert_eq!(report.no_returns, no_returns);
            assert_eq!(c.returns(), rec.len() - no_returns);
            assert_eq!(report.placed, rec.len() - no_returns, "every point in its own cell");
            // Every record's cell holds that record's point, and row 0 is the lowest beam.
            for (k, p) in rec.iter().enumerate() {
                match report.cell_of_point[k] {
                    None => assert_eq!(p[0], 0.0),
                    Some(cell) => {
                        let q = c.point_in_vehicle[cell as usize];
                        assert_eq!(q, Vec3::new(p[0], p[1], p[2]), "record {k}");
                        let row = cell as usize / cols;
                        let file_row = OrganizedLayout { rows: beams, cols, column_major }.cell_of_record(k) / cols;
                        assert_eq!(row, beams - 1 - file_row, "record {k}");
                    }
                }
            }
        }
    }
}
