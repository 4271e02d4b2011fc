//! Classification tests on analytic scenes: car roofs, a basin, clustering against brute force,
//! echo planes, bad input, the method registry and the grid accumulation baseline.

use classifier::nitsch::cluster::{ClusterParams, ClusterWorkspace, cluster_candidates};
use classifier::synthetic::{Shape, SyntheticSensor, car, flat_ground};
use classifier::{ClassifyError, Evaluation, FrameInput, METHODS, Nitsch, NitschParams, method_by_name};
use glam::{Affine3A, Vec3};
use sim::{OrderedCloud, SemanticClass};

fn nitsch(threshold: f32, cluster: bool) -> Nitsch {
    Nitsch::new(NitschParams { threshold, cluster, ..Default::default() }).unwrap()
}

fn box_scene() -> OrderedCloud {
    SyntheticSensor::spinning(32, 720, -25.0, 2.0, 1.8).scan(&[flat_ground(), car(8.0, 0.0, 0.0), car(-6.0, 4.0, 0.0)])
}

fn roof_cells(cloud: &OrderedCloud) -> Vec<usize> {
    (0..cloud.len()).filter(|&i| cloud.label[i] == SemanticClass::CAR && cloud.normal[i].z > 0.9).collect()
}

#[test]
fn car_roof_has_ground_like_g_rho_but_is_not_ground_after_clustering() {
    let cloud = box_scene();
    let roofs = roof_cells(&cloud);
    assert!(roofs.len() > 20, "roof cells: {}", roofs.len());
    let mut m = nitsch(0.6, true);
    let ground = m.classify(&cloud).unwrap();
    // Roof interiors have a flat-ground g_rho...
    let high = roofs.iter().filter(|&&i| m.features.g_rho[i] > 0.9).count();
    assert!(high * 2 > roofs.len(), "{high} of {} roof cells with g_rho > 0.9", roofs.len());
    // ... yet clustering calls none of them ground.
    assert_eq!(roofs.iter().filter(|&&i| ground[i]).count(), 0);
    // Without clustering those roof cells are false positives.
    let no_cluster = nitsch(0.6, false).classify(&cloud).unwrap();
    assert!(roofs.iter().filter(|&&i| no_cluster[i]).count() >= high);
    let mut with = Evaluation::default();
    with.add_frame(&cloud, &ground);
    let mut without = Evaluation::default();
    without.add_frame(&cloud, &no_cluster);
    assert!(with.pooled.fpr() < without.pooled.fpr());
    assert!(with.pooled.recall() > 0.97, "recall {}", with.pooled.recall());
    assert!(with.pooled.accuracy() > 0.97, "accuracy {}", with.pooled.accuracy());
}

/// Road at z = 0 for y > -6, a 2 m deep basin with steep walls for -16 < y < -6, terrain at z = 0
/// beyond it (y < -16).
fn basin_scene() -> Vec<Shape> {
    let wall = |y: f32| Shape::Aabb {
        min: Vec3::new(-100.0, y - 0.01, -2.0),
        max: Vec3::new(100.0, y, 0.0),
        class: SemanticClass::OTHER_STRUCTURE,
    };
    let mut terrain = Shape::ground(0.0, [-100.0, -100.0], [100.0, -16.0]);
    if let Shape::Patch { class, .. } = &mut terrain {
        *class = SemanticClass::TERRAIN;
    }
    vec![
        Shape::ground(0.0, [-100.0, -6.0], [100.0, 100.0]),
        Shape::ground(-2.0, [-100.0, -16.0], [100.0, -6.0]),
        wall(-6.0),
        wall(-15.99),
        terrain,
    ]
}

#[test]
fn basin_far_side_terrain_is_ground() {
    let cloud = SyntheticSensor::spinning(32, 720, -25.0, 2.0, 1.8).scan(&basin_scene());
    let far: Vec<usize> = (0..cloud.len()).filter(|&i| cloud.label[i] == SemanticClass::TERRAIN).collect();
    assert!(far.len() > 200, "far-side cells: {}", far.len());
    let ground = nitsch(0.6, true).classify(&cloud).unwrap();
    let hit = far.iter().filter(|&&i| ground[i]).count();
    assert!(hit as f64 > 0.95 * far.len() as f64, "{hit} of {} far-side cells ground", far.len());
    // The basin walls are not ground.
    let walls: Vec<usize> = (0..cloud.len()).filter(|&i| cloud.label[i] == SemanticClass::OTHER_STRUCTURE).collect();
    assert!(!walls.is_empty());
    assert!(walls.iter().filter(|&&i| ground[i]).count() * 10 < walls.len());
}

#[test]
fn grid_clustering_equals_brute_force_radius_clustering() {
    let cloud = SyntheticSensor::spinning(16, 240, -25.0, 2.0, 1.8).scan(&[flat_ground(), car(7.0, 0.0, 0.0)]);
    let mut m = nitsch(0.6, true);
    m.classify(&cloud).unwrap();
    let view = m.view(&cloud);
    let cand: Vec<bool> = m.features.g_rho.iter().map(|&g| g >= 0.6).collect();
    // The pure radius clustering (tangent-plane link off) against a k-d-tree-like brute force.
    let params = ClusterParams { max_plane_offset_m: 0.0, ..Default::default() };
    let mut ws = ClusterWorkspace::default();
    cluster_candidates(&view, &cand, &m.features.normal, &params, &mut ws);
    // Brute force: union every pair of candidates within the same radius.
    let n = cloud.len();
    let idx: Vec<usize> = (0..n).filter(|&i| cand[i]).collect();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    let pts = &cloud.point_in_vehicle;
    for (k, &a) in idx.iter().enumerate() {
        for &b in &idx[k + 1..] {
            let tol = params.link_tolerance_m + params.link_tolerance_rel * pts[a].length().max(pts[b].length());
            if pts[a].distance(pts[b]) <= tol {
                let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let mut same = 0;
    for (k, &a) in idx.iter().enumerate() {
        for &b in idx[k + 1..].iter().step_by(7) {
            let brute = find(&mut parent, a) == find(&mut parent, b);
            let grid = ws.cluster_of(a) == ws.cluster_of(b);
            assert_eq!(brute, grid, "cells {a} and {b}");
            same += 1;
        }
    }
    assert!(same > 1000);
    assert!(ws.cluster_count() >= 2, "ground and the roof: {} clusters", ws.cluster_count());
}

#[test]
fn second_echoes_follow_the_nearest_first_echo() {
    let single = SyntheticSensor::spinning(16, 180, -25.0, -5.0, 1.8).scan(&[flat_ground()]);
    let mut cloud = OrderedCloud::empty(16, 180, 2);
    let n = 16 * 180;
    for i in 0..n {
        cloud.point_in_vehicle[i] = single.point_in_vehicle[i];
        cloud.range_m[i] = single.range_m[i];
        cloud.ground[i] = true;
    }
    // A second echo 10 cm from its first echo (ground) and one 5 m above the ground.
    cloud.point_in_vehicle[n + 5 * 180 + 10] = single.point_in_vehicle[5 * 180 + 10] + Vec3::new(0.1, 0.0, 0.0);
    cloud.range_m[n + 5 * 180 + 10] = 10.0;
    cloud.point_in_vehicle[n + 5 * 180 + 20] = single.point_in_vehicle[5 * 180 + 20] + Vec3::new(0.0, 0.0, 5.0);
    cloud.range_m[n + 5 * 180 + 20] = 10.0;
    let ground = nitsch(0.6, true).classify(&cloud).unwrap();
    assert!(ground[n + 5 * 180 + 10]);
    assert!(!ground[n + 5 * 180 + 20]);
    assert_eq!(ground[n..].iter().filter(|&&g| g).count(), 1);
}

#[test]
fn bad_input_is_refused_or_handled_without_panic() {
    let mut m = nitsch(0.6, true);
    // No returns at all: every cell non-ground.
    let empty = OrderedCloud::empty(16, 100, 1);
    assert!(m.classify(&empty).unwrap().iter().all(|&g| !g));
    // A single ring is refused.
    let one = OrderedCloud::empty(1, 100, 1);
    assert!(matches!(m.classify(&one), Err(ClassifyError::TooSmall { rows: 1, .. })));
    // Size disagreeing with the data.
    let mut bad = OrderedCloud::empty(16, 100, 1);
    bad.rows = 17;
    let err = m.classify(&bad).unwrap_err();
    assert!(matches!(err, ClassifyError::Inconsistent(_)));
    assert!(err.to_string().contains("point_in_vehicle"), "{err}");
    // NaN coordinates everywhere with finite ranges: handled as no returns.
    let mut nan = OrderedCloud::empty(16, 100, 1);
    nan.range_m.fill(5.0);
    for method in METHODS {
        let mut c = method_by_name(method, 1).unwrap();
        let out = c.classify(&FrameInput { index: 0, cloud: &nan, world_from_vehicle: None }).unwrap();
        assert!(out.iter().all(|&g| !g), "{method}");
        assert!(c.classify(&FrameInput { index: 0, cloud: &one, world_from_vehicle: None }).is_err(), "{method}");
    }
    // Bad parameters are refused.
    assert!(Nitsch::new(NitschParams { threshold: f32::NAN, ..Default::default() }).is_err());
}

#[test]
fn registry_knows_every_method_and_lists_them_for_unknown_names() {
    assert_eq!(METHODS.len(), 10);
    for name in METHODS {
        assert_eq!(method_by_name(name, 0).unwrap().name(), *name);
    }
    let err = method_by_name("patchwork", 0).err().unwrap();
    let msg = err.to_string();
    assert!(msg.contains("patchwork") && msg.contains("nitsch-no-cluster-0.7") && msg.contains("grid"), "{msg}");
}

#[test]
fn every_method_scores_the_box_scene() {
    let cloud = box_scene();
    let roofs = roof_cells(&cloud);
    for name in METHODS {
        let mut m = method_by_name(name, 7).unwrap();
        let pose = Some(Affine3A::from_translation(Vec3::new(100.0, -20.0, 3.0)));
        let out = m.classify(&FrameInput { index: 0, cloud: &cloud, world_from_vehicle: pose }).unwrap();
        let mut e = Evaluation::default();
        e.add_frame(&cloud, &out);
        let s = e.pooled.scores();
        // Flat ground: every method finds most of it.
        assert!(s.recall > 0.9, "{name}: {s:?}");
        let roof_fp = roofs.iter().filter(|&&i| out[i]).count();
        if !name.contains("no-cluster") {
            assert_eq!(roof_fp, 0, "{name}: roof cells called ground");
        }
    }
}

#[test]
fn grid_accumulation_uses_poses_across_frames() {
    // The vehicle moves 1 m forward between frames; the world stays put.
    let sensor = SyntheticSensor::spinning(32, 720, -25.0, 2.0, 1.8);
    let mut m = method_by_name("grid-no-cluster", 0).unwrap();
    let mut last = None;
    for k in 0..3 {
        let dx = k as f32;
        let shapes = [flat_ground(), car(8.0 - dx, 0.0, 0.0)];
        let cloud = sensor.scan(&shapes);
        let pose = Affine3A::from_translation(Vec3::new(dx, 0.0, 0.0));
        let out = m.classify(&FrameInput { index: k, cloud: &cloud, world_from_vehicle: Some(pose) }).unwrap();
        last = Some((cloud, out));
    }
    let (cloud, out) = last.unwrap();
    let mut e = Evaluation::default();
    e.add_frame(&cloud, &out);
    assert!(e.pooled.recall() > 0.95, "{:?}", e.pooled);
    assert!(e.pooled.fpr() < 0.2, "{:?}", e.pooled);
}

/// A 3 x 200 grid whose first 150 cells of row 0 are a road strip 5 m ahead (x = 5 m, z = 0,
/// 0.1 m apart); every other cell has no return. Returns the points and the column count.
fn road_rows() -> (Vec<Vec3>, usize) {
    let (rows, cols) = (3, 200);
    let mut pts = vec![Vec3::NAN; rows * cols];
    for (c, p) in pts[..150].iter_mut().enumerate() {
        *p = Vec3::new(5.0, -7.5 + 0.1 * c as f32, 0.0);
    }
    (pts, cols)
}

/// Clusters every return of the grid `pts` (`cols` columns, normals `+z`) and applies the cluster
/// rules: the number of clusters and the ground decision per cell.
fn cluster_and_decide(pts: &[Vec3], cols: usize, params: &ClusterParams) -> (usize, Vec<bool>) {
    let rows = pts.len() / cols;
    let ranges: Vec<f32> = pts.iter().map(|p| p.length()).collect();
    let view = classifier::nitsch::neighbours::GridView {
        points: pts,
        ranges: &ranges,
        rows,
        cols,
        wrap: false,
        max_col_gap: 2,
    };
    let candidate: Vec<bool> = pts.iter().map(|p| p.is_finite()).collect();
    let normals = vec![Vec3::Z; pts.len()];
    let returns = candidate.iter().filter(|&&c| c).count();
    let mut ws = ClusterWorkspace::default();
    cluster_candidates(&view, &candidate, &normals, params, &mut ws);
    let mut ground = vec![false; pts.len()];
    ws.decide(pts, returns, params, &mut ground);
    (ws.cluster_count(), ground)
}

#[test]
fn wide_low_clusters_outside_the_ground_area_are_ground_high_ones_are_not() {
    let (mut pts, cols) = road_rows();
    for c in 0..20 {
        pts[cols + c] = Vec3::new(60.0, -10.0 + c as f32, -0.5);
        pts[2 * cols + c] = Vec3::new(60.0, -10.0 + c as f32, 3.0);
    }
    for (extent, low_expected) in [(10.0, true), (0.0, false)] {
        let params = ClusterParams { min_large_extent_m: extent, ..Default::default() };
        let (clusters, ground) = cluster_and_decide(&pts, cols, &params);
        assert_eq!(clusters, 3);
        assert!(ground[..150].iter().all(|&g| g), "the largest cluster is ground");
        assert!(ground[cols..cols + 20].iter().all(|&g| g == low_expected), "low strip, extent {extent}");
        assert!(ground[2 * cols..2 * cols + 20].iter().all(|&g| !g), "raised strip, extent {extent}");
    }
}

#[test]
fn the_default_extent_accepts_far_ring_segments_longer_than_object_tops() {
    // Outside the ground area, 60 m ahead and 0.5 m below the road: a ring segment of 8 points
    // 1 m apart (7 m long, far terrain) and one of 5 points 1 m apart (4 m: the size of an object top).
    assert_eq!(ClusterParams::default().min_large_extent_m, 6.0);
    let (mut pts, cols) = road_rows();
    for c in 0..8 {
        pts[cols + c] = Vec3::new(60.0, -20.0 + c as f32, -0.5);
    }
    for c in 0..5 {
        pts[2 * cols + 100 + c] = Vec3::new(80.0, 10.0 + c as f32, -0.5);
    }
    let (clusters, ground) = cluster_and_decide(&pts, cols, &ClusterParams::default());
    assert_eq!(clusters, 3);
    assert!(ground[..150].iter().all(|&g| g), "the largest cluster is ground");
    assert!(ground[cols..cols + 8].iter().all(|&g| g), "7 m segment");
    assert!(ground[2 * cols + 100..2 * cols + 105].iter().all(|&g| !g), "4 m segment");
}
