//! The beam table: a sensor's per-laser elevations (and, where known, azimuth and origin offsets)
//! and its column layout, the physical layout from which a cloud is put back into rows and columns.
//!
//! Angles are in the sensor frame, radians; azimuth is counter-clockwise from +x (left positive),
//! elevation up from the x-y plane. Column 0 is centred on `azimuth_left_rad` and azimuth decreases
//! by `azimuth_step_rad` per column (the `sim::OrderedCloud` convention), wrapping over a full turn.
//! Origin offsets follow `sim::sensor::spinning`: a laser's beam starts `horizontal_offset_m` to the
//! left of its azimuth and `vertical_offset_m` above the sensor origin, so a point at horizontal
//! distance `d` seen by laser `r` lies at azimuth `beam + asin(h_r / d)` and height
//! `v_r + sqrt(d^2 - h_r^2) * tan(elevation_r)`: [`TableRows::beam_azimuth`] and
//! [`TableRows::nearest_row`] undo both. A beam whose origin lies `a_r` out along it (Ouster,
//! RoboSense) reaches height `v_r + (d - a_r) * tan(elevation_r)`: [`TableRows::nearest_row`]
//! undoes that too.

use crate::error::{ClassifyError, Result};

/// Smallest column offset [`BeamTable::from_pattern`] keeps, columns: below it, the rounding of
/// the pattern's azimuths.
pub const MIN_COLUMN_OFFSET: f32 = 1e-3;

/// Smallest beam origin offset out along the beam [`BeamTable::from_pattern`] keeps, metres: below
/// it, the rounding of the pattern's origins and directions (the HDL-64E's origins, sideways and
/// up, leave about 1e-12 m along the beam).
pub const MIN_ALONG_M: f32 = 1e-6;

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
    /// Per beam (same order as `elevations_rad`): azimuth offset from the encoder angle, radians
    /// (left positive; empty = all 0). Informational for a destaggered grid, whose columns are the
    /// beams' own azimuths.
    pub azimuth_offsets_rad: Vec<f32>,
    /// Per beam: horizontal origin offset to the left of the beam, metres (empty = all 0).
    pub horizontal_offsets_m: Vec<f32>,
    /// Per beam: vertical origin offset above the sensor origin, metres (empty = all 0).
    pub vertical_offsets_m: Vec<f32>,
    /// Per beam: origin offset out from the spin axis along the beam's azimuth, metres (empty =
    /// all 0; Ouster and RoboSense sensors: 1 to 3 cm).
    pub along_offsets_m: Vec<f32>,
    /// Per beam: how far its beam azimuth lies from its column's centre, in columns (positive:
    /// towards later columns, clockwise; empty = all 0). A destaggered sensor's lasers fire up to
    /// half a column either side of the centre (VLS-128, Ouster sensors at 512 columns); a point's
    /// column is its beam azimuth's fractional column less this offset, rounded.
    pub column_offsets: Vec<f32>,
    /// The sensor's minimum range, metres (0: not known). The sensor reports nothing nearer, so a
    /// point nearer than this is not a measurement: ordering reads it as a no-return
    /// ([`super::OrderingReport::too_near`]), as it reads the `0, 0, 0` of a driver. nuScenes
    /// writes its no-returns as `0, 0, 0` moved by the ego-motion compensation to where the sensor
    /// was when it fired: up to a few decimetres from the origin, not at it.
    pub min_range_m: f32,
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
            azimuth_offsets_rad: Vec::new(),
            horizontal_offsets_m: Vec::new(),
            vertical_offsets_m: Vec::new(),
            along_offsets_m: Vec::new(),
            column_offsets: Vec::new(),
            min_range_m: 0.0,
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

    /// The table of a simulated sensor's pattern: row elevations, the columns' nominal azimuths, and
    /// per row the origin offsets of its beams (up, sideways and out along the beam) and its
    /// beams' offset from their column's centre in columns (read from the row's first firing;
    /// offsets under [`MIN_COLUMN_OFFSET`] and [`MIN_ALONG_M`] are 0). Refused for a pattern with
    /// fewer than 2 rows or columns.
    pub fn from_pattern(pattern: &sim::sensor::ScanPattern) -> Result<Self> {
        let az = &pattern.col_azimuth_rad;
        if pattern.rows < 2 || az.len() < 2 {
            return Err(ClassifyError::Ordering(format!(
                "a beam table needs 2 or more rows and columns; the pattern has {} x {}",
                pattern.rows,
                az.len()
            )));
        }
        let step = (az[0] - az[az.len() - 1]) / (az.len() - 1) as f32;
        let full_turn = (step * az.len() as f32 - std::f32::consts::TAU).abs() < 1.5 * step;
        let mut h = vec![0.0; pattern.rows];
        let mut v = vec![0.0; pattern.rows];
        let mut along = vec![0.0; pattern.rows];
        let mut column_offsets = vec![0.0; pattern.rows];
        for r in 0..pattern.rows {
            if let Some((c, f)) = (0..pattern.cols).find_map(|c| pattern.at(r, c).map(|f| (c, f))) {
                let o = f.origin_in_sensor;
                let d = glam::Vec2::new(f.dir_in_sensor.x, f.dir_in_sensor.y).normalize_or_zero();
                // Left of the beam = d rotated by +90 degrees.
                h[r] = -o.x * d.y + o.y * d.x;
                v[r] = o.z;
                let a = o.x * d.x + o.y * d.y;
                along[r] = if a.abs() < MIN_ALONG_M { 0.0 } else { a };
                // Column c's centre less the beam's azimuth, in columns (within half a turn).
                let beam = f64::from(f.dir_in_sensor.y).atan2(f64::from(f.dir_in_sensor.x));
                let turn = std::f64::consts::TAU;
                let off = (f64::from(az[c]) - beam).rem_euclid(turn);
                let off = if off > 0.5 * turn { off - turn } else { off } / f64::from(step);
                if off.abs() >= f64::from(MIN_COLUMN_OFFSET) {
                    column_offsets[r] = off as f32;
                }
            }
        }
        let any = |x: &[f32]| x.iter().any(|&a| a != 0.0);
        Ok(Self {
            elevations_rad: pattern.row_elevation_rad.clone(),
            cols: pattern.cols,
            azimuth_left_rad: az[0],
            azimuth_step_rad: step,
            full_turn,
            azimuth_offsets_rad: Vec::new(),
            horizontal_offsets_m: if any(&h) { h } else { Vec::new() },
            vertical_offsets_m: if any(&v) { v } else { Vec::new() },
            along_offsets_m: if any(&along) { along } else { Vec::new() },
            column_offsets: if any(&column_offsets) { column_offsets } else { Vec::new() },
            min_range_m: 0.0,
        })
    }

    /// The table of a simulated sensor ([`BeamTable::from_pattern`] of its pattern) with its
    /// minimum range.
    pub fn from_spec(spec: &sim::sensor::SensorSpec) -> Result<Self> {
        Ok(Self { min_range_m: spec.measurement().min_range_m, ..Self::from_pattern(&spec.pattern())? })
    }

    /// Checks the table and returns its rows sorted up.
    pub fn rows(&self) -> Result<TableRows> {
        let n = self.elevations_rad.len();
        if !(2..=u16::MAX as usize).contains(&n) {
            return Err(ClassifyError::Ordering(format!("beam table has {n} elevations, needs 2 ..= 65535")));
        }
        if self.cols < 2 || self.cols > 1 << 20 {
            return Err(ClassifyError::Ordering(format!("beam table has {} columns, needs 2 ..= 2^20", self.cols)));
        }
        if !(self.azimuth_step_rad.is_finite() && self.azimuth_step_rad > 0.0 && self.azimuth_left_rad.is_finite()) {
            return Err(ClassifyError::Ordering("azimuth step must be finite and > 0, left azimuth finite".into()));
        }
        for (name, v) in [
            ("azimuth offsets", &self.azimuth_offsets_rad),
            ("horizontal offsets", &self.horizontal_offsets_m),
            ("vertical offsets", &self.vertical_offsets_m),
            ("along offsets", &self.along_offsets_m),
            ("column offsets", &self.column_offsets),
        ] {
            if !v.is_empty() && v.len() != n {
                return Err(ClassifyError::Ordering(format!("beam table has {n} elevations but {} {name}", v.len())));
            }
            if v.iter().any(|x| !x.is_finite()) {
                return Err(ClassifyError::Ordering(format!("beam table has a non-finite value in its {name}")));
            }
        }
        if self.elevations_rad.iter().any(|x| !x.is_finite()) {
            return Err(ClassifyError::Ordering("beam table has a non-finite elevation".into()));
        }
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| self.elevations_rad[a].total_cmp(&self.elevations_rad[b]));
        let pick = |v: &[f32]| -> Vec<f32> { order.iter().map(|&k| v.get(k).copied().unwrap_or(0.0)).collect() };
        let elevation_rad = pick(&self.elevations_rad);
        if elevation_rad.windows(2).any(|w| w[1] - w[0] <= 0.0) {
            return Err(ClassifyError::Ordering("beam table has two beams at the same elevation".into()));
        }
        let horizontal_m = pick(&self.horizontal_offsets_m);
        let vertical_m = pick(&self.vertical_offsets_m);
        let column_offset = pick(&self.column_offsets);
        let along_m = pick(&self.along_offsets_m);
        let has_along = along_m.iter().any(|&a| a != 0.0);
        let mean_along_m = along_m.iter().sum::<f32>() / n as f32;
        let mean_vertical_m = vertical_m.iter().sum::<f32>() / n as f32;
        let tan_elevation: Vec<f32> = elevation_rad.iter().map(|e| e.tan()).collect();
        let row_gap = (0..n)
            .map(|r| match r {
                0 => tan_elevation[1] - tan_elevation[0],
                r if r == n - 1 => tan_elevation[r] - tan_elevation[r - 1],
                r => (tan_elevation[r + 1] - tan_elevation[r]).min(tan_elevation[r] - tan_elevation[r - 1]),
            })
            .collect();
        Ok(TableRows {
            guess: RowGuess::new(&tan_elevation),
            row_gap,
            tan_elevation,
            elevation_rad,
            horizontal_m,
            vertical_m,
            along_m,
            has_along,
            mean_along_m,
            column_offset,
            mean_vertical_m,
            cols: self.cols,
            azimuth_left_rad: self.azimuth_left_rad,
            azimuth_step_rad: self.azimuth_step_rad,
            full_turn: self.full_turn,
        })
    }
}

/// A checked beam table with its rows sorted by elevation (row 0 lowest).
#[derive(Clone, Debug, PartialEq)]
pub struct TableRows {
    /// Elevation per row, radians, increasing.
    pub elevation_rad: Vec<f32>,
    /// `tan(elevation)` per row.
    pub tan_elevation: Vec<f32>,
    /// The smaller gap of each row's `tan(elevation)` to its neighbours'.
    pub row_gap: Vec<f32>,
    /// Horizontal origin offset per row, metres (left of the beam).
    pub horizontal_m: Vec<f32>,
    /// Vertical origin offset per row, metres.
    pub vertical_m: Vec<f32>,
    /// Origin offset out along the beam per row, metres.
    pub along_m: Vec<f32>,
    /// Whether any row's origin lies out along its beam (then [`TableRows::nearest_row`] undoes it).
    pub has_along: bool,
    /// Mean offset out along the beam, metres (for a first guess of a point's row).
    pub mean_along_m: f32,
    /// Offset of each row's beams from their column's centre, columns ([`BeamTable::column_offsets`]).
    pub column_offset: Vec<f32>,
    /// Mean vertical offset, metres (for a first guess of a point's row).
    pub mean_vertical_m: f32,
    /// Columns.
    pub cols: usize,
    /// Azimuth of column 0's centre, radians.
    pub azimuth_left_rad: f32,
    /// Azimuth step per column, radians.
    pub azimuth_step_rad: f32,
    /// Whether the columns wrap over a full turn.
    pub full_turn: bool,
    /// First guess of a point's row from its `tan(elevation)`.
    guess: RowGuess,
}

/// Rows below `tan(elevation)` by a lookup in uniform bins, then a step or two: the same as a
/// binary search over the rows, without its chain of dependent, unpredictable branches.
#[derive(Clone, Debug, PartialEq)]
struct RowGuess {
    /// `tan(elevation)` of the first bin's lower edge.
    lo: f32,
    /// Bins per unit of `tan(elevation)`.
    scale: f32,
    /// Per bin: how many rows lie below its lower edge.
    below: Vec<u16>,
}

impl RowGuess {
    /// Bins: 8 per smallest gap between rows over the table's span, at most 4,096.
    fn new(tan: &[f32]) -> Self {
        let (first, last) = (tan[0], tan[tan.len() - 1]);
        let span = (last - first).max(1e-6);
        let bins = 4096usize.min(tan.len() * 64);
        let scale = bins as f32 / span;
        // `tan.partition_point(|&x| x < edge)` per bin edge, by one sweep: the edges increase
        // (rounding is monotone), so each count starts from the last (linear, where a binary
        // search per bin was 4,097 searches per frame; tens of microseconds either way).
        let mut g = 0;
        let below = (0..=bins)
            .map(|b| {
                let edge = first + b as f32 / scale;
                while g < tan.len() && tan[g] < edge {
                    g += 1;
                }
                g as u16
            })
            .collect();
        Self { lo: first, scale, below }
    }

    /// `tan.partition_point(|&x| x < t)` for the table's `tan` (increasing).
    // `!(a < t)` as the binary search compares: NaN counts no row below.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    #[inline(always)]
    fn rows_below(&self, tan: &[f32], t: f32) -> usize {
        // NaN and values below the first edge go to bin 0, values above to the last (casts saturate).
        let bin = (((t - self.lo) * self.scale) as usize).min(self.below.len() - 1);
        let mut g = usize::from(self.below[bin]);
        // The bin's edge is rounded: step down, then up, to the exact count.
        while g > 0 && !(tan[g - 1] < t) {
            g -= 1;
        }
        while g < tan.len() && tan[g] < t {
            g += 1;
        }
        g
    }
}

crate::cpu::dispatch_by_isa! {
    /// Per point `i`: of the five candidate rows `candidates[guess[i]]` (each `[vertical offset,
    /// 0.5 h h, tan(elevation), along offset]`), the fine `tan(elevation)` of the point (height
    /// `z[i]`, `inv_d[i] = 1 / horizontal distance`) seen from the row whose value is nearest its
    /// own, into `out[i]` (which holds the point's rough value `t0`, kept where no candidate is
    /// finite). The operations of [`TableRows::nearest_row`], in its order: the same bits.
    fn nearest_fine(
        candidates: &[[[f32; 4]; 5]],
        guess: &[u32],
        z: &[f32],
        inv_d: &[f32],
        has_along: bool,
        out: &mut [f32],
    ) -> ();
    body: nearest_fine_body, avx2: "avx2" if std::arch::is_x86_feature_detected!("avx2")
}

/// The body of [`nearest_fine`], inlined into each instruction-set variant.
#[inline(always)]
fn nearest_fine_body(
    candidates: &[[[f32; 4]; 5]],
    guess: &[u32],
    z: &[f32],
    inv_d: &[f32],
    has_along: bool,
    out: &mut [f32],
) {
    let m = out.len();
    let (guess, z, inv_d) = (&guess[..m], &z[..m], &inv_d[..m]);
    if has_along {
        for i in 0..m {
            let (z, inv_d, t0) = (z[i], inv_d[i], out[i]);
            let inv_d2 = inv_d * inv_d;
            let (mut best_e, mut best_f) = (f32::INFINITY, t0);
            for [v_r, half_hh, tan_r, a_r] in candidates[guess[i] as usize] {
                let f = (z - v_r) * inv_d * (1.0 + half_hh * inv_d2) / (1.0 - a_r * inv_d).max(1e-3);
                let e = (f - tan_r).abs();
                (best_e, best_f) = if e < best_e { (e, f) } else { (best_e, best_f) };
            }
            out[i] = best_f;
        }
    } else {
        for i in 0..m {
            let (z, inv_d, t0) = (z[i], inv_d[i], out[i]);
            let inv_d2 = inv_d * inv_d;
            let (mut best_e, mut best_f) = (f32::INFINITY, t0);
            for [v_r, half_hh, tan_r, _] in candidates[guess[i] as usize] {
                let f = (z - v_r) * inv_d * (1.0 + half_hh * inv_d2);
                let e = (f - tan_r).abs();
                (best_e, best_f) = if e < best_e { (e, f) } else { (best_e, best_f) };
            }
            out[i] = best_f;
        }
    }
}

crate::cpu::dispatch_by_isa! {
    /// [`RowGuess::rows_below`] of every `t[i]`, capped at the last row, into `out[i]`: one step
    /// down and one up from the bin's count in a loop the compiler vectorises (almost every bin
    /// holds at most one row edge), then the points whose count is not yet exact (both conditions
    /// of the partition point checked) searched one at a time. The same values.
    fn rows_below_all(guess: &RowGuess, tan_padded: &[f32], t: &[f32], out: &mut [u32]) -> ();
    body: rows_below_all_body, avx2: "avx2" if std::arch::is_x86_feature_detected!("avx2")
}

/// The body of [`rows_below_all`]; `tan_padded` is the table's `tan(elevation)` with `+inf` after
/// the last row.
// `!(a < t)` as the search compares: NaN counts no row below.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
#[inline(always)]
fn rows_below_all_body(guess: &RowGuess, tan_padded: &[f32], t: &[f32], out: &mut [u32]) {
    let n = tan_padded.len() - 1;
    let last_bin = guess.below.len() - 1;
    let out = &mut out[..t.len()];
    let mut inexact = 0usize;
    for (o, &t) in out.iter_mut().zip(t) {
        let bin = (((t - guess.lo) * guess.scale) as usize).min(last_bin);
        let mut g = usize::from(guess.below[bin]).min(n);
        // One step down (`!(a < t)`: NaN steps too, as the search's comparison does).
        let below_tan = tan_padded[g.saturating_sub(1)];
        let down = g > 0 && !(below_tan < t);
        g -= usize::from(down);
        // One step up (`tan_padded[n]` is `+inf`: never below `t`).
        g += usize::from(tan_padded[g] < t);
        g = g.min(n);
        let exact = (g == 0 || tan_padded[g.saturating_sub(1)] < t) && !(tan_padded[g] < t);
        inexact += usize::from(!exact);
        *o = if exact { g as u32 } else { u32::MAX };
    }
    if inexact > 0 {
        let tan = &tan_padded[..n];
        for (o, &t) in out.iter_mut().zip(t) {
            if *o == u32::MAX {
                *o = guess.rows_below(tan, t) as u32;
            }
        }
    }
    for o in out.iter_mut() {
        *o = (*o).min(n as u32 - 1);
    }
}

impl RowGuess {
    /// [`RowGuess::rows_below`] of every `t[i]`, capped at the last row of `tan`, into `out[i]`.
    fn rows_below_all(&self, tan: &[f32], t: &[f32], out: &mut [u32]) {
        let mut padded = Vec::with_capacity(tan.len() + 1);
        padded.extend_from_slice(tan);
        padded.push(f32::INFINITY);
        rows_below_all(self, &padded, t, out);
    }
}

impl TableRows {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.elevation_rad.len()
    }

    /// Whether the table has no rows (never, once checked).
    pub fn is_empty(&self) -> bool {
        self.elevation_rad.is_empty()
    }

    /// `tan(elevation)` of `p` (sensor frame) seen from the mean beam origin height.
    pub fn rough_tan(&self, p: glam::Vec3) -> f32 {
        (p.z - self.mean_vertical_m) / (p.x * p.x + p.y * p.y).sqrt().max(1e-6)
    }

    /// The row whose beam passes closest to `p` (sensor frame, compared as `tan(elevation)` with
    /// the row's origin offsets undone), the point's `tan(elevation)` seen from that row's origin,
    /// and whether `p` lies beyond the table's lowest or highest beam by more than half the gap to
    /// its neighbour.
    pub fn nearest_row(&self, p: glam::Vec3) -> (usize, f32, bool) {
        let d2 = p.x * p.x + p.y * p.y;
        let n = self.len();
        let tan = &self.tan_elevation;
        let inv_d = 1.0 / d2.sqrt().max(1e-6);
        let t0 = (p.z - self.mean_vertical_m) * inv_d;
        let t0 = if self.has_along { t0 / (1.0 - self.mean_along_m * inv_d).max(1e-3) } else { t0 };
        let guess = self.guess.rows_below(tan, t0).min(n - 1);
        // 1 / sqrt(d^2 - h^2) = (1 / d) (1 + h^2 / (2 d^2)) to well within 1e-6 for h << d; an
        // origin `a` out along the beam: 1 / (d - a) = (1 / d) / (1 - a / d).
        let inv_d2 = inv_d * inv_d;
        let fine = |r: usize| {
            let h = self.horizontal_m[r];
            let f = (p.z - self.vertical_m[r]) * inv_d * (1.0 + 0.5 * h * h * inv_d2);
            if self.has_along { f / (1.0 - self.along_m[r] * inv_d).max(1e-3) } else { f }
        };
        let (lo, hi) = (guess.saturating_sub(2), (guess + 2).min(n - 1));
        let mut best = (f32::INFINITY, guess, t0);
        // Always five candidates, the last repeated near the top (a repeat never wins a strict
        // comparison): a fixed loop of selects rather than branches.
        for k in 0..5 {
            let r = (lo + k).min(hi);
            let f = fine(r);
            let e = (f - tan[r]).abs();
            best = if e < best.0 { (e, r, f) } else { best };
        }
        let (_, r, f) = best;
        let outside = (r == 0 && tan[0] - f > 0.5 * (tan[1] - tan[0]))
            || (r == n - 1 && f - tan[n - 1] > 0.5 * (tan[n - 1] - tan[n - 2]));
        (r, f, outside)
    }

    /// [`TableRows::nearest_row`]'s `tan(elevation)` (the second value) of the points
    /// `points[valid[i]]` (every point where `valid` is `None`) into `out[i]`, the same bits;
    /// `dist[i]` is the point's horizontal distance `sqrt(x * x + y * y)`. Two passes: the
    /// divisions vectorized, then the row search.
    pub(crate) fn fine_tans<P: super::InputPoint>(
        &self,
        points: &[P],
        valid: Option<&[u32]>,
        dist: &[f32],
        out: &mut [f32],
    ) {
        let (n, tan, mean_v) = (self.len(), &self.tan_elevation[..], self.mean_vertical_m);
        let (h, v) = (&self.horizontal_m[..n], &self.vertical_m[..n]);
        // The points' heights, gathered once (both passes read them).
        let z: Vec<f32> =
            (0..out.len()).map(|i| valid.map_or(points[i], |valid| points[valid[i] as usize]).xyz().z).collect();
        // Pass 1: `1 / d` per point into `inv`, `t0` into `out` (vectorizes).
        let mut inv = vec![0f32; out.len()];
        for (((o, i), &d), &z) in out.iter_mut().zip(inv.iter_mut()).zip(dist).zip(&z) {
            *i = 1.0 / d.max(1e-6);
            *o = (z - mean_v) * *i;
        }
        if self.has_along {
            for (o, &i) in out.iter_mut().zip(&inv) {
                *o /= (1.0 - self.mean_along_m * i).max(1e-3);
            }
        }
        // Per first guess, its five candidate rows' vertical offset, `0.5 h h` (the same bits as
        // `nearest_row`'s left-to-right product) and `tan(elevation)`, side by side: the loop
        // below reads them without index clamps and bounds checks per candidate (it took 1.9 ms of
        // a 124 k-point KITTI frame ordered with origin offsets).
        let candidates: Vec<[[f32; 4]; 5]> = (0..n)
            .map(|g| {
                let (lo, hi) = (g.saturating_sub(2), (g + 2).min(n - 1));
                std::array::from_fn(|k| {
                    let r = (lo + k).min(hi);
                    [v[r], 0.5 * h[r] * h[r], tan[r], self.along_m[r]]
                })
            })
            .collect();
        // Pass 2: every point's first guess, then the nearest of its five candidate rows' fine
        // values, each a loop of its own that the compiler vectorises.
        let mut guess = vec![0u32; out.len()];
        self.guess.rows_below_all(tan, out, &mut guess);
        nearest_fine(&candidates, &guess, &z, &inv, self.has_along, out);
    }

    /// Azimuth of the beam of row `row` that hit `p` (sensor frame): the point's azimuth less the
    /// parallax of the row's horizontal origin offset, radians.
    pub fn beam_azimuth(&self, p: glam::Vec3, row: usize) -> f32 {
        let az = fast_atan2(p.y, p.x);
        let h = self.horizontal_m[row];
        if h == 0.0 {
            return az;
        }
        let d = (p.x * p.x + p.y * p.y).sqrt().max(h.abs() * 1.0001);
        az - (h / d).asin()
    }

    /// Fractional column steps from column 0 to the beam azimuth `az` of row `row`, less the row's
    /// column offset (wrapped into one turn for a full-turn table); column = the nearest integer.
    pub fn column_steps(&self, az: f32, row: usize) -> f32 {
        let steps = (self.azimuth_left_rad - az) / self.azimuth_step_rad - self.column_offset[row];
        if self.full_turn { wrap_into(steps, std::f32::consts::TAU / self.azimuth_step_rad) } else { steps }
    }
}

/// `atan2(y, x)` within 1e-6 rad (a minimax polynomial on `[0, 1]` and octant folding): the
/// azimuth of every point of a frame at a fraction of libm's cost.
#[inline]
pub fn fast_atan2(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let (num, den, swap) = if ay > ax { (ax, ay, true) } else { (ay, ax, false) };
    if den == 0.0 {
        return if x.is_sign_negative() { if y.is_sign_negative() { -PI } else { PI } } else { 0.0f32.copysign(y) };
    }
    let t = num / den;
    let t2 = t * t;
    let mut a = t
        * (0.999_996_1
            + t2 * (-0.333_172_8
                + t2 * (0.198_069_7
                    + t2 * (-0.132_299_9 + t2 * (0.079_560_77 + t2 * (-0.033_548_71 + t2 * 0.006_793_221))))));
    if swap {
        a = FRAC_PI_2 - a;
    }
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 { -a } else { a }
}

/// `x` wrapped into `[0, period)` for `x` within a few periods of it (no `fmod`).
#[inline]
pub fn wrap_into(mut x: f32, period: f32) -> f32 {
    if !(x.is_finite() && period > 0.0) {
        return x;
    }
    if x.abs() > 8.0 * period {
        return x.rem_euclid(period);
    }
    while x < 0.0 {
        x += period;
    }
    while x >= period {
        x -= period;
    }
    x
}

/// `x` rounded to the nearest integer (halves away from zero for positive `x`, up for negative),
/// without a call to libm's `roundf` (not inlined without SSE4.1); `x` within +-2^31.
#[inline]
pub fn round_fast(x: f32) -> f32 {
    let y = x + 0.5;
    let t = y as i64 as f32;
    if t > y { t - 1.0 } else { t }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The binned guess counts the rows below exactly as a binary search does, at bin edges, at the
    /// rows' own values, outside the table and for NaN.
    #[test]
    fn rows_below_equals_the_binary_search() {
        let os1 =
            BeamTable::spinning((0..128).map(|i| (-22.5f32 + 45.0 * i as f32 / 127.0).to_radians()).collect(), 1024);
        for table in [BeamTable::hdl64e(2170), os1] {
            let rows = table.rows().unwrap();
            let tan = &rows.tan_elevation;
            let mut probes: Vec<f32> = vec![f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -10.0, 10.0];
            for &t in tan {
                probes.extend([t, t.next_up(), t.next_down()]);
            }
            let (lo, hi) = (tan[0] - 0.1, tan[tan.len() - 1] + 0.1);
            probes.extend((0..100_000).map(|i| lo + (hi - lo) * i as f32 / 100_000.0));
            for t in probes {
                assert_eq!(rows.guess.rows_below(tan, t), tan.partition_point(|&x| x < t), "t {t}");
            }
            // The bins' counts themselves are the binary search's at their edges (the steps above
            // would hide a wrong count, at a cost).
            let g = &rows.guess;
            for (b, &below) in g.below.iter().enumerate() {
                let edge = g.lo + b as f32 / g.scale;
                assert_eq!(usize::from(below), tan.partition_point(|&x| x < edge), "bin {b}");
            }
        }
    }

    /// The batched first guesses equal the search one point at a time, for unevenly spaced rows
    /// (bins holding several row edges, so the batch's one step each way is not always enough),
    /// values exactly on row edges, outside the table, infinite and NaN.
    #[test]
    fn batched_row_guesses_equal_the_search() {
        let tan: Vec<f32> = [-0.4f32, -0.3999, -0.3998, -0.2, -0.19, -0.05, 0.0, 0.0001, 0.1, 0.35].to_vec();
        let guess = RowGuess::new(&tan);
        let mut t: Vec<f32> = (0..20_000).map(|k| -0.5 + k as f32 * 1e-4 * 0.47).collect();
        t.extend(tan.iter().copied());
        t.extend(tan.iter().map(|x| x.next_up()));
        t.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1e30, 1e30]);
        let mut got = vec![0u32; t.len()];
        guess.rows_below_all(&tan, &t, &mut got);
        let mut steps_beyond_one = 0;
        for (i, &x) in t.iter().enumerate() {
            let want = guess.rows_below(&tan, x).min(tan.len() - 1);
            assert_eq!(got[i] as usize, want, "t = {x}");
            let bin = (((x - guess.lo) * guess.scale) as usize).min(guess.below.len() - 1);
            steps_beyond_one += usize::from(guess.rows_below(&tan, x).abs_diff(usize::from(guess.below[bin])) > 1);
        }
        assert!(steps_beyond_one > 0, "no value needed the one-at-a-time search: the test would not see it fail");
    }

    /// The batch of fine elevations is bit for bit [`TableRows::nearest_row`]'s, with origin offsets
    /// (up and sideways, and out along the beam).
    #[test]
    fn fine_tans_equal_nearest_row() {
        let mut table = BeamTable::hdl64e(2083);
        let n = table.elevations_rad.len();
        table.horizontal_offsets_m = (0..n).map(|i| 0.02 * ((i % 7) as f32 - 3.0)).collect();
        table.vertical_offsets_m = (0..n).map(|i| 0.2 + 0.003 * (i % 11) as f32).collect();
        let mut with_along = table.clone();
        with_along.along_offsets_m = (0..n).map(|i| 0.027 + 0.001 * (i % 3) as f32).collect();
        for table in [table, with_along] {
            let rows = table.rows().unwrap();
            let points: Vec<glam::Vec3> = (0..20_000)
                .map(|i| {
                    let (a, r) = (i as f32 * 0.37, 0.5 + (i % 997) as f32 * 0.08);
                    glam::Vec3::new(r * a.cos(), r * a.sin(), -2.0 + (i % 389) as f32 * 0.01)
                })
                .collect();
            let valid: Vec<u32> = (0..points.len() as u32).filter(|k| k % 5 != 3).collect();
            let dist: Vec<f32> =
                valid.iter().map(|&k| (points[k as usize].x.powi(2) + points[k as usize].y.powi(2)).sqrt()).collect();
            let mut got = vec![0.0; valid.len()];
            rows.fine_tans(&points, Some(&valid), &dist, &mut got);
            for (g, &k) in got.iter().zip(&valid) {
                assert_eq!(g.to_bits(), rows.nearest_row(points[k as usize]).1.to_bits(), "point {k}");
            }
        }
    }
}
