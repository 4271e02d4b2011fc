//! Every bundled scene: loads, validates, is deterministic, has ground and non-ground, is big
//! enough, and the ego origin stands on ground.

use crate::common;

/// Families whose geometry does not depend on the seed.
const SEED_FREE: [&str; 2] = ["ramp-up", "ramp-down"];
/// Families that are indoors or wooded (smaller terrain is fine there).
const NOT_OPEN: [&str; 4] = ["garage", "forest-sparse", "forest-moderate", "forest-dense"];

#[test]
fn there_are_thirteen_bundled_scenes_covering_every_family() {
    let names = scenes::bundled_names();
    assert_eq!(names.len(), 13);
    let mut families: Vec<String> = names.iter().map(|n| scenes::load_bundled(n, 0).unwrap().family).collect();
    families.sort();
    families.dedup();
    let mut all: Vec<&str> = scenes::families::NAMES.to_vec();
    all.sort();
    assert_eq!(families, all);
}

#[test]
fn every_bundled_scene_is_valid_deterministic_and_labelled() {
    for name in scenes::bundled_names() {
        let a = scenes::load(name, 0).unwrap();
        a.mesh.validate().unwrap();
        let degenerate = (0..a.mesh.len()).filter(|&i| a.mesh.triangle_normal(i) == glam::Vec3::ZERO).count();
        assert_eq!(degenerate, 0, "{name}: zero-area triangles");
        let n = a.mesh.len();
        assert!((10_000..1_500_000).contains(&n), "{name}: {n} triangles");
        let ground = a.mesh.surfaces.iter().filter(|s| s.class.is_ground()).count();
        assert!(ground > 1000 && ground < n, "{name}: {ground} ground of {n}");
        assert!(
            a.mesh.surfaces.iter().filter(|s| s.class.is_ground()).all(|s| s.instance == 0),
            "{name}: ground is stuff"
        );
        let objects: std::collections::BTreeSet<u32> = a.mesh.surfaces.iter().map(|s| s.instance).collect();
        assert!(objects.len() > 2, "{name}: {} instances", objects.len());
        let b = scenes::load(name, 0).unwrap();
        assert_eq!(a.mesh.vertices, b.mesh.vertices, "{name}");
        assert_eq!(a.mesh.triangles, b.mesh.triangles, "{name}");
        assert_eq!(a.mesh.surfaces, b.mesh.surfaces, "{name}");
        let c = scenes::load(name, 1).unwrap();
        if SEED_FREE.contains(&name) {
            assert_eq!(a.mesh, c.mesh, "{name} does not depend on the seed");
        } else {
            assert_ne!(a.mesh, c.mesh, "{name}: another seed gives another scene");
        }
        let (lo, hi) = a.mesh.bounds().unwrap();
        let side = if NOT_OPEN.contains(&name) { 100.0 } else { 400.0 };
        assert!(hi.x - lo.x >= side && hi.y - lo.y >= side, "{name}: {lo} .. {hi}");
    }
}

#[test]
fn the_ego_origin_stands_on_ground_in_every_bundled_scene() {
    for name in scenes::bundled_names() {
        let s = scenes::load(name, 3).unwrap();
        // Cast down from a roof sensor 2 m above the reported ground height.
        let (z, surface) = common::hit_below(&s.mesh, 0.0, 0.0, s.ego_ground_z_m + 2.0).unwrap();
        assert!(surface.class.is_ground(), "{name}: {:?}", surface.class);
        assert!((z - s.ego_ground_z_m).abs() < 1e-4, "{name}: ground at {z}, reported {}", s.ego_ground_z_m);
        // The ego's footprint is free of objects: ground under every corner (a 4.5 m x 1.8 m car;
        // in the forests seed 002's small ground robot, 0.8 m x 0.5 m, in a clearing of >= 0.6 m).
        let (hx, hy) = if name.starts_with("forest") { (0.4, 0.25) } else { (2.25, 0.9) };
        for (x, y) in [(hx, hy), (hx, -hy), (-hx, hy), (-hx, -hy)] {
            let (_, corner) = common::hit_below(&s.mesh, x, y, s.ego_ground_z_m + 2.0).unwrap();
            assert!(corner.class.is_ground(), "{name} at ({x}, {y}): {:?}", corner.class);
        }
    }
}
