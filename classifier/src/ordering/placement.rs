//! Putting points into cells so that every point keeps one: each point names a row and a
//! fractional column; the point closest to a cell's column centre keeps the cell, a point that loses
//! it moves to the adjacent column on its side if that is free, else to the nearest free column
//! within [`NEAR_COLUMNS`] in its row, and otherwise stays in its cell on a further plane (plane 1,
//! 2, ...), as a second echo would; where such points are fewer than [`MAX_SHARED_FRACTION`] of the
//! cloud (a laser's turn overlapping its own start) they share their cell and its decision instead
//! of costing a whole plane. The classifier decides planes > 0
//! from the nearest plane-0 return (`nitsch::echoes_from_plane0`), so no point is left out.

use glam::{Affine3A, Vec3};
use sim::{OrderedCloud, SemanticClass};

use super::report::OrderingReport;

/// How far (columns) a point whose cell and side column are taken looks for a free cell in its row
/// before it stays on a further plane.
pub const NEAR_COLUMNS: usize = 16;

/// Below this fraction of the points, points with no free cell nearby share their cell (and its
/// decision) instead of being put on a further plane.
pub const MAX_SHARED_FRACTION: f64 = 0.01;

/// Where one point wants to go.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Wish {
    /// Input point index.
    pub point: u32,
    /// Row.
    pub row: u32,
    /// Fractional column steps (column = nearest integer, wrapped for a full turn).
    pub steps: f32,
}

/// The per-point attributes carried into the cloud.
#[derive(Clone, Copy, Debug, Default)]
pub struct PointAttributes<'a> {
    /// Intensity per input point.
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
    const FREE: u32 = u32::MAX;
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
    // Losers: the adjacent column on their side if free, else a further plane of their own cell.
    let mut depth: Vec<u8> = Vec::new();
    let mut stack: Vec<(u32, usize, u8)> = Vec::new();
    for &w in &losers {
        let wish = wishes[w as usize];
        let (c, alt) = match col_of(wish.steps) {
            Some((c, _, right)) => (c, alt(c, right)),
            None => (if wish.steps < 0.0 { 0 } else { cols - 1 }, None),
        };
        let row0 = wish.row as usize * cols;
        if let Some(a) = alt
            && owner[row0 + a] == FREE
        {
            owner[row0 + a] = w;
            cell_of_wish[w as usize] = (row0 + a) as u32;
            report.moved += 1;
            continue;
        }
        // The nearest free column within `NEAR_COLUMNS` in the same row.
        if let Some(free) = (2..=NEAR_COLUMNS as isize)
            .flat_map(|k| [k, -k])
            .chain([-1, 1])
            .filter_map(|k| {
                let c2 = c as isize + k;
                if full_turn {
                    Some(c2.rem_euclid(cols as isize) as usize)
                } else {
                    usize::try_from(c2).ok().filter(|&a| a < cols)
                }
            })
            .find(|&c2| owner[row0 + c2] == FREE)
        {
            owner[row0 + free] = w;
            cell_of_wish[w as usize] = (row0 + free) as u32;
            report.moved += 1;
            continue;
        }
        if depth.is_empty() {
            depth = vec![0; n];
        }
        let cell = row0 + c;
        depth[cell] = depth[cell].saturating_add(1);
        stack.push((w, cell, depth[cell]));
        report.stacked += 1;
    }
    // A handful of such points (under `MAX_SHARED_FRACTION`: a laser's turn overlapping its start)
    // share their cell's decision rather than cost a whole further plane.
    if (stack.len() as f64) < MAX_SHARED_FRACTION * wishes.len() as f64 {
        report.shared = stack.len();
        report.stacked = 0;
        for (w, cell, _) in stack {
            cell_of_wish[w as usize] = cell as u32;
        }
        return (cell_of_wish, 1);
    }
    let planes = 1 + stack.iter().map(|s| s.2 as usize).max().unwrap_or(0);
    for (w, cell, d) in stack {
        cell_of_wish[w as usize] = (d as usize * n + cell) as u32;
    }
    (cell_of_wish, planes)
}

/// Builds the cloud: the points of `wishes` in their cells (`cell_of_wish`), moved to the vehicle
/// frame by `vehicle_from_sensor`; every cell's `ring` is its row and `column` its column.
#[allow(clippy::too_many_arguments)]
pub(crate) fn build_cloud(
    points_in_sensor: &[Vec3],
    attributes: &PointAttributes<'_>,
    wishes: &[Wish],
    cell_of_wish: &[u32],
    rows: usize,
    cols: usize,
    planes: usize,
    vehicle_from_sensor: Affine3A,
    report: &mut OrderingReport,
) -> OrderedCloud {
    // Built here rather than by `OrderedCloud::empty` (whose rayon fill costs more than it saves on
    // one core for a frame of this size).
    let n = rows * cols * planes;
    let mut cloud = OrderedCloud {
        rows,
        cols,
        planes,
        point_in_vehicle: vec![Vec3::NAN; n],
        range_m: vec![f32::NAN; n],
        intensity: vec![0.0; n],
        ring: vec![0; n],
        column: vec![0; n],
        sensor: vec![u8::MAX; n],
        time_s: vec![0.0; n],
        echo: vec![0; n],
        label: vec![SemanticClass::UNLABELED; n],
        instance: vec![0; n],
        ground: vec![false; n],
        normal: vec![Vec3::ZERO; n],
    };
    for (ring_index, (ring, column)) in
        cloud.ring.chunks_exact_mut(cols).zip(cloud.column.chunks_exact_mut(cols)).enumerate()
    {
        ring.fill((ring_index % rows.max(1)) as u16);
        for (c, v) in column.iter_mut().enumerate() {
            *v = c as u32;
        }
    }
    let identity = vehicle_from_sensor == Affine3A::IDENTITY;
    let plane = rows * cols;
    for (wish, &cell) in wishes.iter().zip(cell_of_wish) {
        let k = wish.point as usize;
        let cell = cell as usize;
        report.cell_of_point[k] = Some(cell as u32);
        if cloud.range_m[cell].is_finite() {
            // A shared cell keeps its first point.
            continue;
        }
        let p = points_in_sensor[k];
        cloud.point_in_vehicle[cell] = if identity { p } else { vehicle_from_sensor.transform_point3(p) };
        cloud.range_m[cell] = p.length();
        cloud.sensor[cell] = 0;
        cloud.echo[cell] = if cell < plane { 0 } else { (cell / plane) as u8 };
        if let Some(v) = attributes.intensity {
            cloud.intensity[cell] = v[k];
        }
        if let Some(t) = attributes.time_s {
            cloud.time_s[cell] = t[k];
        }
        if let Some(l) = attributes.labels {
            cloud.label[cell] = l[k];
            cloud.ground[cell] = l[k].is_ground();
        }
    }
    cloud
}
