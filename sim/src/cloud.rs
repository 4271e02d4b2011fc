//! The ordered labelled cloud: a rows x columns grid per frame in which every cell, return or not,
//! carries its ring, column, sensor and time, and returns carry position, range, intensity, echo,
//! labels and the true surface normal.
//!
//! Storage is one array per field (structure of arrays), index `(plane * rows + row) * cols + col`.
//! Plane 0 holds each shot's first echo; planes 1.. hold second and third echoes where the sensor
//! reports them (multi-echo LUX), so `planes == 1` for most sensors.

use glam::Vec3;

use crate::scene::SemanticClass;

/// One frame of an ordered, labelled LiDAR cloud.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct OrderedCloud {
    /// Grid rows (rings, sorted by elevation, row 0 lowest).
    pub rows: usize,
    /// Grid columns (sorted by azimuth, column 0 left-most).
    pub cols: usize,
    /// Echo planes (1 unless the sensor reports multiple echoes).
    pub planes: usize,
    /// Position in the vehicle frame at the frame's reference time, metres; NaN where no return.
    pub point_in_vehicle: Vec<Vec3>,
    /// Measured range from the beam origin, metres; NaN where no return.
    pub range_m: Vec<f32>,
    /// Intensity in `[0, 1]`; 0 where no return.
    pub intensity: Vec<f32>,
    /// The sensor's own ring (layer, laser) index of the cell.
    pub ring: Vec<u16>,
    /// The sensor's own column index of the cell.
    pub column: Vec<u32>,
    /// Sensor id (index into the rig); `u8::MAX` where no sensor covers the cell.
    pub sensor: Vec<u8>,
    /// Shot time, seconds since the start of the scan (frame `k` starts at `k * period`).
    pub time_s: Vec<f64>,
    /// Echo number of the return (0 = first); 0 where no return.
    pub echo: Vec<u8>,
    /// Semantic class of the surface hit; 0 (unlabeled) where no return.
    pub label: Vec<SemanticClass>,
    /// Instance id of the surface hit; 0 for stuff and where no return.
    pub instance: Vec<u32>,
    /// Ground truth: whether the surface hit is ground.
    pub ground: Vec<bool>,
    /// True surface normal at the hit, vehicle frame, unit; zero where no return.
    pub normal: Vec<Vec3>,
}

/// Fields that a cloud is known to hold at their [`OrderedCloud::reset_as_grid`] values in every
/// cell, so that it leaves them as they are (`false`: reset it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct KnownFields {
    /// `ring` and `column` hold every cell's row and column of the cloud's current shape (used only
    /// where the shape stays the same).
    pub grid: bool,
    /// `time_s` is 0 everywhere.
    pub time_s: bool,
    /// `echo` is 0 everywhere.
    pub echo: bool,
    /// `label` is unlabeled and `ground` false everywhere.
    pub label: bool,
    /// `instance` is 0 everywhere.
    pub instance: bool,
    /// `normal` is zero everywhere.
    pub normal: bool,
}

/// A vector of `n` copies of `value`, written by the rayon pool.
fn filled<T: Clone + Send + Sync>(value: T, n: usize) -> Vec<T> {
    use rayon::prelude::*;
    let mut v = Vec::with_capacity(n);
    v.par_extend(rayon::iter::repeat_n(value, n));
    v
}

/// `Vec3::NAN` in every entry of `points`, four entries per 48-byte copy: the compiler writes
/// those as whole vector stores, where a fill writes each 12-byte entry as two stores (sampled
/// on KITTI frames: the grid's reset went from 1.6 to 1.2 % of the time of read, order and
/// classify).
fn fill_nan(points: &mut [Vec3]) {
    let mut quads = points.chunks_exact_mut(4);
    for q in &mut quads {
        q.copy_from_slice(&[Vec3::NAN; 4]);
    }
    quads.into_remainder().fill(Vec3::NAN);
}

impl OrderedCloud {
    /// A grid of `planes * rows * cols` no-return cells (sensor `u8::MAX`, time 0). The fields are
    /// filled in parallel (a 128 x 2048 grid is 14 MB).
    pub fn empty(rows: usize, cols: usize, planes: usize) -> Self {
        let n = rows * cols * planes;
        Self {
            rows,
            cols,
            planes,
            point_in_vehicle: filled(Vec3::NAN, n),
            range_m: filled(f32::NAN, n),
            intensity: filled(0.0, n),
            ring: filled(0, n),
            column: filled(0, n),
            sensor: filled(u8::MAX, n),
            time_s: filled(0.0, n),
            echo: filled(0, n),
            label: filled(SemanticClass::UNLABELED, n),
            instance: filled(0, n),
            ground: filled(false, n),
            normal: filled(Vec3::ZERO, n),
        }
    }

    /// Makes this a grid of `planes * rows * cols` no-return cells, as [`OrderedCloud::empty`]
    /// makes them, keeping its buffers: a cloud refilled frame after frame allocates nothing once
    /// its buffers are large enough (on one thread, where `empty`'s parallel fill does not pay).
    ///
    /// ```
    /// let mut cloud = sim::OrderedCloud::empty(2, 3, 1);
    /// cloud.range_m[4] = 7.5;
    /// cloud.sensor[4] = 0;
    /// cloud.reset(4, 3, 1);
    /// assert_eq!((cloud.rows, cloud.len(), cloud.returns()), (4, 12, 0));
    /// assert!(cloud.sensor.iter().all(|&s| s == u8::MAX));
    /// ```
    pub fn reset(&mut self, rows: usize, cols: usize, planes: usize) {
        self.reshape(rows, cols, planes);
        self.reset_cells(0..self.len());
    }

    /// Gives every field `planes * rows * cols` entries without setting them: the entries kept
    /// from the previous frame hold its values, new ones the no-return values. For readers that
    /// then write every entry of every field (a cloud refilled frame after frame writes each
    /// entry once instead of twice).
    pub(crate) fn reshape(&mut self, rows: usize, cols: usize, planes: usize) {
        let n = rows * cols * planes;
        (self.rows, self.cols, self.planes) = (rows, cols, planes);
        self.point_in_vehicle.resize(n, Vec3::NAN);
        self.range_m.resize(n, f32::NAN);
        self.intensity.resize(n, 0.0);
        self.ring.resize(n, 0);
        self.column.resize(n, 0);
        self.sensor.resize(n, u8::MAX);
        self.time_s.resize(n, 0.0);
        self.echo.resize(n, 0);
        self.label.resize(n, SemanticClass::UNLABELED);
        self.instance.resize(n, 0);
        self.ground.resize(n, false);
        self.normal.resize(n, Vec3::ZERO);
    }

    /// [`OrderedCloud::reset`] for a cloud that is refilled frame after frame: no-return cells
    /// whose `ring` is their row and `column` their column (what an orderer gives every cell),
    /// except that the fields `known` marks are not written. Those must hold these values in every
    /// cell already (the caller's knowledge: a refill that never writes them, a grid of the same
    /// shape); entries that a larger grid adds get them. A KITTI frame's grid (64 x 2,170) is 7.6 MB
    /// of fields, and more than half of it are such fields: ordering took 0.2 ms less without
    /// rewriting them.
    ///
    /// ```
    /// use sim::cloud::KnownFields;
    /// let mut cloud = sim::OrderedCloud::empty(2, 3, 1);
    /// (cloud.range_m[4], cloud.time_s[4]) = (7.5, 0.1);
    /// cloud.reset_as_grid(4, 3, 1, KnownFields::default());
    /// assert_eq!((cloud.rows, cloud.len(), cloud.returns()), (4, 12, 0));
    /// assert!(cloud.time_s.iter().all(|&t| t == 0.0));
    /// assert_eq!((cloud.ring[7], cloud.column[7]), (2, 1));
    /// // A field marked as known is trusted, not written.
    /// cloud.time_s[4] = 0.2;
    /// cloud.reset_as_grid(4, 3, 1, KnownFields { time_s: true, ..KnownFields::default() });
    /// assert_eq!(cloud.time_s[4], 0.2);
    /// ```
    pub fn reset_as_grid(&mut self, rows: usize, cols: usize, planes: usize, known: KnownFields) {
        let n = rows * cols * planes;
        let same_grid = known.grid && (self.rows, self.cols, self.planes, self.len()) == (rows, cols, planes, n);
        self.reshape(rows, cols, planes);
        fill_nan(&mut self.point_in_vehicle[..n]);
        self.range_m[..n].fill(f32::NAN);
        self.intensity[..n].fill(0.0);
        self.sensor[..n].fill(u8::MAX);
        if cols > 0 && !same_grid {
            let grid = self.ring.chunks_exact_mut(cols).zip(self.column.chunks_exact_mut(cols));
            for (ring_index, (ring, column)) in grid.enumerate() {
                ring.fill((ring_index % rows.max(1)) as u16);
                for (c, v) in column.iter_mut().enumerate() {
                    *v = c as u32;
                }
            }
        }
        let KnownFields { time_s, echo, label, instance, normal, .. } = known;
        if !time_s {
            self.time_s.fill(0.0);
        }
        if !echo {
            self.echo.fill(0);
        }
        if !label {
            self.label.fill(SemanticClass::UNLABELED);
            self.ground.fill(false);
        }
        if !instance {
            self.instance.fill(0);
        }
        if !normal {
            self.normal.fill(Vec3::ZERO);
        }
    }

    /// Sets cells `range` back to no-return cells (as [`OrderedCloud::empty`] makes them).
    pub fn reset_cells(&mut self, range: std::ops::Range<usize>) {
        fill_nan(&mut self.point_in_vehicle[range.clone()]);
        self.range_m[range.clone()].fill(f32::NAN);
        self.intensity[range.clone()].fill(0.0);
        self.ring[range.clone()].fill(0);
        self.column[range.clone()].fill(0);
        self.sensor[range.clone()].fill(u8::MAX);
        self.time_s[range.clone()].fill(0.0);
        self.echo[range.clone()].fill(0);
        self.label[range.clone()].fill(SemanticClass::UNLABELED);
        self.instance[range.clone()].fill(0);
        self.ground[range.clone()].fill(false);
        self.normal[range].fill(Vec3::ZERO);
    }

    /// Number of cells (`planes * rows * cols`).
    pub fn len(&self) -> usize {
        self.point_in_vehicle.len()
    }

    /// Whether the grid has no cells.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Cell index of `(plane, row, col)`.
    #[inline]
    pub fn index(&self, plane: usize, row: usize, col: usize) -> usize {
        (plane * self.rows + row) * self.cols + col
    }

    /// Whether cell `i` holds a return.
    #[inline]
    pub fn has_return(&self, i: usize) -> bool {
        self.range_m[i].is_finite()
    }

    /// Number of cells with a return.
    pub fn returns(&self) -> usize {
        self.range_m.iter().filter(|r| r.is_finite()).count()
    }

    /// Number of returns on ground.
    pub fn ground_returns(&self) -> usize {
        (0..self.len()).filter(|&i| self.has_return(i) && self.ground[i]).count()
    }

    /// Checks that every field has `planes * rows * cols` entries.
    pub fn check_consistent(&self) -> Result<(), String> {
        let n = self.rows * self.cols * self.planes;
        let lens = [
            ("point_in_vehicle", self.point_in_vehicle.len()),
            ("range_m", self.range_m.len()),
            ("intensity", self.intensity.len()),
            ("ring", self.ring.len()),
            ("column", self.column.len()),
            ("sensor", self.sensor.len()),
            ("time_s", self.time_s.len()),
            ("echo", self.echo.len()),
            ("label", self.label.len()),
            ("instance", self.instance.len()),
            ("ground", self.ground.len()),
            ("normal", self.normal.len()),
        ];
        for (name, len) in lens {
            if len != n {
                return Err(format!(
                    "field `{name}` has {len} entries, grid {}x{}x{} needs {n}",
                    self.planes, self.rows, self.cols
                ));
            }
        }
        Ok(())
    }
}

/// `vehicle_from_sensor.transform_point3` of every finite point of `points`, in place (no-returns
/// stay as they are). Written out per coordinate in the operations of glam's `transform_point3`
/// (`((x_axis x + y_axis y) + z_axis z) + translation`, the same bits), with the no-returns put
/// back by a select: the loop vectorizes, where a call per point and a branch did not.
pub fn transform_returns(vehicle_from_sensor: glam::Affine3A, points: &mut [glam::Vec3]) {
    let m = vehicle_from_sensor.matrix3;
    let (xa, ya, za, t) = (m.x_axis, m.y_axis, m.z_axis, vehicle_from_sensor.translation);
    for p in points {
        let q = glam::Vec3::new(
            ((xa.x * p.x + ya.x * p.y) + za.x * p.z) + t.x,
            ((xa.y * p.x + ya.y * p.y) + za.y * p.z) + t.y,
            ((xa.z * p.x + ya.z * p.y) + za.z * p.z) + t.z,
        );
        *p = if p.is_finite() { q } else { *p };
    }
}

#[cfg(test)]
mod tests {
    use glam::{Affine3A, Vec3};

    #[test]
    fn transform_returns_gives_transform_point3_bits_and_keeps_no_returns() {
        let t = Affine3A::from_rotation_z(0.7)
            * Affine3A::from_rotation_x(-0.1)
            * Affine3A::from_translation(Vec3::new(1.3, -0.2, 1.85));
        let mut points: Vec<Vec3> = (0..1000)
            .map(|i| Vec3::new(i as f32 * 0.37 - 150.0, (i % 17) as f32 * -2.1, (i % 5) as f32 * 0.3 - 0.7))
            .collect();
        points[3] = Vec3::NAN;
        points[7] = Vec3::new(1.0, f32::INFINITY, 0.0);
        let before = points.clone();
        super::transform_returns(t, &mut points);
        for (k, (p, q)) in before.iter().zip(&points).enumerate() {
            let want = if p.is_finite() { t.transform_point3(*p) } else { *p };
            let bits = |v: &Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
            assert_eq!(bits(q), bits(&want), "point {k}");
        }
    }

    /// Grids of every length modulo 4 (the fill's whole quads and its remainder), reset after a
    /// frame of returns, hold no return in any cell; a reset of a range leaves the cells outside it.
    #[test]
    fn resets_clear_every_point_whole_quads_and_remainder() {
        for (rows, cols) in [(1, 1), (2, 3), (3, 3), (5, 7), (4, 4)] {
            let mut cloud = super::OrderedCloud::empty(rows, cols, 1);
            cloud.point_in_vehicle.iter_mut().enumerate().for_each(|(i, p)| *p = Vec3::splat(i as f32 + 1.0));
            cloud.reset_as_grid(rows, cols, 1, super::KnownFields::default());
            assert_eq!(cloud.point_in_vehicle.len(), rows * cols);
            assert!(cloud.point_in_vehicle.iter().all(|p| p.is_nan()), "{rows} x {cols}");
            cloud.point_in_vehicle.iter_mut().for_each(|p| *p = Vec3::ONE);
            cloud.reset_cells(1..rows * cols);
            assert_eq!(cloud.point_in_vehicle[0], Vec3::ONE);
            let nan = cloud.point_in_vehicle[1..].iter().filter(|p| p.x.is_nan() && p.y.is_nan() && p.z.is_nan());
            assert_eq!(nan.count(), rows * cols - 1, "{rows} x {cols}");
        }
    }
}
