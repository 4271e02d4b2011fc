//! Feature tests on analytic synthetic clouds: flat ground, walls, missing neighbours, wrap-around.

use classifier::nitsch::features::{FeatureParams, Features, compute_features};
use classifier::nitsch::neighbours::{GridView, MAX_ROW_GAP, detect_wrap};
use classifier::synthetic::{Shape, SyntheticSensor, flat_ground};
use glam::Vec3;
use sim::{OrderedCloud, SemanticClass};

fn features(cloud: &OrderedCloud, wrap: bool, params: FeatureParams) -> Features {
    let view = GridView {
        points: &cloud.point_in_vehicle,
        ranges: &cloud.range_m,
        rows: cloud.rows,
        cols: cloud.cols,
        wrap,
        max_col_gap: 2,
    };
    let mut f = Features::default();
    compute_features(&view, &params, &mut f);
    f
}

#[test]
fn flat_ground_gives_up_normals_and_g_rho_one_all_around() {
    let sensor = SyntheticSensor::spinning(16, 360, -25.0, -5.0, 1.8);
    let cloud = sensor.scan(&[flat_ground()]);
    assert_eq!(cloud.returns(), 16 * 360);
    let f = features(&cloud, true, FeatureParams::default());
    let mut worst_deg = 0f32;
    for i in 0..cloud.len() {
        let angle = f.normal[i].angle_between(Vec3::Z).to_degrees();
        worst_deg = worst_deg.max(angle);
        assert!(f.g_rho[i] > 0.999, "cell {i}: g_rho {}", f.g_rho[i]);
    }
    assert!(worst_deg < 0.5, "worst normal off +z by {worst_deg} deg");
}

#[test]
fn wall_gives_g_rho_near_zero() {
    // A forward sensor in front of a vertical wall 8 m ahead (no ground in the way: rings look up).
    let sensor = SyntheticSensor::forward(8, 60, 2.0, 20.0, 60.0, 1.8);
    let wall = Shape::Patch {
        point: Vec3::new(8.0, 0.0, 0.0),
        normal: Vec3::NEG_X,
        min_xy: glam::Vec2::new(7.0, -50.0),
        max_xy: glam::Vec2::new(9.0, 50.0),
        class: SemanticClass::BUILDING,
    };
    let cloud = sensor.scan(&[wall]);
    assert_eq!(cloud.returns(), 8 * 60);
    let f = features(&cloud, false, FeatureParams::default());
    for i in 0..cloud.len() {
        assert!(f.g_rho[i].abs() < 0.02, "cell {i}: g_rho {}", f.g_rho[i]);
        // The normal points back at the sensor (-x), and the quality of a plane is still 1.
        assert!(f.normal[i].dot(Vec3::NEG_X) > 0.999, "normal {:?}", f.normal[i]);
        assert!(f.n_rho[i] > 0.999);
    }
}

#[test]
fn lowest_ring_and_grid_edges_keep_features() {
    // Forward sensor: no wrap; row 0 lacks the neighbours below, columns 0 / last lack one side.
    let sensor = SyntheticSensor::forward(6, 40, -20.0, -10.0, 40.0, 1.8);
    let cloud = sensor.scan(&[flat_ground()]);
    let f = features(&cloud, false, FeatureParams::default());
    // Row 0, middle column: 4 of 8 pairs exist; n_rho averages over those, so g_rho ~ 1.
    assert!(f.g_rho[20] > 0.999);
    // Corner (row 0, col 0): only d1, d2, d3 exist -> 2 pairs -> still features (min 2).
    assert!(f.g_rho[0] > 0.999);
    // With min_valid_pairs = 3 the corner gets none, the edge still does.
    let f3 = features(&cloud, false, FeatureParams { min_valid_pairs: 3, ..Default::default() });
    assert_eq!(f3.g_rho[0], 0.0);
    assert_eq!(f3.normal[0], Vec3::ZERO);
    assert!(f3.g_rho[20] > 0.999);
}

#[test]
fn missing_neighbours_are_skipped_or_bridged() {
    let sensor = SyntheticSensor::forward(6, 40, -20.0, -10.0, 40.0, 1.8);
    let mut cloud = sensor.scan(&[flat_ground()]);
    let at = |r: usize, c: usize| r * 40 + c;
    // Knock out the right neighbour of (3, 20): the gap search takes (3, 22) instead.
    cloud.point_in_vehicle[at(3, 21)] = Vec3::NAN;
    cloud.range_m[at(3, 21)] = f32::NAN;
    // An isolated return: everything around (1, 5) empty, up to 2 columns and 3 rows away.
    for r in 0..5 {
        for c in 3..=7 {
            if (r, c) != (1, 5) {
                cloud.point_in_vehicle[at(r, c)] = Vec3::NAN;
            }
        }
    }
    // Corrupt input: finite range but NaN coordinates counts as no return.
    cloud.point_in_vehicle[at(4, 30)] = Vec3::new(f32::NAN, 1.0, 0.0);
    let f = features(&cloud, false, FeatureParams::default());
    assert!(f.g_rho[at(3, 20)] > 0.999);
    assert!(f.g_rho[at(3, 22)] > 0.999);
    assert_eq!(f.g_rho[at(3, 21)], 0.0, "no return, no features");
    assert_eq!(f.g_rho[at(1, 5)], 0.0, "isolated return: no pair normals");
    assert_eq!(f.g_rho[at(4, 30)], 0.0);
    assert!(f.g_rho[at(4, 29)] > 0.999, "the NaN neighbour is bridged");
    // With direct neighbours only, an isolated column gap still leaves the up/down pairs.
    let view = GridView {
        points: &cloud.point_in_vehicle,
        ranges: &cloud.range_m,
        rows: 6,
        cols: 40,
        wrap: false,
        max_col_gap: 1,
    };
    let nb = view.neighbours(3, 20);
    assert_eq!(nb[2], None, "right neighbour missing without gap search");
    assert_eq!(nb[0], Some(at(4, 20)));
    assert_eq!(nb[1], Some(at(4, 21)));
}

#[test]
fn far_neighbours_are_dropped_by_the_distance_threshold() {
    let sensor = SyntheticSensor::forward(6, 40, -20.0, -10.0, 40.0, 1.8);
    let cloud = sensor.scan(&[flat_ground()]);
    // Row spacing on the ground at these elevations is > 1 m, column spacing < 0.6 m.
    let f = features(&cloud, false, FeatureParams { max_neighbour_distance_m: 0.6, ..Default::default() });
    // Only the left and right neighbours remain: they are not adjacent in the enumeration -> no pairs.
    assert_eq!(f.g_rho[3 * 40 + 20], 0.0);
    let f = features(&cloud, false, FeatureParams { max_neighbour_distance_m: 50.0, ..Default::default() });
    assert!(f.g_rho[3 * 40 + 20] > 0.999);
}

#[test]
fn wrap_is_detected_for_full_turns_only_and_joins_the_seam() {
    let spin = SyntheticSensor::spinning(8, 180, -25.0, -5.0, 1.8).scan(&[flat_ground()]);
    assert!(detect_wrap(&spin.point_in_vehicle, 8, 180));
    let fwd = SyntheticSensor::forward(8, 180, -25.0, -5.0, 120.0, 1.8).scan(&[flat_ground()]);
    assert!(!detect_wrap(&fwd.point_in_vehicle, 8, 180));
    // At the seam, with wrap, column 0 sees column 179 as its left neighbour.
    let view = GridView {
        points: &spin.point_in_vehicle,
        ranges: &spin.range_m,
        rows: 8,
        cols: 180,
        wrap: true,
        max_col_gap: 2,
    };
    assert_eq!(view.neighbours(3, 0)[6], Some(3 * 180 + 179));
    let fw = features(&spin, true, FeatureParams::default());
    let fnw = features(&spin, false, FeatureParams::default());
    // Both give upward normals on flat ground; with wrap the seam cells have all 8 pairs.
    assert!(fw.g_rho[3 * 180] > 0.999 && fnw.g_rho[3 * 180] > 0.999);
    let (d1, d2) = (spin.point_in_vehicle[3 * 180 + 179], spin.point_in_vehicle[3 * 180]);
    assert!(d1.distance(d2) < 0.3, "seam columns are physical neighbours");
}

#[test]
fn an_upper_neighbour_in_front_of_the_cell_is_an_occluder() {
    let sensor = SyntheticSensor::forward(6, 40, -20.0, -10.0, 40.0, 1.8);
    let mut cloud = sensor.scan(&[flat_ground()]);
    let (r, c) = (2, 20);
    let i = r * 40 + c;
    // Put the three upper neighbours on an object 30 % nearer and 0.4 m up (a bumper seen above
    // the ground under a car).
    for cc in c - 1..=c + 1 {
        let j = (r + 1) * 40 + cc;
        let p = cloud.point_in_vehicle[j];
        let origin = sensor.origin;
        let q = origin + (p - origin) * 0.7;
        cloud.point_in_vehicle[j] = Vec3::new(q.x, q.y, 0.4);
        cloud.range_m[j] = (cloud.point_in_vehicle[j] - origin).length();
    }
    let with = features(&cloud, false, FeatureParams::default());
    let without = features(&cloud, false, FeatureParams { upper_occlusion_ratio: 0.0, ..Default::default() });
    assert!(with.g_rho[i] > 0.99, "occluders left out: g_rho {}", with.g_rho[i]);
    assert!(without.g_rho[i] < 0.6, "occluders kept: g_rho {}", without.g_rho[i]);
    // Ratio checks are refused outside [0, 1).
    assert!(FeatureParams { occlusion_ratio: 1.0, ..Default::default() }.validate().is_err());
}

#[test]
fn a_same_row_neighbour_in_front_of_the_cell_is_an_occluder() {
    // Ground at (2, 20); its right neighbour in the row is on a bush 30 % nearer and 0.5 m up (the
    // near edge of a range jump). The lateral test leaves it out; without the test it tilts the normal.
    let sensor = SyntheticSensor::forward(6, 40, -20.0, -10.0, 40.0, 1.8);
    let mut cloud = sensor.scan(&[flat_ground()]);
    let (i, j) = (2 * 40 + 20, 2 * 40 + 21);
    let q = sensor.origin + (cloud.point_in_vehicle[j] - sensor.origin) * 0.7;
    cloud.point_in_vehicle[j] = Vec3::new(q.x, q.y, 0.5);
    cloud.range_m[j] = (cloud.point_in_vehicle[j] - sensor.origin).length();
    assert!(cloud.range_m[j] < 0.9 * cloud.range_m[i]);
    let with = features(&cloud, false, FeatureParams::default());
    assert_eq!(FeatureParams::default().lateral_occlusion_ratio, 0.1);
    let without = features(&cloud, false, FeatureParams { lateral_occlusion_ratio: 0.0, ..Default::default() });
    assert!(with.g_rho[i] > 0.999, "occluder left out: g_rho {}", with.g_rho[i]);
    assert!(without.g_rho[i] < 0.9, "occluder kept: g_rho {}", without.g_rho[i]);
    // The left neighbour, 8 % nearer than the cell (a wall seen obliquely), is kept.
    let k = 2 * 40 + 19;
    cloud.range_m[k] = 0.92 * cloud.range_m[i];
    let f = features(&cloud, false, FeatureParams::default());
    assert_eq!(f.g_rho[i], with.g_rho[i]);
    assert!(FeatureParams { lateral_occlusion_ratio: -0.1, ..Default::default() }.validate().is_err());
}

#[test]
fn empty_rows_of_a_merged_grid_are_skipped_up_to_max_row_gap() {
    // The merged lux-roof-4 pattern: of every 4 rows, the upper 2 have a narrower field of view, so
    // near the left and right edges rows 2, 3, 6, 7, 10, 11 are empty. Row 12 (the top ring) then
    // has no return in the rows next to it; its physical lower neighbour is row 9.
    assert_eq!(MAX_ROW_GAP, 3);
    let (rows, cols) = (13, 40);
    let mut cloud = SyntheticSensor::forward(rows, cols, -20.0, -5.0, 40.0, 1.8).scan(&[flat_ground()]);
    assert_eq!(cloud.returns(), rows * cols);
    let at = |r: usize, c: usize| r * cols + c;
    let blank = |cloud: &mut OrderedCloud, rows: &[usize]| {
        for &r in rows {
            for c in (0..8).chain(32..cols) {
                cloud.point_in_vehicle[at(r, c)] = Vec3::NAN;
                cloud.range_m[at(r, c)] = f32::NAN;
            }
        }
    };
    blank(&mut cloud, &[2, 3, 6, 7, 10, 11]);
    let view =
        GridView { points: &cloud.point_in_vehicle, ranges: &cloud.range_m, rows, cols, wrap: false, max_col_gap: 2 };
    // The lower neighbours of the top ring at the edge are found three rows down.
    let nb = view.neighbours(12, 4);
    assert_eq!((nb[3], nb[4], nb[5]), (Some(at(9, 5)), Some(at(9, 4)), Some(at(9, 3))));
    assert_eq!((nb[0], nb[1], nb[7]), (None, None, None), "nothing above the top row");
    // Row 4 at the edge looks past the empty rows 3 and 2 to row 1; the centre columns are unchanged.
    assert_eq!(view.neighbours(4, 4)[4], Some(at(1, 4)));
    assert_eq!(view.neighbours(4, 20)[4], Some(at(3, 20)));
    // So flat ground gets g_rho = 1 in every remaining cell, the edges included.
    let f = features(&cloud, false, FeatureParams::default());
    for c in 0..cols {
        for r in [0, 1, 4, 5, 8, 9, 12] {
            assert!(f.g_rho[at(r, c)] > 0.999, "cell ({r}, {c}): g_rho {}", f.g_rho[at(r, c)]);
        }
    }
    // Three empty rows are beyond the search: the top ring at the edge then has only its two row
    // neighbours, no pair normal and no features.
    blank(&mut cloud, &[9]);
    let view =
        GridView { points: &cloud.point_in_vehicle, ranges: &cloud.range_m, rows, cols, wrap: false, max_col_gap: 2 };
    assert_eq!(view.neighbours(12, 4).iter().flatten().count(), 2);
    let f = features(&cloud, false, FeatureParams::default());
    assert_eq!(f.g_rho[at(12, 4)], 0.0);
}
