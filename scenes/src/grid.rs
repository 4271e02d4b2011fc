//! Watertight terrain on a rectilinear grid.
//!
//! A [`Grid`] is a list of x and a list of y grid-line coordinates (not necessarily evenly spaced)
//! that run across the whole terrain, so there are no T-junctions: every vertex is shared by all the
//! cells around it. A coordinate listed twice gives a zero-width column or row whose cells are the
//! exactly vertical faces of a step (curbs, retaining walls, pit walls); the first copy takes the
//! height just before the coordinate, the second the height just after it. Grid lines placed on
//! the edges of roads, ramps and markings make those regions exactly planar, which is what lets
//! tests measure a ramp's slope or a basin's depth to within rounding.

use glam::Vec3;
use sim::{SceneMesh, Surface};

/// How far before/after a doubled coordinate the height function is probed, metres.
const STEP_PROBE_M: f32 = 1e-3;

/// One cell as the surface callback of [`Grid::push`] sees it.
#[derive(Clone, Copy, Debug)]
pub struct Cell {
    /// Cell centre x, metres (for a zero-width column this is the step coordinate).
    pub x: f32,
    /// Cell centre y, metres.
    pub y: f32,
    /// Whether the cell is a vertical step face (zero width in x or y).
    pub vertical: bool,
    /// Lowest corner height, metres.
    pub z_min: f32,
    /// Highest corner height, metres.
    pub z_max: f32,
}

/// Grid-line coordinates along x and y, sorted ascending (a coordinate may appear twice: a step).
#[derive(Clone, Debug, Default)]
pub struct Grid {
    /// x grid lines, metres.
    pub xs: Vec<f32>,
    /// y grid lines, metres.
    pub ys: Vec<f32>,
}

/// Grid lines from `-half_m` to `half_m`: `fine_m` spacing within `near_half_m` of zero and
/// `coarse_m` beyond, plus the given breakpoints (a breakpoint listed in `steps` is doubled).
pub fn axis(half_m: f32, near_half_m: f32, fine_m: f32, coarse_m: f32, breaks: &[f32], steps: &[f32]) -> Vec<f32> {
    let mut v = Vec::new();
    let near = near_half_m.min(half_m);
    // Coarse part from -half to -near, fine part, coarse part to +half.
    let n_coarse = ((half_m - near) / coarse_m).ceil().max(0.0) as usize;
    let n_fine = (2.0 * near / fine_m).round().max(1.0) as usize;
    let far = near + n_coarse as f32 * coarse_m;
    for i in 0..n_coarse {
        v.push(-far + i as f32 * coarse_m);
    }
    for i in 0..=n_fine {
        v.push(-near + i as f32 * (2.0 * near / n_fine as f32));
    }
    for i in 1..=n_coarse {
        v.push(near + i as f32 * coarse_m);
    }
    let lo = v[0];
    let hi = v[v.len() - 1];
    v.extend(breaks.iter().copied().filter(|b| b.is_finite() && *b > lo && *b < hi));
    v.sort_by(f32::total_cmp);
    // Merge lines closer than 1 cm (a breakpoint wins over a regular line by snapping to it).
    let mut merged: Vec<f32> = Vec::with_capacity(v.len());
    for x in v {
        match merged.last_mut() {
            Some(last) if (x - *last).abs() < 0.01 => {
                if breaks.contains(&x) {
                    *last = x;
                }
            }
            _ => merged.push(x),
        }
    }
    for &s in steps {
        if s > lo && s < hi {
            let at = merged.partition_point(|&x| x < s);
            if merged.get(at).is_some_and(|&x| (x - s).abs() < 0.01) {
                merged[at] = s;
                merged.insert(at, s);
            } else {
                merged.insert(at, s);
                merged.insert(at, s);
            }
        }
    }
    merged
}

impl Grid {
    /// A grid with the given lines.
    pub fn new(xs: Vec<f32>, ys: Vec<f32>) -> Self {
        Self { xs, ys }
    }

    /// Adds the grid to `mesh` with vertex heights from `height(x, y)` and one surface per cell from
    /// `surface(cell)`; a cell for which it returns `None` is left open. Zero-area triangles (both
    /// sides of a step at the same height) are skipped: they cover nothing, so no crack opens.
    pub fn push(
        &self,
        mesh: &mut SceneMesh,
        height: impl Fn(f32, f32) -> f32,
        surface: impl Fn(&Cell) -> Option<Surface>,
    ) {
        let (nx, ny) = (self.xs.len(), self.ys.len());
        if nx < 2 || ny < 2 {
            return;
        }
        let probe = |v: &[f32], i: usize| -> f32 {
            if i + 1 < v.len() && v[i + 1] == v[i] {
                v[i] - STEP_PROBE_M
            } else if i > 0 && v[i - 1] == v[i] {
                v[i] + STEP_PROBE_M
            } else {
                v[i]
            }
        };
        let base = mesh.vertices.len() as u32;
        mesh.vertices.reserve(nx * ny);
        for j in 0..ny {
            let py = probe(&self.ys, j);
            for i in 0..nx {
                let px = probe(&self.xs, i);
                mesh.vertices.push(Vec3::new(self.xs[i], self.ys[j], height(px, py)));
            }
        }
        let stride = nx as u32;
        mesh.triangles.reserve(2 * (nx - 1) * (ny - 1));
        mesh.surfaces.reserve(2 * (nx - 1) * (ny - 1));
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let wx = self.xs[i + 1] - self.xs[i];
                let wy = self.ys[j + 1] - self.ys[j];
                if wx == 0.0 && wy == 0.0 {
                    continue;
                }
                let v00 = base + j as u32 * stride + i as u32;
                let (v10, v01) = (v00 + 1, v00 + stride);
                let v11 = v01 + 1;
                let zs = [v00, v10, v01, v11].map(|v| mesh.vertices[v as usize].z);
                let (z_min, z_max) = zs.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &z| (lo.min(z), hi.max(z)));
                let vertical = wx == 0.0 || wy == 0.0;
                if vertical && z_max == z_min {
                    continue;
                }
                let cell = Cell {
                    x: 0.5 * (self.xs[i] + self.xs[i + 1]),
                    y: 0.5 * (self.ys[j] + self.ys[j + 1]),
                    vertical,
                    z_min,
                    z_max,
                };
                let Some(s) = surface(&cell) else { continue };
                for tri in [[v00, v10, v11], [v00, v11, v01]] {
                    let [a, b, c] = tri.map(|v| mesh.vertices[v as usize]);
                    if (b - a).cross(c - a).length_squared() > 0.0 {
                        mesh.push_triangle(tri, s);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sim::SemanticClass;

    #[test]
    fn axis_has_breaks_and_doubled_steps() {
        let a = axis(10.0, 4.0, 1.0, 2.0, &[0.25], &[1.5]);
        assert_eq!(a[0], -10.0);
        assert_eq!(*a.last().unwrap(), 10.0);
        assert!(a.contains(&0.25));
        assert_eq!(a.iter().filter(|&&x| x == 1.5).count(), 2);
        assert!(a.windows(2).all(|w| w[0] <= w[1]));
    }

    #[test]
    fn step_makes_a_vertical_face_of_the_right_height() {
        let g = Grid::new(axis(2.0, 2.0, 1.0, 1.0, &[], &[0.5]), axis(2.0, 2.0, 1.0, 1.0, &[], &[]));
        let mut m = SceneMesh::new();
        let wall = Surface::stuff(SemanticClass::FENCE);
        let road = Surface::stuff(SemanticClass::ROAD);
        g.push(&mut m, |x, _| if x > 0.5 { 0.15 } else { 0.0 }, |c| Some(if c.vertical { wall } else { road }));
        let walls: Vec<usize> = (0..m.len()).filter(|&i| m.surfaces[i] == wall).collect();
        // 4 rows of cells along y, two triangles each.
        assert_eq!(walls.len(), 8);
        for &i in &walls {
            let n = m.triangle_normal(i);
            assert!(n.z.abs() < 1e-6 && (n.x.abs() - 1.0).abs() < 1e-6);
            let [a, b, c] = m.triangle(i);
            let hi = a.z.max(b.z).max(c.z);
            assert!((hi - 0.15).abs() < 1e-6);
        }
        m.validate().unwrap();
    }
}
