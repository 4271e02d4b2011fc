//! Ordering recovery: puts an unordered cloud (e.g. a KITTI `.bin` from an HDL-64E) back into
//! ring x column order from a beam table, so the method runs on clouds from other sources
//! (the paper: "it can be easily computed from the physical sensor layout").
//!
//! Each point's elevation `atan2(z, hypot(x, y))` in the sensor frame picks the row of the nearest
//! table elevation (rows sorted up, row 0 lowest); points farther than half the local beam gap
//! beyond the table's lowest or highest beam are dropped. Its azimuth `atan2(y, x)` picks the
//! column: column 0 is centred on `azimuth_left_rad` and azimuth decreases by `azimuth_step_rad`
//! per column (the `sim::OrderedCloud` convention), wrapping for a full turn. When two points fall
//! into one cell the one closer to the cell's azimuth centre stays and the other moves to the
//! adjacent column on its side if that cell stays free, else it is dropped (counted). Per-laser origin offsets (HDL-64E) are ignored: they shift elevations by far less
//! than the beam gap beyond a few metres.

use glam::{Affine3A, Vec3};
use sim::{OrderedCloud, SemanticClass};

use crate::error::{ClassifyError, Result, is_valid};

/// The physical layout needed to order a cloud.
#[derive(Clone, Debug, PartialEq)]
pub struct BeamTable {
    /// Elevation of each beam in the sensor frame, radians (any order; rows are sorted up).
    pub elevations_rad: Vec<f32>,
    /// Columns per frame.
    pub cols: usize,
    /// Azimuth of the centre of column 0, radians.
    pub azimuth_left_rad: f32,
    /// Azimuth step per column, radians (> 0; azimuth decreases with the column).
    pub azimuth_step_rad: f32,
    /// Whether the columns cover a full turn (wrap).
    pub full_turn: bool,
}

impl BeamTable {
    /// A spinning sensor: `cols` columns over a full turn, column 0 just right of azimuth +pi.
    pub fn spinning(elevations_rad: Vec<f32>, cols: usize) -> Self {
        let step = std::f32::consts::TAU / cols.max(1) as f32;
        Self {
            elevations_rad,
            cols,
            azimuth_left_rad: std::f32::consts::PI - 0.5 * step,
            azimuth_step_rad: step,
            full_turn: true,
        }
    }

    /// The HDL-64E S2 nominal beam table (64 lasers from +2 to -24.8 degrees: the upper block at
    /// 1/3 degree, the lower at 1/2 degree) with `cols` columns (KITTI: about 2083 at 10 Hz).
    pub fn hdl64e(cols: usize) -> Self {
        let mut e = Vec::with_capacity(64);
        for i in 0..32 {
            e.push((2.0 - i as f32 / 3.0).to_radians());
        }
        for i in 0..32 {
            e.push((-8.83 - i as f32 * 0.5).to_radians());
        }
        Self::spinning(e, cols)
    }

    fn validate(&self) -> Result<Vec<f32>> {
        if self.elevations_rad.len() < 2 || self.elevations_rad.len() > u16::MAX as usize {
            return Err(ClassifyError::Ordering(format!(
                "beam table has {} elevations, needs 2 ..= 65535",
                self.elevations_rad.len()
            )));
        }
        if self.cols < 2 || self.cols > 1 << 20 {
            return Err(ClassifyError::Ordering(format!("beam table has {} columns, needs 2 ..= 2^20", self.cols)));
        }
        if !(self.azimuth_step_rad.is_finite() && self.azimuth_step_rad > 0.0 && self.azimuth_left_rad.is_finite()) {
            return Err(ClassifyError::Ordering("azimuth step must be finite and > 0, left azimuth finite".into()));
        }
        let mut e = self.elevations_rad.clone();
        if e.iter().any(|x| !x.is_finite()) {
            return Err(ClassifyError::Ordering("beam table has a non-finite elevation".into()));
        }
        e.sort_by(f32::total_cmp);
        if e.windows(2).any(|w| w[1] - w[0] <= 0.0) {
            return Err(ClassifyError::Ordering("beam table has two beams at the same elevation".into()));
        }
        Ok(e)
    }
}

/// What ordering did with the points.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OrderingReport {
    /// Cell index of each input point, `None` for points dropped (outside the table, collision, NaN).
    pub cell_of_point: Vec<Option<u32>>,
    /// Points placed in the grid.
    pub placed: usize,
    /// Points dropped because their cell was taken by a better-centred point.
    pub collisions: usize,
    /// Points dropped for NaN coordinates, zero range or an elevation outside the table.
    pub outside: usize,
}

/// Orders `points_in_sensor` (with optional labels) into a grid; points go to the vehicle frame
/// through `vehicle_from_sensor`. Labels make the cloud's `label` and `ground` fields.
pub fn order_points(
    points_in_sensor: &[Vec3],
    labels: Option<&[SemanticClass]>,
    table: &BeamTable,
    vehicle_from_sensor: Affine3A,
) -> Result<(OrderedCloud, OrderingReport)> {
    let elev = table.validate()?;
    if labels.is_some_and(|l| l.len() != points_in_sensor.len()) {
        return Err(ClassifyError::Ordering("labels and points differ in length".into()));
    }
    let (rows, cols) = (elev.len(), table.cols);
    let mut cloud = OrderedCloud::empty(rows, cols, 1);
    for r in 0..rows {
        for c in 0..cols {
            cloud.ring[r * cols + c] = r as u16;
            cloud.column[r * cols + c] = c as u32;
        }
    }
    let mut owner: Vec<Option<(u32, f32)>> = vec![None; rows * cols];
    let mut owner_alt: Vec<Option<usize>> = vec![None; rows * cols];
    let mut losers: Vec<(u32, Option<usize>)> = Vec::new();
    let mut report = OrderingReport { cell_of_point: vec![None; points_in_sensor.len()], ..OrderingReport::default() };
    for (k, &p) in points_in_sensor.iter().enumerate() {
        let h = (p.x * p.x + p.y * p.y).sqrt();
        if !is_valid(p) || p.length_squared() == 0.0 {
            report.outside += 1;
            continue;
        }
        let e = p.z.atan2(h);
        let row = match elev.binary_search_by(|x| x.total_cmp(&e)) {
            Ok(i) => i,
            Err(i) => {
                if i == 0 {
                    if elev[0] - e > 0.5 * (elev[1] - elev[0]) {
                        report.outside += 1;
                        continue;
                    }
                    0
                } else if i == rows {
                    if e - elev[rows - 1] > 0.5 * (elev[rows - 1] - elev[rows - 2]) {
                        report.outside += 1;
                        continue;
                    }
                    rows - 1
                } else if e - elev[i - 1] < elev[i] - e {
                    i - 1
                } else {
                    i
                }
            }
        };
        let az = p.y.atan2(p.x);
        let mut steps = (table.azimuth_left_rad - az) / table.azimuth_step_rad;
        if table.full_turn {
            let turn = std::f32::consts::TAU / table.azimuth_step_rad;
            steps = steps.rem_euclid(turn);
        }
        let mut col = steps.round();
        if table.full_turn && col as usize >= cols {
            col -= cols as f32;
        }
        if col < 0.0 || col as usize >= cols {
            report.outside += 1;
            continue;
        }
        let off = (steps - col).abs().min((steps - col - cols as f32).abs());
        let cell = row * cols + col as usize;
        // The adjacent column on the point's side, for a second pass.
        let alt = if steps >= col { col as isize + 1 } else { col as isize - 1 };
        let alt = if table.full_turn {
            Some(alt.rem_euclid(cols as isize) as usize)
        } else {
            usize::try_from(alt).ok().filter(|&a| a < cols)
        };
        let alt_cell = alt.map(|a| row * cols + a);
        match owner[cell] {
            Some((prev, prev_off)) if prev_off <= off => {
                let _ = prev;
                losers.push((k as u32, alt_cell));
                continue;
            }
            Some((prev, _)) => {
                report.cell_of_point[prev as usize] = None;
                report.placed -= 1;
                losers.push((prev, owner_alt[cell]));
            }
            None => {}
        }
        owner[cell] = Some((k as u32, off));
        owner_alt[cell] = alt_cell;
        report.cell_of_point[k] = Some(cell as u32);
        report.placed += 1;
    }
    // Second pass: a point that lost its cell moves to the adjacent column on its side if that is
    // free (staggered firing times and per-laser azimuth offsets put two points into one column
    // now and then); otherwise it is dropped as a collision.
    for (k, alt_cell) in losers {
        match alt_cell {
            Some(c) if owner[c].is_none() => {
                owner[c] = Some((k, 1.0));
                report.cell_of_point[k as usize] = Some(c as u32);
                report.placed += 1;
            }
            _ => report.collisions += 1,
        }
    }
    for (cell, o) in owner.iter().enumerate() {
        if let Some((k, _)) = *o {
            let p = points_in_sensor[k as usize];
            cloud.point_in_vehicle[cell] = vehicle_from_sensor.transform_point3(p);
            cloud.range_m[cell] = p.length();
            cloud.sensor[cell] = 0;
            if let Some(l) = labels {
                cloud.label[cell] = l[k as usize];
                cloud.ground[cell] = l[k as usize].is_ground();
            }
        }
    }
    Ok((cloud, report))
}
