//! Ordering recovery on hand-made clouds: scan unfolding of a KITTI-like scan order (with extra
//! wraps at +-pi inside a turn), the beam-table fallback for a shuffled cloud, bad points skipped
//! and counted, bad clouds refused, organized clouds stored top-first or without a ring field.

use classifier::ordering::{
    BeamTable, OrderingPath, OrderingReport, PathChoice, PointAttributes, UnfoldParams, decisions_per_point,
    order_cloud, order_organized,
};
use glam::{Affine3A, Vec3};

/// A 16-laser sensor over a flat floor 1.8 m below, `cols` columns; points in KITTI order (top laser
/// first, each a counter-clockwise turn from the front), with each point's true `(row, col)`.
fn kitti_like(cols: usize) -> (BeamTable, Vec<Vec3>, Vec<(usize, usize)>) {
    let elevations: Vec<f32> = (0..16).map(|i| (-15.0 + 2.0 * i as f32).to_radians()).collect();
    let table = BeamTable::spinning(elevations.clone(), cols);
    let mut pts = Vec::new();
    let mut truth = Vec::new();
    for row in (0..16).rev() {
        let front = cols / 2;
        for k in 0..cols {
            let col = (front + cols - k) % cols;
            let az = table.azimuth_left_rad - table.azimuth_step_rad * col as f32;
            let el = elevations[row];
            // A wall at 30 m for upward beams, the floor for downward ones.
            let r = if el < -0.01 { 1.8 / (-el).sin() } else { 30.0 / el.cos() };
            let d = Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            pts.push(d * r);
            truth.push((row, col));
        }
    }
    (table, pts, truth)
}

/// [`order_cloud`] of points in the vehicle frame (the identity mount) with the default unfolding
/// parameters.
fn order_unmounted(
    points: &[Vec3],
    attributes: &PointAttributes<'_>,
    table: &BeamTable,
    choice: PathChoice,
) -> Result<(sim::OrderedCloud, OrderingReport), classifier::ClassifyError> {
    order_cloud(points, attributes, table, Affine3A::IDENTITY, choice, &UnfoldParams::default())
}

/// Every cell that one point of `pts` went to holds that point (through `vehicle_from_sensor`)
/// and its range from the sensor, `|p|`, to the bit.
fn assert_cells_hold_their_points(
    cloud: &sim::OrderedCloud,
    cell_of_point: &[Option<u32>],
    pts: &[Vec3],
    vehicle_from_sensor: Affine3A,
) {
    let mut count = vec![0u32; cloud.len()];
    for c in cell_of_point.iter().flatten() {
        count[*c as usize] += 1;
    }
    let mut checked = 0;
    for (p, c) in pts.iter().zip(cell_of_point) {
        let Some(c) = c.map(|c| c as usize) else { continue };
        if count[c] == 1 {
            assert_eq!(cloud.range_m[c].to_bits(), p.length().to_bits(), "range of {p:?}");
            assert_eq!(cloud.point_in_vehicle[c], vehicle_from_sensor.transform_point3(*p));
            checked += 1;
        }
    }
    assert!(checked > pts.len() * 9 / 10, "{checked} of {} points checked", pts.len());
}

#[test]
fn scan_order_unfolds_into_true_cells_despite_jitter_at_the_back() {
    let (table, mut pts, truth) = kitti_like(360);
    // Jitter: a point at the back steps just across +-pi and back (an extra wrap inside a turn).
    let back = pts.iter().position(|p| (p.y.atan2(p.x) + std::f32::consts::PI).abs() < 0.012).unwrap();
    pts[back].y = -pts[back].y;
    let (cloud, report) = order_unmounted(&pts, &PointAttributes::default(), &table, PathChoice::Auto).unwrap();
    assert_eq!(report.path, OrderingPath::Unfolded, "{}", report.summary());
    assert_eq!(report.rings_found, 16);
    assert_eq!(report.kept(), pts.len());
    let right =
        truth.iter().enumerate().filter(|&(k, &(r, c))| report.cell_of_point[k] == Some((r * 360 + c) as u32)).count();
    assert!(right >= pts.len() - 2, "{right} of {} in their true cell", pts.len());
    assert_eq!((cloud.rows, cloud.cols), (16, 360));
    assert_cells_hold_their_points(&cloud, &report.cell_of_point, &pts, Affine3A::IDENTITY);
}

#[test]
fn shuffled_points_fall_back_to_the_beam_table_and_bad_points_are_counted() {
    let (table, pts, truth) = kitti_like(360);
    let n = pts.len();
    let mut order: Vec<usize> = (0..n).collect();
    for k in (1..n).rev() {
        order.swap(k, (k * 7919 + 13) % (k + 1));
    }
    let mut shuffled: Vec<Vec3> = order.iter().map(|&k| pts[k]).collect();
    // A handful of bad points and no-returns: skipped, decision 0, counted.
    shuffled[5] = Vec3::new(f32::NAN, 0.0, 0.0);
    shuffled[77] = Vec3::new(0.0, f32::INFINITY, 0.0);
    shuffled[99] = Vec3::ZERO;
    let (cloud, report) = order_unmounted(&shuffled, &PointAttributes::default(), &table, PathChoice::Auto).unwrap();
    assert_eq!(report.path, OrderingPath::BeamTable);
    assert!(report.fallback.is_some(), "{}", report.summary());
    assert_eq!((report.skipped, report.no_returns), (2, 1));
    assert_eq!(report.kept(), n - 3);
    for k in [5, 77, 99] {
        assert_eq!(report.cell_of_point[k], None);
    }
    let right = (0..n)
        .filter(|&k| report.cell_of_point[k] == Some((truth[order[k]].0 * 360 + truth[order[k]].1) as u32))
        .count();
    assert_eq!(right, n - 3);
    // 5,757 usable points: the ranges' blocks of 8 and a partial one.
    assert_cells_hold_their_points(&cloud, &report.cell_of_point, &shuffled, Affine3A::IDENTITY);
    let ground = vec![true; cloud.len()];
    let d = decisions_per_point(&report, &ground);
    assert_eq!((d[5], d[77], d[99], d[0]), (0, 0, 0, 1));
}

#[test]
fn bad_clouds_are_refused() {
    let (table, mut pts, _) = kitti_like(90);
    let attrs = PointAttributes::default();
    let order = |p: &[Vec3]| order_unmounted(p, &attrs, &table, PathChoice::Auto);
    // More than 1 % NaN.
    let n = pts.len();
    for p in pts.iter_mut().take(n / 50) {
        *p = Vec3::NAN;
    }
    let e = order(&pts).unwrap_err().to_string();
    assert!(e.contains("NaN or infinite"), "{e}");
    // One ring in the table.
    let one = BeamTable::spinning(vec![0.0], 90);
    assert!(order_unmounted(&pts[n / 2..], &attrs, &one, PathChoice::Auto).is_err());
    // Unfolding alone on shuffled points: refused, saying why.
    let mut shuffled = pts[n / 2..].to_vec();
    shuffled.reverse();
    shuffled.swap(3, 400);
    shuffled.swap(10, 700);
    let e = order_unmounted(&shuffled, &attrs, &table, PathChoice::Unfold);
    assert!(e.is_err() || e.unwrap().1.rings_found <= 16);
}

#[test]
fn organized_top_first_or_without_ring_gives_the_bottom_first_decisions() {
    let bottom = classifier::synthetic::noisy_cars_frame(0.05, 3, true, 0.01);
    let mut m = classifier::Nitsch::new(Default::default()).unwrap();
    let reference = m.classify(&bottom).unwrap();
    let (rows, cols) = (bottom.rows, bottom.cols);
    // Reverse the rows (ouster-ros: row 0 = ring 0 = top beam).
    let mut top = bottom.clone();
    for k in 0..rows {
        let src = (rows - 1 - k) * cols;
        top.point_in_vehicle[k * cols..(k + 1) * cols].copy_from_slice(&bottom.point_in_vehicle[src..src + cols]);
        top.range_m[k * cols..(k + 1) * cols].copy_from_slice(&bottom.range_m[src..src + cols]);
        top.ring[k * cols..(k + 1) * cols].fill(k as u16);
    }
    for has_ring in [true, false] {
        let (ordered, report) = order_organized(top.clone(), has_ring, Affine3A::IDENTITY).unwrap();
        assert_eq!(report.path, OrderingPath::Organized);
        let d = decisions_per_point(&report, &m.classify(&ordered).unwrap());
        for k in 0..rows {
            for c in 0..cols {
                let want = reference[(rows - 1 - k) * cols + c];
                assert_eq!(d[k * cols + c] == 1, want, "row {k} col {c} (ring field {has_ring})");
            }
        }
    }
    // A ring value out of range, or two rows of one ring: refused.
    let mut bad = top.clone();
    bad.ring[..cols].fill(rows as u16);
    let e = order_organized(bad, true, Affine3A::IDENTITY).unwrap_err().to_string();
    assert!(e.contains("out of range"), "{e}");
    let mut twice = top.clone();
    twice.ring[..cols].fill(1);
    assert!(order_organized(twice, true, Affine3A::IDENTITY).unwrap_err().to_string().contains("more than one row"));
    // A row holding two ring values, the other one in its last cell: refused, naming both.
    let mut mixed = top.clone();
    mixed.ring[2 * cols - 1] = 7;
    let e = order_organized(mixed, true, Affine3A::IDENTITY).unwrap_err().to_string();
    assert!(e.contains("row 1 holds rings 1 and 7"), "{e}");
    // Normals turn with the points into the vehicle frame; a cloud without normals keeps zeros.
    let yaw = Affine3A::from_rotation_z(std::f32::consts::FRAC_PI_2) * Affine3A::from_translation(Vec3::Z);
    let mut no_normals = top.clone();
    no_normals.normal.fill(Vec3::ZERO);
    let (turned, _) = order_organized(no_normals.clone(), true, yaw).unwrap();
    assert!(turned.normal.iter().all(|n| *n == Vec3::ZERO));
    let mut with_normal = no_normals;
    with_normal.normal[5 * cols + 3] = Vec3::X;
    let (turned, _) = order_organized(with_normal, true, yaw).unwrap();
    let moved = turned.normal[(rows - 1 - 5) * cols + 3];
    assert!((moved - Vec3::Y).length() < 1e-6, "{moved}");
    assert_eq!(turned.normal.iter().filter(|n| **n != Vec3::ZERO).count(), 1);
    // No way up to tell: every row the same.
    let mut flat = top.clone();
    let fullest = (0..rows)
        .max_by_key(|&k| top.point_in_vehicle[k * cols..(k + 1) * cols].iter().filter(|p| p.is_finite()).count())
        .unwrap();
    let row0: Vec<Vec3> = flat.point_in_vehicle[fullest * cols..(fullest + 1) * cols].to_vec();
    for k in 1..rows {
        flat.point_in_vehicle[k * cols..(k + 1) * cols].copy_from_slice(&row0);
    }
    let e = order_organized(flat, false, Affine3A::IDENTITY).unwrap_err().to_string();
    assert!(e.contains("cannot tell"), "{e}");
}

#[test]
fn ring_fields_give_rows_top_first_or_bottom_first_and_out_of_range_rings_are_refused() {
    let (table, pts, truth) = kitti_like(360);
    let n = pts.len();
    let mut order: Vec<usize> = (0..n).collect();
    for k in (1..n).rev() {
        order.swap(k, (k * 104_729 + 7) % (k + 1));
    }
    let shuffled: Vec<Vec3> = order.iter().map(|&k| pts[k]).collect();
    for top_first in [true, false] {
        // ouster-ros numbers rings from the top beam, velodyne from the bottom one.
        let rings: Vec<u16> =
            order.iter().map(|&k| if top_first { 15 - truth[k].0 as u16 } else { truth[k].0 as u16 }).collect();
        let attrs = PointAttributes { rings: Some(&rings), ..PointAttributes::default() };
        let (_, report) = order_unmounted(&shuffled, &attrs, &table, PathChoice::Auto).unwrap();
        assert_eq!(report.path, OrderingPath::RingField);
        assert_eq!(report.rings_found, 16);
        for (k, &o) in order.iter().enumerate() {
            assert_eq!(report.cell_of_point[k], Some((truth[o].0 * 360 + truth[o].1) as u32), "point {k}");
        }
    }
    let mut rings = vec![0u16; n];
    rings[17] = 16;
    let attrs = PointAttributes { rings: Some(&rings), ..PointAttributes::default() };
    let e = order_unmounted(&shuffled, &attrs, &table, PathChoice::Auto).unwrap_err().to_string();
    assert!(e.contains("ring 16, out of range"), "{e}");
}

/// A garage seen by a 16-beam sensor in its own frame: the lower beams hit the floor 1.8 m below,
/// the upper ones a ceiling 0.6 m above, which the higher beams meet nearer (on the ceiling the
/// step between neighbouring rings' points is inwards, against the ground's). The rows come out in
/// elevation order whichever way up they are stored; the surface vote alone leaned neither way
/// (a real `garage` scan in the velodyne layout was refused).
#[test]
fn rows_under_a_ceiling_are_put_in_elevation_order() {
    let (rows, cols) = (16, 360);
    let elevation = |g: usize| (-15.0 + 2.0 * g as f32).to_radians();
    let mut bottom = sim::OrderedCloud::empty(rows, cols, 1);
    for g in 0..rows {
        for c in 0..cols {
            let (e, az) = (elevation(g), std::f32::consts::PI - (c as f32 + 0.5) * std::f32::consts::TAU / cols as f32);
            // Floor, ceiling, or (the flattest beams) a wall 12 m away.
            let r = if e < -0.08 {
                1.8 / (-e).sin()
            } else if e > 0.06 {
                (0.6 / e.sin()).min(12.0 / e.cos())
            } else {
                12.0 / e.cos()
            };
            let i = g * cols + c;
            bottom.point_in_vehicle[i] = Vec3::new(e.cos() * az.cos(), e.cos() * az.sin(), e.sin()) * r;
            bottom.range_m[i] = r;
            bottom.ring[i] = g as u16;
        }
    }
    let mut top = bottom.clone();
    for k in 0..rows {
        let src = (rows - 1 - k) * cols;
        top.point_in_vehicle[k * cols..(k + 1) * cols].copy_from_slice(&bottom.point_in_vehicle[src..src + cols]);
        top.range_m[k * cols..(k + 1) * cols].copy_from_slice(&bottom.range_m[src..src + cols]);
    }
    for (stored, top_first) in [(&bottom, false), (&top, true)] {
        let (ordered, report) = order_organized(stored.clone(), false, Affine3A::IDENTITY).unwrap();
        assert_eq!(classifier::ordering::organized::is_top_first(&report, rows, cols), top_first);
        assert_eq!(ordered.point_in_vehicle, bottom.point_in_vehicle, "stored top-first: {top_first}");
    }
}

/// KITTI records (`x y z intensity`) ordered where they lie give the cloud and the report of the
/// same points with their intensities given apart: scan order (unfolded), shuffled with bad
/// points (the beam table), with a transform, and with labels.
#[test]
fn records_order_as_points_with_intensities() {
    let (table, pts, _) = kitti_like(360);
    let n = pts.len();
    let mut shuffled: Vec<Vec3> = (0..n).map(|k| pts[(k * 7919 + 13) % n]).collect();
    shuffled[5] = Vec3::new(f32::NAN, 0.0, 0.0);
    shuffled[99] = Vec3::ZERO;
    let labels: Vec<_> = (0..n).map(|k| sim::SemanticClass(if k % 3 == 0 { 40 } else { 50 })).collect();
    let vehicle_from_sensor = Affine3A::from_translation(Vec3::new(0.5, 0.0, 1.9));
    for (points, transform, with_labels) in
        [(&pts, Affine3A::IDENTITY, false), (&shuffled, vehicle_from_sensor, true), (&pts, vehicle_from_sensor, true)]
    {
        let intensity: Vec<f32> = (0..n).map(|k| (k % 251) as f32 / 250.0).collect();
        let records: Vec<[f32; 4]> = points.iter().zip(&intensity).map(|(p, &i)| [p.x, p.y, p.z, i]).collect();
        let labels = with_labels.then_some(labels.as_slice());
        let apart = PointAttributes { intensity: Some(&intensity), labels, ..PointAttributes::default() };
        let (choice, params) = (PathChoice::Auto, UnfoldParams::default());
        let (want, want_report) = order_cloud(points, &apart, &table, transform, choice, &params).unwrap();
        let own = PointAttributes { labels, ..PointAttributes::default() };
        let (got, got_report) = order_cloud(&records, &own, &table, transform, choice, &params).unwrap();
        assert_eq!(got_report, want_report);
        assert_eq!(got.intensity, want.intensity);
        assert_eq!(got.label, want.label);
        let bits = |c: &sim::OrderedCloud| {
            c.point_in_vehicle.iter().map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>()
        };
        assert_eq!(bits(&got), bits(&want));
        assert!(got.intensity.iter().filter(|&&i| i > 0.0).count() > n / 2);
        assert_cells_hold_their_points(&got, &got_report.cell_of_point, points, transform);
    }
}
