//! Putting points into cells so that every point keeps one: each point names a row and a
//! fractional column; the point closest to a cell's column centre keeps the cell, a point that loses
//! it moves to the adjacent column on its side if that is free, else to the nearest free column
//! within [`NEAR_COLUMNS`] in its row, and otherwise stays in its cell on a further plane (plane 1,
//! 2, ...), as a second echo would; where such points are fewer than [`MAX_SHARED_FRACTION`] of the
//! cloud (a laser's turn overlapping its own start) they share their cell and its decision instead
//! of costing a whole plane. The classifier decides planes > 0
//! from the nearest plane-0 return (`nitsch::echoes_from_plane0`), so no point is left out.

use glam::{Affine3A, Vec3};
use sim::cloud::KnownFields;
use sim::{OrderedCloud, SemanticClass};

use super::buffer::CloudBuffer;
use super::input_point::InputPoint;
use super::report::OrderingReport;
use super::usable::Usable;

/// How far (columns) a point whose cell and side column are taken looks for a free cell in its row
/// before it stays on a further plane.
pub const NEAR_COLUMNS: usize = 16;

/// Below this fraction of the points, points with no free cell nearby share their cell (and its
/// decision) instead of being put on a further plane.
pub const MAX_SHARED_FRACTION: f64 = 0.01;

/// An owner of no cell.
const FREE: u32 = u32::MAX;

/// Where one usable point wants to go (wishes are in the order of the usable points).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Wish {
    /// Row.
    pub row: u32,
    /// Fractional column steps (column = nearest integer, wrapped for a full turn).
    pub steps: f32,
}

/// The per-point attributes carried into the cloud.
#[derive(Clone, Copy, Debug, Default)]
pub struct PointAttributes<'a> {
    /// Intensity per input point (where `None`, points that carry an intensity, such as KITTI
    /// records, give their own).
    pub intensity: Option<&'a [f32]>,
    /// Semantic label per input point (makes `label` and `ground`).
    pub labels: Option<&'a [SemanticClass]>,
    /// Time per input point, seconds.
    pub time_s: Option<&'a [f64]>,
    /// A `ring` field per input point (ROS drivers' clouds): rows come from it
    /// ([`super::OrderingPath::RingField`]).
    pub rings: Option<&'a [u16]>,
}

/// Places `wishes` into a `rows x cols` grid (planes added as needed) and fills `report`'s
/// `cell_of_point`, `placed`, `moved` and `stacked`.
pub(crate) fn place(
    wishes: &[Wish],
    rows: usize,
    cols: usize,
    full_turn: bool,
    report: &mut OrderingReport,
) -> (Vec<u32>, usize) {
    let n = rows * cols;
    // owner[cell] = index into `wishes`; `off` its distance from the column centre.
    let mut owner = vec![FREE; n];
    let mut off = vec![0f32; n];
    let mut cell_of_wish = vec![FREE; wishes.len()];
    let col_of = |steps: f32| -> Option<(usize, f32, bool)> {
        let mut col = super::beam_table::round_fast(steps);
        if full_turn && col >= cols as f32 {
            col -= cols as f32;
        }
        if !(col >= 0.0 && (col as usize) < cols) {
            return None;
        }
        let c = col as usize;
        let o = (steps - col).abs().min((steps - col - cols as f32).abs());
        Some((c, o, steps >= col && steps - col < 0.5 * cols as f32))
    };
    // The adjacent column on the side of the column centre the wish lies (`right`: +1), wrapped
    // for a full turn (no `rem_euclid`: an integer division per point cost a third of `place`).
    let alt = |c: usize, right: bool| -> Option<usize> {
        match (right, full_turn) {
            (true, _) if c + 1 < cols => Some(c + 1),
            (true, true) => Some(0),
            (false, _) if c > 0 => Some(c - 1),
            (false, true) => Some(cols - 1),
            _ => None,
        }
    };
    let mut losers: Vec<u32> = Vec::new();
    for (w, wish) in wishes.iter().enumerate() {
        let Some((c, o, _)) = col_of(wish.steps) else {
            losers.push(w as u32);
            continue;
        };
        let cell = wish.row as usize * cols + c;
        let prev = owner[cell];
        if prev == FREE {
            owner[cell] = w as u32;
            off[cell] = o;
            cell_of_wish[w] = cell as u32;
        } else if off[cell] <= o {
            losers.push(w as u32);
        } else {
            cell_of_wish[prev as usize] = FREE;
            losers.push(prev);
            owner[cell] = w as u32;
            off[cell] = o;
            cell_of_wish[w] = cell as u32;
        }
    }
    report.placed = wishes.len() - losers.len();
    // Losers: the adjacent column on their side if free, else the nearest free one, else a
    // further plane of their own cell.
    let mut stacked = Stacked::new(n);
    for &w in &losers {
        let wish = wishes[w as usize];
        let (c, alt) = match col_of(wish.steps) {
            Some((c, _, right)) => (c, alt(c, right)),
            None => (if wish.steps < 0.0 { 0 } else { cols - 1 }, None),
        };
        let row0 = wish.row as usize * cols;
        match free_column_near(&mut owner[row0..row0 + cols], w, c, alt, full_turn) {
            Some(free) => {
                cell_of_wish[w as usize] = (row0 + free) as u32;
                report.moved += 1;
            }
            None => stacked.push(w, row0 + c, report),
        }
    }
    let planes = stacked.finish(&mut cell_of_wish, wishes.len(), report);
    (cell_of_wish, planes)
}

/// [`place`] for the rings of scan unfolding ([`super::unfold::Unfolded::Rings`]): ring `r` holds
/// the points `bounds[r] .. bounds[r + 1]` (in order) and goes to row `row_of_ring[r]`, every
/// point has a whole column (`column`), and `spans_turn[r]` says whether two points of ring `r` may
/// share a column. A whole column lies at its cell's centre, so [`place`] keeps a cell for the
/// first point that names it; a ring that does not span a turn names every cell once, and its
/// points go straight to their cells. The result is [`place`]'s for the same points (tested).
pub(crate) fn place_rings(
    bounds: &[usize],
    row_of_ring: &[usize],
    column: &[u32],
    spans_turn: &[bool],
    rows: usize,
    cols: usize,
    report: &mut OrderingReport,
) -> (Vec<u32>, usize) {
    let total = column.len();
    // Filled ring by ring (not zeroed first: each entry is written before it is read).
    let mut cell_of_point = Vec::with_capacity(total);
    let mut stacked = Stacked::new(rows * cols);
    // The cells of a spanning ring's row: FREE or the point that holds the cell.
    let mut owner: Vec<u32> = Vec::new();
    let mut losers: Vec<usize> = Vec::new();
    let mut lost = 0;
    for ((w, &row), &spans) in bounds.windows(2).zip(row_of_ring).zip(spans_turn) {
        let row0 = row * cols;
        let ring = &column[w[0]..w[1]];
        debug_assert_eq!(cell_of_point.len(), w[0], "rings follow each other");
        // Every point in its own column's cell: final unless the ring spans a turn and the point
        // lost the cell to an earlier one (moved or stacked below).
        cell_of_point.extend(ring.iter().map(|&c| (row0 + c as usize) as u32));
        if !spans {
            continue;
        }
        let out = &mut cell_of_point[w[0]..w[1]];
        owner.clear();
        owner.resize(cols, FREE);
        losers.clear();
        for (i, &c) in ring.iter().enumerate() {
            let c = c as usize;
            if owner[c] == FREE {
                owner[c] = (w[0] + i) as u32;
            } else {
                losers.push(i);
            }
        }
        lost += losers.len();
        for &i in &losers {
            let c = ring[i] as usize;
            // The side of a whole column is the right one ([`place`]'s `alt`).
            let alt = if c + 1 < cols { c + 1 } else { 0 };
            match free_column_near(&mut owner, (w[0] + i) as u32, c, Some(alt), true) {
                Some(free) => {
                    out[i] = (row0 + free) as u32;
                    report.moved += 1;
                }
                None => stacked.push((w[0] + i) as u32, row0 + c, report),
            }
        }
    }
    report.placed = total - lost;
    let planes = stacked.finish(&mut cell_of_point, total, report);
    (cell_of_point, planes)
}

/// A free column for point `w`, which lost column `c` of a row (`owner`: the row's cells, FREE
/// where free): the adjacent column `alt` on its side if free, else the nearest free one within
/// [`NEAR_COLUMNS`] (wrapped over a full turn). The column found is taken for `w`.
fn free_column_near(owner: &mut [u32], w: u32, c: usize, alt: Option<usize>, full_turn: bool) -> Option<usize> {
    let cols = owner.len();
    let mut near = (2..=NEAR_COLUMNS as isize).flat_map(|k| [k, -k]).chain([-1, 1]).filter_map(|k| {
        let c2 = c as isize + k;
        if full_turn {
            Some(c2.rem_euclid(cols as isize) as usize)
        } else {
            usize::try_from(c2).ok().filter(|&a| a < cols)
        }
    });
    let free = alt.filter(|&a| owner[a] == FREE).or_else(|| near.find(|&c2| owner[c2] == FREE))?;
    owner[free] = w;
    Some(free)
}

/// Points with no free cell nearby: each on a further plane of its own cell (plane 1, 2, ...), or,
/// when they are fewer than [`MAX_SHARED_FRACTION`] of the points, sharing their cell.
struct Stacked {
    /// Cells per plane.
    n: usize,
    /// Points stacked so far per cell (allocated with the first).
    depth: Vec<u8>,
    /// `(point, cell, plane)` of each.
    entries: Vec<(u32, usize, u8)>,
}

impl Stacked {
    fn new(n: usize) -> Self {
        Self { n, depth: Vec::new(), entries: Vec::new() }
    }

    /// Stacks point `w` on its cell `cell` (plane 0 index).
    fn push(&mut self, w: u32, cell: usize, report: &mut OrderingReport) {
        if self.depth.is_empty() {
            self.depth = vec![0; self.n];
        }
        self.depth[cell] = self.depth[cell].saturating_add(1);
        self.entries.push((w, cell, self.depth[cell]));
        report.stacked += 1;
    }

    /// Writes the stacked points' cells into `cell_of_point` (`total` points in all) and returns
    /// the planes of the grid. A handful of such points (under `MAX_SHARED_FRACTION`: a laser's
    /// turn overlapping its start) share their cell's decision rather than cost a whole further
    /// plane.
    fn finish(self, cell_of_point: &mut [u32], total: usize, report: &mut OrderingReport) -> usize {
        if (self.entries.len() as f64) < MAX_SHARED_FRACTION * total as f64 {
            report.shared = self.entries.len();
            report.stacked = 0;
            for (w, cell, _) in self.entries {
                cell_of_point[w as usize] = cell as u32;
            }
            return 1;
        }
        let planes = 1 + self.entries.iter().map(|s| s.2 as usize).max().unwrap_or(0);
        for (w, cell, d) in self.entries {
            cell_of_point[w as usize] = (d as usize * self.n + cell) as u32;
        }
        planes
    }
}

/// Builds the cloud into `cloud` (its buffers reused): the usable points in their cells (`cell_of_usable`), moved to the vehicle
/// frame by `vehicle_from_sensor`; every cell's `ring` is its row and `column` its column.
#[allow(clippy::too_many_arguments)]
pub(crate) fn build_cloud<P: InputPoint>(
    points_in_sensor: &[P],
    attributes: &PointAttributes<'_>,
    usable: &Usable,
    cell_of_usable: &[u32],
    rows: usize,
    cols: usize,
    planes: usize,
    vehicle_from_sensor: Affine3A,
    buffer: &mut CloudBuffer,
    report: &mut OrderingReport,
) {
    let (cloud, known) = buffer.parts();
    cloud.reset_as_grid(rows, cols, planes, *known);
    // What this fill leaves at the reset values: every cell's row and column, the attributes it
    // lacks, echoes on one plane, and the instances and normals it never writes.
    *known = KnownFields {
        grid: true,
        time_s: attributes.time_s.is_none(),
        echo: planes == 1,
        label: attributes.labels.is_none(),
        instance: true,
        normal: true,
    };
    let plane = rows * cols;
    // Every usable point gets its cell here; the others none (the report's entries are left from
    // the last frame until now, not cleared first).
    match usable.indices() {
        // Every point usable: point `i` is usable point `i` (a zip, no index checks).
        None => {
            for (o, &cell) in report.cell_of_point.iter_mut().zip(cell_of_usable) {
                *o = Some(cell);
            }
        }
        Some(idx) => {
            report.cell_of_point.fill(None);
            for (&k, &cell) in idx.iter().zip(cell_of_usable) {
                report.cell_of_point[k as usize] = Some(cell);
            }
        }
    }
    // The fields scattered into the cells (points, ranges and intensities in one loop, times and
    // labels in their own), in reverse order: where points share a cell, the first one's values
    // are written last and stay (a shared cell keeps its first point).
    let transform = (vehicle_from_sensor != Affine3A::IDENTITY).then_some(vehicle_from_sensor);
    match usable.indices() {
        None => scatter(cloud, points_in_sensor, attributes, cell_of_usable, transform, |i| i),
        Some(idx) => scatter(cloud, points_in_sensor, attributes, cell_of_usable, transform, |i| idx[i] as usize),
    }
    if planes > 1 {
        for &cell in cell_of_usable {
            cloud.echo[cell as usize] = (cell as usize / plane) as u8;
        }
    }
}

/// Writes the points (usable point `i` is input point `point(i)`, its cell `cells[i]`) and their
/// attributes into `cloud`'s cells, last point first.
#[inline(always)]
fn scatter<P: InputPoint>(
    cloud: &mut OrderedCloud,
    points_in_sensor: &[P],
    attributes: &PointAttributes<'_>,
    cells: &[u32],
    transform: Option<Affine3A>,
    point: impl Fn(usize) -> usize,
) {
    // The fields cut to the grid's length: a cell checked against it once needs no check per
    // field.
    let n = cloud.len();
    let fields = Fields {
        points: &mut cloud.point_in_vehicle[..n],
        range: &mut cloud.range_m[..n],
        sensor: &mut cloud.sensor[..n],
        intensity: &mut cloud.intensity[..n],
    };
    // One loop per case, so that no case is tested per point.
    let t = transform.unwrap_or(Affine3A::IDENTITY);
    // Intensities: the attributes', else the points' own (KITTI records), else none written.
    match (transform.is_some(), attributes.intensity, P::HAS_INTENSITY) {
        (false, None, false) => {
            scatter_points::<P, false, false, false>(fields, points_in_sensor, &[], cells, t, &point)
        }
        (false, None, true) => scatter_points::<P, false, false, true>(fields, points_in_sensor, &[], cells, t, &point),
        (false, Some(v), _) => scatter_points::<P, false, true, false>(fields, points_in_sensor, v, cells, t, &point),
        (true, None, false) => scatter_points::<P, true, false, false>(fields, points_in_sensor, &[], cells, t, &point),
        (true, None, true) => scatter_points::<P, true, false, true>(fields, points_in_sensor, &[], cells, t, &point),
        (true, Some(v), _) => scatter_points::<P, true, true, false>(fields, points_in_sensor, v, cells, t, &point),
    }
    if let Some(t) = attributes.time_s {
        for (i, &cell) in cells.iter().enumerate().rev() {
            cloud.time_s[cell as usize] = t[point(i)];
        }
    }
    if let Some(l) = attributes.labels {
        for (i, &cell) in cells.iter().enumerate().rev() {
            let l = l[point(i)];
            (cloud.label[cell as usize], cloud.ground[cell as usize]) = (l, l.is_ground());
        }
    }
}

/// The cloud's fields that [`scatter_points`] writes, cut to the grid's length.
struct Fields<'a> {
    points: &'a mut [Vec3],
    range: &'a mut [f32],
    sensor: &'a mut [u8],
    intensity: &'a mut [f32],
}

/// [`scatter`]'s points, ranges, sensors and intensities (from `intensity_in` where `INTENSITY`,
/// from the points where `OWN_INTENSITY`), transformed by `t` where `TRANSFORM`.
#[inline(always)]
fn scatter_points<P: InputPoint, const TRANSFORM: bool, const INTENSITY: bool, const OWN_INTENSITY: bool>(
    fields: Fields<'_>,
    points_in_sensor: &[P],
    intensity_in: &[f32],
    cells: &[u32],
    t: Affine3A,
    point: &impl Fn(usize) -> usize,
) {
    let n = fields.points.len();
    // The inputs cut to one length: a point index checked against it once needs no check per field.
    let m = if INTENSITY { points_in_sensor.len().min(intensity_in.len()) } else { points_in_sensor.len() };
    let (points_in, intensity_in) = (&points_in_sensor[..m], &intensity_in[..if INTENSITY { m } else { 0 }]);
    let mut store = |i: usize, cell: u32, range: f32| {
        let (k, cell) = (point(i), cell as usize);
        if cell >= n || k >= m {
            // Never: every cell is one of the grid's, every index one of the points'.
            return;
        }
        let q = points_in[k];
        let p = q.xyz();
        fields.points[cell] = if TRANSFORM { t.transform_point3(p) } else { p };
        fields.range[cell] = range;
        fields.sensor[cell] = 0;
        if INTENSITY {
            fields.intensity[cell] = intensity_in[k];
        } else if OWN_INTENSITY {
            fields.intensity[cell] = q.intensity().unwrap_or(0.0);
        }
    };
    // Last point first. The ranges (`Vec3::length`: the same operations, the same bits) of
    // `RANGE_LANES` points at a time, so that their square roots run as one vector instruction
    // rather than one each (a square root per point bounded the loop).
    let whole = cells.len() - cells.len() % RANGE_LANES;
    for (i, &cell) in cells.iter().enumerate().skip(whole).rev() {
        let p = points_in.get(point(i)).map_or(Vec3::NAN, |q| q.xyz());
        store(i, cell, p.length());
    }
    for (b, block) in cells[..whole].chunks_exact(RANGE_LANES).enumerate().rev() {
        let i0 = b * RANGE_LANES;
        let mut range = [0f32; RANGE_LANES];
        for (l, r) in range.iter_mut().enumerate() {
            let p = points_in.get(point(i0 + l)).map_or(Vec3::NAN, |q| q.xyz());
            *r = p.x * p.x + p.y * p.y + p.z * p.z;
        }
        for r in &mut range {
            *r = r.sqrt();
        }
        for (l, &cell) in block.iter().enumerate().rev() {
            store(i0 + l, cell, range[l]);
        }
    }
}

/// Points whose ranges [`scatter_points`] computes together.
const RANGE_LANES: usize = 8;

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    use super::*;

    /// Rings of whole columns, some running past their start (shared columns, moved points, a
    /// crowded row that stacks), placed by [`place_rings`] and by [`place`]: the same cells, planes
    /// and counts.
    #[test]
    fn rings_are_placed_as_place_places_them() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let (rows, cols) = (12, 200);
        let (mut moved, mut stacked, mut shared) = (0, 0, 0);
        for case in 0..40 {
            let (mut bounds, mut row_of_ring, mut column, mut spans_turn) =
                (vec![0], Vec::new(), Vec::new(), Vec::new());
            let mut row = 0;
            while row < rows {
                // Longer than a turn in some cases; a crowded ring (many repeats) in others.
                let len = rng.random_range(1..if case % 3 == 0 { 260 } else { 190 });
                let start = rng.random_range(0..cols);
                let crowd = case % 5 == 0 && row == 3;
                for i in 0..len {
                    let c = if crowd { start + i / 3 } else { start + i };
                    column.push((c % cols) as u32);
                }
                spans_turn.push(len >= cols || crowd);
                bounds.push(column.len());
                row_of_ring.push(row);
                row += rng.random_range(1..3);
            }
            let wishes: Vec<Wish> = bounds
                .windows(2)
                .zip(&row_of_ring)
                .flat_map(|(w, &r)| column[w[0]..w[1]].iter().map(move |&c| Wish { row: r as u32, steps: c as f32 }))
                .collect();
            let mut expected = OrderingReport::default();
            let want = place(&wishes, rows, cols, true, &mut expected);
            let mut report = OrderingReport::default();
            let got = place_rings(&bounds, &row_of_ring, &column, &spans_turn, rows, cols, &mut report);
            assert_eq!(got, want, "case {case}");
            assert_eq!(report, expected, "case {case}");
            (moved, stacked, shared) = (moved + report.moved, stacked + report.stacked, shared + report.shared);
        }
        // Every way of settling a point that lost its cell was exercised.
        assert!(moved > 0 && stacked > 0 && shared > 0, "{moved} moved, {stacked} stacked, {shared} shared");
    }
}
