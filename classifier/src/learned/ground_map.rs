//! A height map of the ground under a frame: square cells in the x-y plane of the cloud's frame
//! holding the mean height of the returns a first classifier (Nitsch et al.) called ground, with
//! the cells it found no ground in filled from their neighbours, and per cell the lowest and
//! highest return of any kind. The learned method's heights are measured against it, so that they
//! do not depend on where the frame's origin lies (a vehicle frame at the ground, or a sensor
//! frame 1.7 m above it).

use glam::Vec3;

/// Side of a fine cell, metres.
pub const CELL_M: f32 = 1.0;

/// Fine cells per coarse cell along each axis (coarse cells of 8 m).
pub const COARSE: usize = 8;

/// Half the side of the square the map covers around the frame's origin, metres (returns beyond
/// it fall in the edge cells).
pub const HALF_EXTENT_M: f32 = 96.0;

/// Cells along each axis.
pub const SIDE: usize = (2.0 * HALF_EXTENT_M / CELL_M) as usize;

const COARSE_SIDE: usize = SIDE / COARSE;

/// What the learned features read of a fine cell, together (one cache line for a return, not
/// four arrays).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellSummary {
    /// The ground height used (filled), as [`GroundMap::level`].
    pub level: f32,
    /// The coarse cell's ground height, as [`GroundMap::coarse_level`].
    pub coarse_level: f32,
    /// The lowest return.
    pub lowest: f32,
    /// Highest minus lowest return.
    pub span: f32,
    /// Ground returns over returns (0 where the cell holds none).
    pub ground_share: f32,
}

/// The map of one frame; buffers are reused between frames.
#[derive(Clone, Debug, Default)]
pub struct GroundMap {
    /// Per fine cell: sum of ground heights and their count.
    ground: Vec<(f32, u32)>,
    /// Per fine cell: lowest and highest return, returns.
    span: Vec<(f32, f32, u32)>,
    /// Per coarse cell: sum of ground heights and their count.
    coarse: Vec<(f32, u32)>,
    /// Per fine cell: the ground height used (filled).
    level: Vec<f32>,
    /// Per coarse cell: the ground height used (filled).
    coarse_level: Vec<f32>,
    /// Per fine cell: what the features read.
    summary: Vec<CellSummary>,
    /// Per point given to [`GroundMap::build`]: its fine cell ([`cell_of`]; `u32::MAX` where the
    /// point is not finite).
    point_cell: Vec<u32>,
    /// The heights of the ground returns within 20 m (reused between frames).
    near: Vec<f32>,
    /// The frame's ground level: the median height of the ground returns within 20 m.
    pub global_level: f32,
}

/// The fine cell of a point.
#[inline]
pub fn cell_of(p: Vec3) -> usize {
    let i = ((p.x + HALF_EXTENT_M) / CELL_M).clamp(0.0, (SIDE - 1) as f32) as usize;
    let j = ((p.y + HALF_EXTENT_M) / CELL_M).clamp(0.0, (SIDE - 1) as f32) as usize;
    i * SIDE + j
}

impl GroundMap {
    /// Builds the map from the returns `points` (NaN where none) and the first classifier's ground
    /// decisions `ground` (same length).
    pub fn build(&mut self, points: &[Vec3], ground: &[bool]) {
        self.ground.clear();
        self.ground.resize(SIDE * SIDE, (0.0, 0));
        self.span.clear();
        self.span.resize(SIDE * SIDE, (f32::INFINITY, f32::NEG_INFINITY, 0));
        self.coarse.clear();
        self.coarse.resize(COARSE_SIDE * COARSE_SIDE, (0.0, 0));
        let mut near = std::mem::take(&mut self.near);
        near.clear();
        self.point_cell.clear();
        self.point_cell.resize(points.len(), u32::MAX);
        for ((p, &g), point_cell) in points.iter().zip(ground).zip(&mut self.point_cell) {
            if !p.is_finite() {
                continue;
            }
            let c = cell_of(*p);
            *point_cell = c as u32;
            let s = &mut self.span[c];
            s.0 = s.0.min(p.z);
            s.1 = s.1.max(p.z);
            s.2 += 1;
            if g {
                self.ground[c].0 += p.z;
                self.ground[c].1 += 1;
                let (i, j) = (c / SIDE / COARSE, c % SIDE / COARSE);
                let k = i * COARSE_SIDE + j;
                self.coarse[k].0 += p.z;
                self.coarse[k].1 += 1;
                if p.x * p.x + p.y * p.y < 400.0 {
                    near.push(p.z);
                }
            }
        }
        self.global_level = if near.is_empty() {
            // No ground near the origin: the lowest tenth of all returns.
            let mut z: Vec<f32> = points.iter().filter(|p| p.is_finite()).map(|p| p.z).collect();
            if z.is_empty() {
                0.0
            } else {
                let k = z.len() / 10;
                *z.select_nth_unstable_by(k, f32::total_cmp).1
            }
        } else {
            let k = near.len() / 2;
            *near.select_nth_unstable_by(k, f32::total_cmp).1
        };
        self.near = near;
        // Coarse levels: the cell's mean, else the mean over its 3 x 3 coarse neighbours, else the
        // frame's level.
        self.coarse_level.clear();
        self.coarse_level.resize(COARSE_SIDE * COARSE_SIDE, self.global_level);
        for i in 0..COARSE_SIDE {
            for j in 0..COARSE_SIDE {
                let (s, n) = self.coarse[i * COARSE_SIDE + j];
                self.coarse_level[i * COARSE_SIDE + j] = if n > 0 {
                    s / n as f32
                } else {
                    let (s, n) = neighbourhood(&self.coarse, COARSE_SIDE, i, j, 1);
                    if n > 0 { s / n as f32 } else { self.global_level }
                };
            }
        }
        // Fine levels: the cell's mean, else the mean over the 5 x 5 cells around it, else the
        // coarse level.
        // Every cell's level and every summary read below is written in this pass: no clearing
        // (1 MB of stores a frame).
        self.level.resize(SIDE * SIDE, 0.0);
        self.summary.resize(SIDE * SIDE, CellSummary::default());
        for i in 0..SIDE {
            for j in 0..SIDE {
                let c = i * SIDE + j;
                let (s, n) = self.ground[c];
                self.level[c] = if n > 0 {
                    s / n as f32
                } else if self.span[c].2 == 0 {
                    // Nothing here: no return will ask.
                    self.coarse_level[(i / COARSE) * COARSE_SIDE + j / COARSE]
                } else {
                    let (s, n) = neighbourhood(&self.ground, SIDE, i, j, 2);
                    if n > 0 { s / n as f32 } else { self.coarse_level[(i / COARSE) * COARSE_SIDE + j / COARSE] }
                };
                let (lowest, highest, returns) = self.span[c];
                if returns > 0 {
                    self.summary[c] = CellSummary {
                        level: self.level[c],
                        coarse_level: self.coarse_level(c),
                        lowest,
                        span: highest - lowest,
                        ground_share: self.ground[c].1 as f32 / returns as f32,
                    };
                }
            }
        }
    }

    /// What the features read of fine cell `c`, a cell holding a return of the last
    /// [`GroundMap::build`] (elsewhere: what an earlier frame left, or the default).
    #[inline]
    pub fn summary(&self, c: usize) -> &CellSummary {
        &self.summary[c]
    }

    /// The fine cell of every point given to the last [`GroundMap::build`], `u32::MAX` for
    /// points that are not finite.
    #[inline]
    pub fn point_cells(&self) -> &[u32] {
        &self.point_cell
    }

    /// The ground height under fine cell `c`.
    #[inline]
    pub fn level(&self, c: usize) -> f32 {
        self.level[c]
    }

    /// The ground height of the coarse cell holding fine cell `c`.
    #[inline]
    pub fn coarse_level(&self, c: usize) -> f32 {
        let (i, j) = (c / SIDE / COARSE, c % SIDE / COARSE);
        self.coarse_level[i * COARSE_SIDE + j]
    }

    /// Lowest and highest return of fine cell `c`, and its returns.
    #[inline]
    pub fn span(&self, c: usize) -> (f32, f32, u32) {
        self.span[c]
    }

    /// Returns the first classifier called ground in fine cell `c`.
    #[inline]
    pub fn ground_count(&self, c: usize) -> u32 {
        self.ground[c].1
    }
}

/// Sum and count over the `(2 r + 1)^2` cells around `(i, j)` of a `side x side` grid.
fn neighbourhood(cells: &[(f32, u32)], side: usize, i: usize, j: usize, r: usize) -> (f32, u32) {
    let (mut s, mut n) = (0.0f32, 0u32);
    for a in i.saturating_sub(r)..=(i + r).min(side - 1) {
        for b in j.saturating_sub(r)..=(j + r).min(side - 1) {
            let (cs, cn) = cells[a * side + b];
            s += cs;
            n += cn;
        }
    }
    (s, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_come_from_ground_and_fill_their_neighbours() {
        // Ground at z = -1.7 on a 10 m square, a wall at x = 5 up to 2 m, nothing else.
        let mut points = Vec::new();
        let mut ground = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                points.push(Vec3::new(-5.0 + i as f32 * 0.25, -5.0 + j as f32 * 0.25, -1.7));
                ground.push(true);
            }
        }
        for k in 0..20 {
            points.push(Vec3::new(7.2, 0.0, -1.7 + k as f32 * 0.2));
            ground.push(false);
        }
        points.push(Vec3::NAN);
        ground.push(false);
        let mut map = GroundMap::default();
        map.build(&points, &ground);
        assert!((map.global_level + 1.7).abs() < 1e-6);
        let c = cell_of(Vec3::new(1.1, 1.1, 0.0));
        assert!((map.level(c) + 1.7).abs() < 1e-5);
        // The wall's cell holds no ground; its level comes from the ground 2 cells away, its span
        // from the wall.
        let w = cell_of(Vec3::new(7.2, 0.0, 0.0));
        assert_eq!(map.ground_count(w), 0);
        assert!((map.level(w) + 1.7).abs() < 1e-5);
        let (lo, hi, n) = map.span(w);
        assert_eq!(n, 20);
        assert!((lo + 1.7).abs() < 1e-6 && (hi - 2.1).abs() < 1e-5);
        // Far away: the coarse level, then the frame's.
        assert!((map.coarse_level(cell_of(Vec3::new(80.0, 80.0, 0.0))) + 1.7).abs() < 1e-5);
    }
}
