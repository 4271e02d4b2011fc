//! The generators honour their parameters, measured on the mesh.

use crate::common;

use glam::Vec3;
use sim::SemanticClass;

fn ramp_toml(slope_deg: f32, sides: &str) -> String {
    format!(
        "version = 1\nfamily = \"ramp\"\n[params]\nslope_deg = {slope_deg}\nlength_m = 25.0\ndistance_m = 12.0\nwidth_m = 6.0\nsides = \"{sides}\"\n"
    )
}

#[test]
fn ramp_slope_on_the_mesh_equals_the_requested_slope() {
    for (slope, sides) in
        [(-20.0f32, "walls"), (-12.5, "railings"), (-3.0, "none"), (4.0, "walls"), (12.0, "railings"), (20.0, "walls")]
    {
        let s = scenes::load_str(&ramp_toml(slope, sides), "test", std::path::Path::new("."), 0).unwrap();
        let m = &s.mesh;
        let mut n = 0;
        for i in 0..m.len() {
            let [a, b, c] = m.triangle(i);
            let mid = (a + b + c) / 3.0;
            if m.surfaces[i].class != SemanticClass::ROAD || mid.x < 12.0 || mid.x > 37.0 || mid.y.abs() > 3.0 {
                continue;
            }
            let nrm = m.triangle_normal(i);
            let measured = (-nrm.x).atan2(nrm.z).to_degrees();
            assert!((measured - slope).abs() < 0.1, "slope {slope}: triangle {i} at {mid} measures {measured}");
            n += 1;
        }
        // 25 m x 6 m at 1 m cells, two triangles each.
        assert_eq!(n, 25 * 6 * 2, "slope {slope}");
        // The corridor floor at the ramp's middle and end, by vertical rays from above.
        let t = slope.to_radians().tan();
        let (z_mid, _) = common::top_hit(m, 24.5, 0.3).unwrap();
        assert!((z_mid - 12.5 * t).abs() < 2e-3, "slope {slope}: mid {z_mid}");
        let (z_land, land) = common::hit_below(m, 45.0, 0.0, 50.0).unwrap();
        assert!((z_land - 25.0 * t).abs() < 2e-3, "slope {slope}: landing {z_land}");
        assert!(land.class.is_ground());
        // Walls or railings beside the corridor; with no side structures a descending corridor
        // has plain ground beside it.
        let (_, beside) = common::hit_below(m, 24.5, 3.1, 10.0).unwrap();
        if sides == "none" && slope < 0.0 {
            assert_eq!(beside.class, SemanticClass::OTHER_GROUND, "slope {slope}");
        } else {
            assert_eq!(beside.class, SemanticClass::FENCE, "slope {slope} {sides}");
        }
    }
}

#[test]
fn basin_depth_on_the_mesh_equals_the_requested_depth() {
    for depth in [0.5f32, 2.0, 4.5] {
        let text = format!(
            "version = 1\nfamily = \"basin\"\n[params]\ndepth_m = {depth}\nbottom_width_m = 6.0\nbank_slope_deg = 25.0\n"
        );
        let s = scenes::load_str(&text, "test", std::path::Path::new("."), 0).unwrap();
        let m = &s.mesh;
        // Default geometry: road 7 m, shoulder 2 m, basin on the right (-y).
        let run = depth / 25f32.to_radians().tan();
        let centre_y = -(3.5 + 2.0 + run + 3.0);
        let (z, surf) = common::top_hit(m, 30.0, centre_y).unwrap();
        assert!((z + depth).abs() < 1e-4, "depth {depth}: bottom at {z}");
        assert_eq!(surf.class, SemanticClass::TERRAIN);
        let lowest = m.vertices.iter().map(|v| v.z).fold(f32::MAX, f32::min);
        assert!((lowest + depth).abs() < 1e-4, "depth {depth}: lowest vertex {lowest}");
        // Level ground at road height just beyond the far bank (the elevated target).
        let far = centre_y - 3.0 - run - 1.0;
        let (z_far, _) = common::top_hit(m, 30.0, far).unwrap();
        assert!(z_far.abs() < 1e-6, "depth {depth}: beyond at {z_far}");
        // Halfway down the near bank the surface is at half depth.
        let (z_bank, _) = common::top_hit(m, 30.0, -(5.5 + 0.5 * run)).unwrap();
        assert!((z_bank + 0.5 * depth).abs() < 0.02 * depth.max(1.0), "depth {depth}: bank {z_bank}");
    }
}

#[test]
fn hill_slope_under_the_ego_equals_the_requested_slope() {
    for slope in [5.0f32, 18.0, 25.0] {
        let text = format!("version = 1\nfamily = \"hill\"\n[params]\nslope_deg = {slope}\n");
        let s = scenes::load_str(&text, "test", std::path::Path::new("."), 0).unwrap();
        let (z0, _) = common::top_hit(&s.mesh, -2.0, 0.0).unwrap();
        let (z1, _) = common::top_hit(&s.mesh, 2.0, 0.0).unwrap();
        let measured = ((z1 - z0) / 4.0).atan().to_degrees();
        assert!((measured - slope).abs() < 0.05, "slope {slope}: {measured}");
        // Past the crest the road descends at 12 deg (default).
        let (za, _) = common::top_hit(&s.mesh, 80.0, 0.0).unwrap();
        let (zb, _) = common::top_hit(&s.mesh, 90.0, 0.0).unwrap();
        assert!((((zb - za) / 10.0).atan().to_degrees() + 12.0).abs() < 0.05);
    }
}

#[test]
fn city_curbs_have_the_requested_height_and_markings_are_coplanar() {
    let text = "version = 1\nfamily = \"city\"\n[params]\ncurb_height_m = 0.14\npedestrians_per_100m = 0.0\nparking_occupancy = 0.0\n";
    let s = scenes::load_str(text, "test", std::path::Path::new("."), 0).unwrap();
    let (z_road, road) = common::hit_below(&s.mesh, 10.0, -4.0, 1.0).unwrap();
    let (z_walk, walk) = common::hit_below(&s.mesh, 11.0, -7.5, 1.0).unwrap();
    assert_eq!(road.class, SemanticClass::ROAD);
    assert_eq!(walk.class, SemanticClass::SIDEWALK);
    assert!((z_walk - z_road - 0.14).abs() < 1e-5);
    let marks: Vec<usize> =
        (0..s.mesh.len()).filter(|&i| s.mesh.surfaces[i].class == SemanticClass::LANE_MARKING).collect();
    assert!(marks.len() > 100);
    for i in marks {
        assert!(s.mesh.triangle(i).iter().all(|v| v.z == 0.0));
        assert!((s.mesh.triangle_normal(i) - Vec3::Z).length() < 1e-6);
    }
}

#[test]
fn highway_has_markings_in_the_road_plane_and_traffic() {
    let s = scenes::load("highway", 0).unwrap();
    let m = &s.mesh;
    let marks = (0..m.len()).filter(|&i| m.surfaces[i].class == SemanticClass::LANE_MARKING).count();
    assert!(marks > 1000, "{marks}");
    assert!(
        (0..m.len())
            .filter(|&i| m.surfaces[i].class == SemanticClass::LANE_MARKING)
            .all(|i| m.triangle(i).iter().all(|v| v.z == 0.0))
    );
    let vehicles: std::collections::BTreeSet<u32> = m
        .surfaces
        .iter()
        .filter(|s| [SemanticClass::CAR, SemanticClass::TRUCK, SemanticClass::OTHER_VEHICLE].contains(&s.class))
        .map(|s| s.instance)
        .collect();
    assert!(vehicles.len() > 20, "{} vehicles", vehicles.len());
    // The embankment: 2 m down to the fields far from the road.
    let (z, _) = common::top_hit(m, 0.0, -60.0).unwrap();
    assert!((z + 2.0).abs() < 1e-5);
}

/// Bush and shrub instances (class bush) per hectare.
fn bushes_per_ha(name: &str) -> f32 {
    let s = scenes::load(name, 0).unwrap();
    let (lo, hi) = s.mesh.bounds().unwrap();
    let area_ha = (hi.x - lo.x) * (hi.y - lo.y) / 10_000.0;
    let bushes: std::collections::BTreeSet<u32> =
        s.mesh.surfaces.iter().filter(|surf| surf.class == SemanticClass::BUSH).map(|surf| surf.instance).collect();
    bushes.len() as f32 / area_ha
}

#[test]
fn forest_presets_follow_seed_002_sparse_has_no_bushes_dense_is_cluttered() {
    let (sparse, moderate, dense) =
        (bushes_per_ha("forest-sparse"), bushes_per_ha("forest-moderate"), bushes_per_ha("forest-dense"));
    assert_eq!(sparse, 0.0);
    // Presets: moderate 3400 + 1400, dense 7600 + 4400 bushes and shrubs per hectare where they
    // grow; the track, its verges, the clearing and a 3 m border take 10-20 % of the terrain.
    for (got, nominal) in [(moderate, 4800.0), (dense, 12000.0)] {
        assert!(got > 0.8 * nominal && got < nominal, "{got} of {nominal} per hectare");
    }
    assert!(dense > 2.0 * moderate, "dense {dense}, moderate {moderate}");
}

#[test]
fn forest_terrain_is_uneven_but_gently_sloped() {
    let s = scenes::load("forest-moderate", 0).unwrap();
    let m = &s.mesh;
    let ground: Vec<usize> = (0..m.len()).filter(|&i| m.surfaces[i].class == SemanticClass::TERRAIN).collect();
    let max_slope = ground.iter().map(|&i| m.triangle_normal(i).z.acos().to_degrees()).fold(0.0f32, f32::max);
    let zs: Vec<f32> = m.vertices.iter().map(|v| v.z).collect();
    assert!(max_slope > 1.0 && max_slope < 15.0, "max slope {max_slope}");
    let (lo, hi) =
        ground.iter().flat_map(|&i| m.triangle(i)).fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(v.z), h.max(v.z)));
    assert!(hi - lo > 0.5 && hi - lo < 3.0, "relief {lo} .. {hi}");
    assert!(!zs.is_empty());
}
