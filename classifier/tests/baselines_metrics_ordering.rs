//! Metrics on hand-made counts, RANSAC on a synthetic plane, ordering recovery of an HDL-64E-like cloud.

use classifier::baselines::ransac::{RansacParams, fit_plane};
use classifier::metrics::{Confusion, range_band};
use classifier::ordering::{BeamTable, order_points};
use classifier::synthetic::SyntheticSensor;
use glam::{Affine3A, Vec3};

#[test]
fn metrics_from_hand_made_counts() {
    let c = Confusion { tp: 80, fp: 5, tn: 95, fn_: 20 };
    assert_eq!(c.total(), 200);
    assert!((c.accuracy() - 175.0 / 200.0).abs() < 1e-12);
    assert!((c.fpr() - 5.0 / 100.0).abs() < 1e-12);
    assert!((c.precision() - 80.0 / 85.0).abs() < 1e-12);
    assert!((c.recall() - 80.0 / 100.0).abs() < 1e-12);
    assert!((c.f1() - 160.0 / 185.0).abs() < 1e-12);
    assert!((c.iou() - 80.0 / 105.0).abs() < 1e-12);
    assert!(Confusion::default().fpr().is_nan());
    assert_eq!((range_band(5.0), range_band(10.0), range_band(39.9), range_band(500.0)), (0, 1, 2, 4));
}

#[test]
fn ransac_finds_a_tilted_plane_among_outliers() {
    // Plane z = 0.1 x - 0.5 sampled on a grid, plus 30 % outliers 1 to 4 m above it.
    let mut pts = Vec::new();
    for i in 0..40 {
        for j in 0..40 {
            let (x, y) = (i as f32 * 0.5, j as f32 * 0.5 - 10.0);
            pts.push(Vec3::new(x, y, 0.1 * x - 0.5));
        }
    }
    let inliers = pts.len();
    for k in 0..700 {
        let f = k as f32;
        let x = (f * 0.37) % 20.0;
        pts.push(Vec3::new(x, (f * 0.91) % 20.0 - 10.0, 0.1 * x - 0.5 + 1.0 + (f * 0.13) % 3.0));
    }
    pts.push(Vec3::NAN);
    let (plane, mask) = fit_plane(&pts, &RansacParams { seed: 3, ..Default::default() }, 0).unwrap().unwrap();
    let expected = Vec3::new(-0.1, 0.0, 1.0).normalize();
    assert!(plane.normal.dot(expected).abs() > 0.9999, "normal {:?}", plane.normal);
    assert_eq!(mask[..inliers].iter().filter(|&&m| m).count(), inliers);
    assert_eq!(mask[inliers..].iter().filter(|&&m| m).count(), 0);
    // Same seed, same answer.
    let again = fit_plane(&pts, &RansacParams { seed: 3, ..Default::default() }, 0).unwrap().unwrap();
    assert_eq!(again.1, mask);
}

#[test]
fn ordering_recovers_the_grid_of_an_hdl64e_like_cloud() {
    let table = BeamTable::hdl64e(900);
    let mut sorted = table.elevations_rad.clone();
    sorted.sort_by(f32::total_cmp);
    let sensor = SyntheticSensor {
        elevations_rad: sorted,
        cols: table.cols,
        azimuth_left_rad: table.azimuth_left_rad,
        azimuth_step_rad: table.azimuth_step_rad,
        origin: Vec3::ZERO,
        max_range_m: 120.0,
    };
    // Ground 1.73 m below the sensor (KITTI), points in the sensor frame.
    let grid = sensor.scan(&[classifier::synthetic::Shape::ground(-1.73, [-150.0, -150.0], [150.0, 150.0])]);
    // Shuffle deterministically.
    let cells: Vec<usize> = (0..grid.len()).filter(|&i| grid.has_return(i)).collect();
    let mut order: Vec<usize> = (0..cells.len()).collect();
    for k in (1..order.len()).rev() {
        order.swap(k, (k * 7919 + 13) % (k + 1));
    }
    let points: Vec<Vec3> = order.iter().map(|&k| grid.point_in_vehicle[cells[k]]).collect();
    let (cloud, report) = order_points(&points, None, &table, Affine3A::IDENTITY).unwrap();
    assert_eq!((cloud.rows, cloud.cols), (64, 900));
    assert_eq!(report.placed, cells.len());
    assert_eq!(report.moved + report.stacked + report.outside, 0);
    for (k, &o) in order.iter().enumerate() {
        assert_eq!(report.cell_of_point[k], Some(cells[o] as u32));
        assert_eq!(cloud.point_in_vehicle[cells[o]], grid.point_in_vehicle[cells[o]]);
    }
    // A bad table is refused.
    assert!(order_points(&points, None, &BeamTable::spinning(vec![0.1], 10), Affine3A::IDENTITY).is_err());
}

#[test]
fn a_point_that_loses_its_cell_moves_to_the_free_adjacent_column() {
    // 4 columns over a full turn (90 degrees each), 2 beams at 0 and 10 degrees elevation.
    let table = BeamTable::spinning(vec![0.0, 10f32.to_radians()], 4);
    // Column 0 is centred at 135 degrees; 130, 100 and 135 degrees all round to column 0.
    let at = |az_deg: f32| Vec3::new(az_deg.to_radians().cos(), az_deg.to_radians().sin(), 0.0) * 10.0;
    let pts = [at(130.0), at(100.0), at(135.0)];
    let (_, report) = order_points(&pts, None, &table, Affine3A::IDENTITY).unwrap();
    // 135 is best centred in column 0. The losers move in input order: 100 takes column 1 (its
    // side), 130, evicted later, finds column 1 taken and takes the nearest free column in its row
    // (column 2): no point is dropped.
    assert_eq!(report.cell_of_point, vec![Some(2), Some(1), Some(0)]);
    assert_eq!((report.placed, report.moved, report.stacked), (1, 2, 0));
}
