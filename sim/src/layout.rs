//! How a rig's sensors are merged into one ordered grid, so that a cell's 8 grid neighbours are its
//! physical neighbours.
//!
//! Rule:
//! - **Rows**: every (sensor, ring) pair is one merged row; rows are sorted by the ring's elevation
//!   in the vehicle frame (the elevation of its middle fired beam after the mount rotation), lowest
//!   first. A 4-LUX roof rig thus gives 16 rows with the layers of the four sensors interleaved.
//! - **Columns**: each sensor column has a vehicle-frame azimuth: the mount's yaw plus the column's
//!   nominal azimuth (mount pitch and roll are ignored here, so equally yawed sensors share columns). Columns are sorted by azimuth, decreasing (clockwise), starting at sensor
//!   0's column 0. Columns of different sensors whose azimuths agree within half the finer of their
//!   steps share a merged column (identical forward LUX share all columns); otherwise each gets its
//!   own merged column.
//! - Cells a sensor does not cover stay in the grid as no-return cells (sensor id `u8::MAX`). Where
//!   sensors' columns do not line up (front and rear LUX of the highway rig look in opposite
//!   directions), the grid holds both sets of columns side by side and each row is populated only
//!   in the columns of its own sensor; the other cells are empty.
//!
//! For a single sensor the layout is the identity: its own grid is already ordered.

use crate::rig::Rig;
use crate::sensor::ScanPattern;

/// The merged grid of a rig and where each sensor cell lands in it.
#[derive(Clone, Debug, PartialEq)]
pub struct RigLayout {
    /// Merged rows.
    pub rows: usize,
    /// Merged columns.
    pub cols: usize,
    /// `row_of[sensor][ring]`: merged row of a sensor ring.
    pub row_of: Vec<Vec<usize>>,
    /// `col_of[sensor][column]`: merged column of a sensor column.
    pub col_of: Vec<Vec<usize>>,
}

fn wrap_tau(a: f32) -> f32 {
    a.rem_euclid(std::f32::consts::TAU)
}

impl RigLayout {
    /// Computes the layout of `rig` whose sensors have the firing patterns `patterns`.
    pub fn new(rig: &Rig, patterns: &[ScanPattern]) -> Self {
        // Rows: vehicle-frame elevation of each ring.
        let mut rings: Vec<(f32, usize, usize)> = Vec::new();
        for (s, (ms, p)) in rig.sensors.iter().zip(patterns).enumerate() {
            let rot = ms.mount.vehicle_from_sensor().matrix3;
            for r in 0..p.rows {
                let fired: Vec<_> = (0..p.cols).filter_map(|c| p.at(r, c)).collect();
                let elev = fired.get(fired.len() / 2).map_or(p.row_elevation_rad[r], |f| {
                    let d = rot * f.dir_in_sensor;
                    d.z.clamp(-1.0, 1.0).asin()
                });
                rings.push((elev, s, r));
            }
        }
        // Stable sort keeps sensor order for equal elevations (and a single sensor's own row order).
        rings.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut row_of: Vec<Vec<usize>> = patterns.iter().map(|p| vec![0; p.rows]).collect();
        for (merged, &(_, s, r)) in rings.iter().enumerate() {
            row_of[s][r] = merged;
        }

        // Columns: vehicle-frame azimuth, measured clockwise from sensor 0's column 0.
        // A column's vehicle azimuth is the mount's yaw plus the column's nominal azimuth: pitch and
        // roll of the mount skew the flanks slightly (0.45 deg at 50 deg azimuth for 10 deg of pitch),
        // but the same columns of equally yawed sensors stay one merged column.
        let azimuth = |s: usize, c: usize| rig.sensors[s].mount.yaw_deg.to_radians() + patterns[s].col_azimuth_rad[c];
        let step = |s: usize| {
            let p = &patterns[s];
            if p.cols < 2 {
                return std::f32::consts::TAU;
            }
            (0..p.cols - 1)
                .map(|c| wrap_tau(p.col_azimuth_rad[c] - p.col_azimuth_rad[c + 1]))
                .fold(f32::INFINITY, f32::min)
                .max(1e-6)
        };
        let start = if patterns.first().is_some_and(|p| p.cols > 0) { azimuth(0, 0) } else { 0.0 };
        let mut cols: Vec<(f32, usize, usize)> = Vec::new();
        for (s, p) in patterns.iter().enumerate() {
            for c in 0..p.cols {
                // Keys just below 2*pi (a column a hair left of column 0) count as 0.
                let mut key = wrap_tau(start - azimuth(s, c) + 1e-5) - 1e-5;
                if key < 0.0 {
                    key = 0.0;
                }
                cols.push((key, s, c));
            }
        }
        cols.sort_by(|a, b| a.0.total_cmp(&b.0));
        let steps: Vec<f32> = (0..patterns.len()).map(step).collect();
        let mut col_of: Vec<Vec<usize>> = patterns.iter().map(|p| vec![0; p.cols]).collect();
        let mut merged = 0usize;
        let mut group_key = f32::NEG_INFINITY;
        let mut group_sensors: Vec<usize> = Vec::new();
        let mut group_step = f32::INFINITY;
        for (i, &(key, s, c)) in cols.iter().enumerate() {
            let tol = 0.5 * group_step.min(steps[s]);
            let joins = i > 0 && key - group_key <= tol && !group_sensors.contains(&s);
            if !joins {
                if i > 0 {
                    merged += 1;
                }
                group_key = key;
                group_sensors.clear();
                group_step = steps[s];
            }
            group_sensors.push(s);
            group_step = group_step.min(steps[s]);
            col_of[s][c] = merged;
        }
        let n_cols = if cols.is_empty() { 0 } else { merged + 1 };
        Self { rows: rings.len(), cols: n_cols, row_of, col_of }
    }
}

/// The ordering rule in one sentence (written into manifests).
pub const ORDERING: &str = "row-major grid; rows sorted by ring elevation in the vehicle frame (row 0 lowest); \
columns sorted by vehicle azimuth, decreasing (clockwise) from sensor 0's first column; columns of sensors that \
agree within half a step are shared; uncovered cells are no-return cells; echo plane k occupies rows k*R..(k+1)*R";

/// Marks a merged column that a sensor does not cover in [`RigLayout::sensor_col_of`].
pub const NO_COLUMN: u32 = u32::MAX;

impl RigLayout {
    /// The inverse of `col_of[sensor]`: for every merged column, the sensor column that lands there,
    /// or [`NO_COLUMN`]. (A sensor's columns never share a merged column, so the inverse exists.)
    pub fn sensor_col_of(&self, sensor: usize) -> Vec<u32> {
        let mut inverse = vec![NO_COLUMN; self.cols];
        for (c, &mc) in self.col_of[sensor].iter().enumerate() {
            inverse[mc] = c as u32;
        }
        inverse
    }
}
