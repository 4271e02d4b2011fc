//! The terrain of every bundled scene is watertight: each edge of a ground ("stuff") triangle is
//! shared, by exact vertex coordinates, with exactly one other triangle, except along the outer
//! border of the terrain. No T-junctions, no cracks at curbs, ramp walls or basin banks.

use std::collections::HashMap;

/// The garage's floor slabs are stuff too, not terrain grid: every other bundled scene's instance-0
/// triangles are all terrain grid.
const NOT_GRID: [&str; 1] = ["garage"];

type Key = [u32; 3];

/// Exact coordinates (with -0.0 taken as 0.0: the same point).
fn key(v: glam::Vec3) -> Key {
    (v + glam::Vec3::ZERO).to_array().map(f32::to_bits)
}

#[test]
fn terrain_edges_are_shared_by_exactly_two_triangles() {
    let grid_scenes: Vec<&str> = scenes::bundled_names().into_iter().filter(|n| !NOT_GRID.contains(n)).collect();
    assert!(grid_scenes.len() >= 12, "{grid_scenes:?}");
    for name in grid_scenes {
        let s = scenes::load(name, 0).unwrap();
        let m = &s.mesh;
        let mut edges: HashMap<(Key, Key), u32> = HashMap::new();
        let (mut lo, mut hi) = (glam::Vec2::MAX, glam::Vec2::MIN);
        for i in (0..m.len()).filter(|&i| m.surfaces[i].instance == 0) {
            let t = m.triangle(i);
            for k in 0..3 {
                let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
                *edges.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
                lo = lo.min(t[k].truncate());
                hi = hi.max(t[k].truncate());
            }
        }
        let on_border = |k: &Key| {
            let (x, y) = (f32::from_bits(k[0]), f32::from_bits(k[1]));
            x == lo.x || x == hi.x || y == lo.y || y == hi.y
        };
        let mut border = 0;
        for ((a, b), n) in &edges {
            if on_border(a) && on_border(b) && *n == 1 {
                border += 1;
                continue;
            }
            assert_eq!(*n, 2, "{name}: edge {:?} - {:?} used {n} times", a.map(f32::from_bits), b.map(f32::from_bits));
        }
        assert!(border >= 400, "{name}: {border} border edges");
    }
}
