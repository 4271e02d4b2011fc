//! Writing a row's cells: per-row mutable views of a cloud's plane 0 (filled in parallel) and the
//! later echoes written after the row pass.

use glam::Vec3;

use crate::cloud::OrderedCloud;
use crate::scene::SemanticClass;

/// A return's fields, for writing a cell of a later echo plane.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cell {
    pub(super) point_in_vehicle: Vec3,
    pub(super) range_m: f32,
    pub(super) intensity: f32,
    pub(super) class: SemanticClass,
    pub(super) instance: u32,
    pub(super) normal: Vec3,
    pub(super) sensor: u8,
    pub(super) ring: u16,
    pub(super) column: u32,
    pub(super) time_s: f64,
}

impl Cell {
    pub(super) fn write(&self, cloud: &mut OrderedCloud, i: usize, echo: u8) {
        cloud.point_in_vehicle[i] = self.point_in_vehicle;
        cloud.range_m[i] = self.range_m;
        cloud.intensity[i] = self.intensity;
        cloud.label[i] = self.class;
        cloud.instance[i] = self.instance;
        cloud.ground[i] = self.class.is_ground();
        cloud.normal[i] = self.normal;
        cloud.sensor[i] = self.sensor;
        cloud.ring[i] = self.ring;
        cloud.column[i] = self.column;
        cloud.time_s[i] = self.time_s;
        cloud.echo[i] = echo;
    }
}

/// A second or later echo, written after the parallel row pass.
#[derive(Clone, Copy, Debug)]
pub(super) struct ExtraEcho {
    pub(super) row: usize,
    pub(super) col: usize,
    pub(super) echo: u8,
    pub(super) cell: Cell,
}

/// Mutable views of one plane-0 row of every field of a cloud.
pub(super) struct RowView<'c> {
    pub(super) point: &'c mut [Vec3],
    pub(super) range: &'c mut [f32],
    pub(super) intensity: &'c mut [f32],
    pub(super) ring: &'c mut [u16],
    pub(super) column: &'c mut [u32],
    pub(super) sensor: &'c mut [u8],
    pub(super) time: &'c mut [f64],
    pub(super) label: &'c mut [SemanticClass],
    pub(super) instance: &'c mut [u32],
    pub(super) ground: &'c mut [bool],
    pub(super) normal: &'c mut [Vec3],
}

impl RowView<'_> {
    /// Writes the return fields of `cell` into cell `i` (ring, column, sensor and time are the
    /// caller's, as for [`RowView::set_no_return`]).
    #[inline]
    pub(super) fn set_return(&mut self, i: usize, cell: &Cell) {
        self.point[i] = cell.point_in_vehicle;
        self.range[i] = cell.range_m;
        self.intensity[i] = cell.intensity;
        self.label[i] = cell.class;
        self.instance[i] = cell.instance;
        self.ground[i] = cell.class.is_ground();
        self.normal[i] = cell.normal;
    }

    /// Writes the no-return defaults of the return fields of cell `i` (as [`OrderedCloud::empty`]
    /// makes them); ring, column, sensor and time are the caller's.
    #[inline]
    pub(super) fn set_no_return(&mut self, i: usize) {
        self.point[i] = Vec3::NAN;
        self.range[i] = f32::NAN;
        self.intensity[i] = 0.0;
        self.label[i] = SemanticClass::UNLABELED;
        self.instance[i] = 0;
        self.ground[i] = false;
        self.normal[i] = Vec3::ZERO;
    }
}

/// Splits plane 0 of `cloud` into disjoint per-row views (for parallel filling). Requires `cols > 0`.
pub(super) fn row_views(cloud: &mut OrderedCloud) -> Vec<RowView<'_>> {
    let n = cloud.rows * cloud.cols;
    let cols = cloud.cols;
    let mut point = cloud.point_in_vehicle[..n].chunks_mut(cols);
    let mut range = cloud.range_m[..n].chunks_mut(cols);
    let mut intensity = cloud.intensity[..n].chunks_mut(cols);
    let mut ring = cloud.ring[..n].chunks_mut(cols);
    let mut column = cloud.column[..n].chunks_mut(cols);
    let mut sensor = cloud.sensor[..n].chunks_mut(cols);
    let mut time = cloud.time_s[..n].chunks_mut(cols);
    let mut label = cloud.label[..n].chunks_mut(cols);
    let mut instance = cloud.instance[..n].chunks_mut(cols);
    let mut ground = cloud.ground[..n].chunks_mut(cols);
    let mut normal = cloud.normal[..n].chunks_mut(cols);
    let mut views = Vec::with_capacity(cloud.rows);
    while let (Some(p), Some(r), Some(i), Some(rg), Some(c), Some(s), Some(t), Some(l), Some(inst), Some(g), Some(nm)) = (
        point.next(),
        range.next(),
        intensity.next(),
        ring.next(),
        column.next(),
        sensor.next(),
        time.next(),
        label.next(),
        instance.next(),
        ground.next(),
        normal.next(),
    ) {
        views.push(RowView {
            point: p,
            range: r,
            intensity: i,
            ring: rg,
            column: c,
            sensor: s,
            time: t,
            label: l,
            instance: inst,
            ground: g,
            normal: nm,
        });
    }
    views
}
