//! Test helpers: a brute-force vertical ray cast (independent of `sim::cast`).

use sim::{SceneMesh, Surface};

/// The highest surface point above `(x, y)`: its height and surface, or `None` where nothing is.
/// Triangles that are vertical (zero area seen from above) are ignored.
#[allow(dead_code)] // not every test file uses both helpers
pub fn top_hit(mesh: &SceneMesh, x: f32, y: f32) -> Option<(f32, Surface)> {
    hit_below(mesh, x, y, f32::INFINITY)
}

/// What a ray cast straight down from `(x, y, z_from)` hits first: height and surface.
pub fn hit_below(mesh: &SceneMesh, x: f32, y: f32, z_from: f32) -> Option<(f32, Surface)> {
    let mut best: Option<(f32, Surface)> = None;
    for i in 0..mesh.len() {
        let [a, b, c] = mesh.triangle(i);
        let det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
        if det.abs() < 1e-12 {
            continue;
        }
        let l1 = ((x - a.x) * (c.y - a.y) - (c.x - a.x) * (y - a.y)) / det;
        let l2 = ((b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y)) / det;
        let l0 = 1.0 - l1 - l2;
        let eps = -1e-6;
        if l0 < eps || l1 < eps || l2 < eps {
            continue;
        }
        let z = l0 * a.z + l1 * b.z + l2 * c.z;
        if z <= z_from && best.is_none_or(|(bz, _)| z > bz) {
            best = Some((z, mesh.surfaces[i]));
        }
    }
    best
}
