//! Rings recovered without a sensor given, on hand-made clouds of a sensor no known table matches
//! (20 beams, 1.58 deg apart): ring-major and firing order, single and dual returns, give every
//! point its true cell and name no sensor; a shuffled cloud is refused with a typed error. With the
//! sensor's calibration file (which gives no column count), the same clouds, a shuffled one and a
//! ring field in laser-id order take its lasers and the columns the data shows.

use classifier::ClassifyError;
use classifier::ordering::{
    CloudBuffer, OrderingPath, OrderingReport, PointAttributes, RecoveredOrder, RecoveryError, SensorSetup,
};
use glam::Vec3;

const BEAMS: usize = 20;
const COLS: usize = 1000;

/// The point of beam `row` (0 lowest, -25 .. +5 deg) in column `col` (column 0 just right of +pi,
/// azimuth decreasing), `further` metres beyond the surface it hits (a floor 1.8 m below, walls
/// 30 m away).
fn point(row: usize, col: usize, further: f32) -> Vec3 {
    let el = (-25.0 + 30.0 * row as f32 / (BEAMS - 1) as f32).to_radians();
    let step = std::f32::consts::TAU / COLS as f32;
    let az = std::f32::consts::PI - 0.5 * step - step * col as f32;
    let r = if el < -0.03 { 1.8 / (-el).sin() } else { 30.0 / el.cos() };
    Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin()) * (r + further)
}

/// Every cell in ring-major order (top laser first, each a counter-clockwise turn from the front).
fn ring_major() -> Vec<(usize, usize)> {
    let mut cells = Vec::new();
    for row in (0..BEAMS).rev() {
        for k in 0..COLS {
            cells.push((row, (COLS / 2 + COLS - k) % COLS));
        }
    }
    cells
}

/// Every cell in firing order: column by column (clockwise in time), channels top first.
fn firing() -> Vec<(usize, usize)> {
    (0..COLS).flat_map(|col| (0..BEAMS).rev().map(move |row| (row, col))).collect()
}

fn order(points: &[Vec3]) -> Result<(sim::OrderedCloud, OrderingReport), ClassifyError> {
    let (mut cloud, mut report) = (CloudBuffer::default(), OrderingReport::default());
    SensorSetup::default().order_flat(points, &PointAttributes::default(), &mut cloud, &mut report)?;
    Ok((cloud.into_cloud(), report))
}

#[test]
fn an_unnamed_sensor_is_recovered_in_ring_major_and_firing_order() {
    for (kind, cells) in [(RecoveredOrder::RingMajor, ring_major()), (RecoveredOrder::Firing, firing())] {
        let points: Vec<Vec3> = cells.iter().map(|&(r, c)| point(r, c, 0.0)).collect();
        let (cloud, report) = order(&points).unwrap();
        let sensor = report.sensor.clone().expect("recovered");
        assert_eq!(sensor.model, None, "{}", report.summary());
        assert_eq!((sensor.rings, sensor.rows, sensor.columns, sensor.order), (BEAMS, BEAMS, COLS, kind));
        assert_eq!(sensor.echoes, 1);
        assert!(report.summary().contains("unnamed sensor"), "{}", report.summary());
        let path = if kind == RecoveredOrder::RingMajor { OrderingPath::Unfolded } else { OrderingPath::BeamTable };
        assert_eq!(report.path, path);
        assert_eq!((cloud.rows, cloud.cols), (BEAMS, COLS));
        for (k, &(r, c)) in cells.iter().enumerate() {
            assert_eq!(report.cell_of_point[k], Some((r * COLS + c) as u32), "{kind:?} point {k}");
        }
    }
}

#[test]
fn dual_returns_share_their_first_echo_cell() {
    // Ring-major: the first plane, then every third cell's second echo 2 m further, plane by plane.
    let first = ring_major();
    let seconds: Vec<(usize, usize)> = first.iter().copied().filter(|&(r, c)| (r + c) % 3 == 0).collect();
    // Firing order: per column, the channels' first echoes, then their second echoes.
    let mut fired = Vec::new();
    for col in 0..COLS {
        let column: Vec<(usize, usize, f32)> = (0..BEAMS).rev().map(|r| (r, col, 0.0)).collect();
        fired.extend(column.iter().copied());
        fired.extend(column.iter().filter(|&&(r, c, _)| (r + c) % 3 == 0).map(|&(r, c, _)| (r, c, 2.0)));
    }
    let ring_cells: Vec<(usize, usize, f32)> =
        first.iter().map(|&(r, c)| (r, c, 0.0)).chain(seconds.iter().map(|&(r, c)| (r, c, 2.0))).collect();
    for (kind, cells) in [(RecoveredOrder::RingMajor, ring_cells), (RecoveredOrder::Firing, fired)] {
        let points: Vec<Vec3> = cells.iter().map(|&(r, c, f)| point(r, c, f)).collect();
        let (cloud, report) = order(&points).unwrap();
        let sensor = report.sensor.clone().expect("recovered");
        assert_eq!((sensor.order, sensor.echoes, sensor.rows), (kind, 2, BEAMS), "{}", report.summary());
        let second = cells.iter().filter(|c| c.2 > 0.0).count();
        assert_eq!(report.shared, second, "{}", report.summary());
        assert_eq!(cloud.returns(), BEAMS * COLS);
        for (k, &(r, c, _)) in cells.iter().enumerate() {
            assert_eq!(report.cell_of_point[k], Some((r * COLS + c) as u32), "{kind:?} point {k}");
        }
    }
}

#[test]
fn a_shuffled_cloud_without_a_sensor_is_refused() {
    let cells = ring_major();
    let n = cells.len();
    let points: Vec<Vec3> = (0..n).map(|k| cells[(k * 7919 + 13) % n]).map(|(r, c)| point(r, c, 0.0)).collect();
    let e = order(&points).unwrap_err();
    assert!(matches!(e, ClassifyError::NoOrder(RecoveryError::NoOrder { points: 20_000, .. })), "{e}");
    assert!(e.to_string().contains("no ring order can be recovered from 20000 points"), "{e}");
}

/// An HDL-32E sweep at 20 Hz stored as nuScenes stores it: every firing whole (32 points, bottom
/// laser first, 1,085 firings), the no-returns written as `0, 0, 0` and then moved by the
/// ego-motion compensation to where the sensor was when it fired (0.45 m behind at the first
/// firing, at the origin at the last). Returns the records (x y z intensity), each point's laser
/// (the nuScenes ring) and which points are such no-returns.
fn compensated_hdl32e_sweep() -> (Vec<[f32; 4]>, Vec<u16>, Vec<bool>) {
    let spec = sim::sensor::SensorSpec::default_for("hdl32e").unwrap();
    let mut elevations = spec.pattern().row_elevation_rad.clone();
    elevations.sort_by(f32::total_cmp);
    assert_eq!(elevations.len(), 32);
    let cols = 1085;
    let step = std::f32::consts::TAU / cols as f32;
    let (mut records, mut rings, mut no_return) = (Vec::new(), Vec::new(), Vec::new());
    for col in 0..cols {
        let az = std::f32::consts::PI - 0.5 * step - step * col as f32;
        let behind = 0.45 * (1.0 - col as f32 / (cols - 1) as f32);
        for (laser, &el) in elevations.iter().enumerate() {
            // A fifth of the upper lasers' beams see nothing (sky), scattered.
            let gone = laser >= 20 && (col * 7 + laser * 13) % 5 == 0;
            let p = if gone {
                Vec3::new(-0.001, -behind, -0.01 * behind)
            } else {
                let r = if el < -0.03 { 1.84 / (-el).sin() } else { 25.0 / el.cos() };
                Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin()) * r
            };
            records.push([p.x, p.y, p.z, 10.0]);
            rings.push(laser as u16);
            no_return.push(gone);
        }
    }
    (records, rings, no_return)
}

#[test]
fn motion_compensated_no_returns_are_no_returns_and_a_ring_less_copy_reads_as_its_ring_field() {
    let (records, rings, no_return) = compensated_hdl32e_sweep();
    let gone = no_return.iter().filter(|&&g| g).count();
    let setup = SensorSetup::default();
    // As a nuScenes `.pcd.bin`: lasers from the ring field.
    let (mut cloud, mut with_rings) = (CloudBuffer::default(), OrderingReport::default());
    let attributes = PointAttributes { rings: Some(&rings), ..PointAttributes::default() };
    setup.order_flat(&records, &attributes, &mut cloud, &mut with_rings).unwrap();
    // As a KITTI `.bin` of the same records: a whole image stored firing by firing.
    let (mut cloud, mut ring_less) = (CloudBuffer::default(), OrderingReport::default());
    setup.order_kitti(&records, None, &mut cloud, &mut ring_less).unwrap();
    for (what, report) in [("ring field", &with_rings), ("ring-less", &ring_less)] {
        let sensor = report.sensor.as_ref().expect("recovered");
        assert_eq!((sensor.model, sensor.columns), (Some("hdl32e"), 1085), "{what}: {}", report.summary());
        assert_eq!((report.no_returns, report.too_near), (gone, gone), "{what}: {}", report.summary());
        assert!((report.min_range_m - 0.9).abs() < 1e-6, "{what}: {}", report.summary());
        assert_eq!(report.kept(), records.len() - gone, "{what}: every return kept: {}", report.summary());
        assert!(report.placed as f64 >= 0.999 * report.kept() as f64, "{what}: {}", report.summary());
        for (k, &g) in no_return.iter().enumerate() {
            assert_eq!(report.cell_of_point[k].is_none(), g, "{what}: point {k}");
        }
    }
    assert_eq!(ring_less.sensor.as_ref().unwrap().order, RecoveredOrder::ImageColumns);
    assert_eq!(with_rings.cell_of_point, ring_less.cell_of_point);
}

/// The 20 beams as Hesai's angle-correction CSV: laser ids from the top beam down, then every
/// other one swapped (ids not in elevation order, as Hesai's are not), no column count.
fn calibration_csv(dir: &std::path::Path) -> (std::path::PathBuf, Vec<usize>) {
    // Laser id k (0-based) -> beam row.
    let mut row_of_laser: Vec<usize> = (0..BEAMS).rev().collect();
    for pair in row_of_laser.chunks_mut(4) {
        pair.swap(0, 1);
    }
    let mut text = String::from("Laser id,Elevation,Azimuth\n");
    for (k, &row) in row_of_laser.iter().enumerate() {
        let el = -25.0 + 30.0 * row as f64 / (BEAMS - 1) as f64;
        text.push_str(&format!("{},{el},0\n", k + 1));
    }
    let path = dir.join("angle_correction.csv");
    std::fs::write(&path, text).unwrap();
    (path, row_of_laser)
}

#[test]
fn a_calibration_without_columns_takes_the_order_echoes_and_columns_from_the_data() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, row_of_laser) = calibration_csv(dir.path());
    let setup = SensorSetup::new(None, Some(&csv)).unwrap();
    let run = |points: &[Vec3], rings: Option<&[u16]>| {
        let (mut cloud, mut report) = (CloudBuffer::default(), OrderingReport::default());
        let attributes = PointAttributes { rings, ..PointAttributes::default() };
        setup.order_flat(points, &attributes, &mut cloud, &mut report).map(|()| (cloud.into_cloud(), report))
    };
    // Ring-major, firing order with second echoes, shuffled: the grid the sensor has (not a
    // default column count), every point in its true cell.
    let mut fired = Vec::new();
    for col in 0..COLS {
        fired.extend((0..BEAMS).rev().map(|r| (r, col, 0.0)));
        fired.extend((0..BEAMS).rev().filter(|r| (r + col) % 3 == 0).map(|r| (r, col, 2.0)));
    }
    let ring_cells: Vec<(usize, usize, f32)> = ring_major().into_iter().map(|(r, c)| (r, c, 0.0)).collect();
    let n = ring_cells.len();
    let shuffled: Vec<(usize, usize, f32)> = (0..n).map(|k| ring_cells[(k * 7919 + 13) % n]).collect();
    for (kind, echoes, cells) in [
        (RecoveredOrder::RingMajor, 1, ring_cells),
        (RecoveredOrder::Firing, 2, fired),
        (RecoveredOrder::Elevations, 1, shuffled),
    ] {
        let points: Vec<Vec3> = cells.iter().map(|&(r, c, f)| point(r, c, f)).collect();
        let (cloud, report) = run(&points, None).unwrap();
        let sensor = report.sensor.clone().expect("recovered");
        assert!(sensor.calibrated, "{}", report.summary());
        assert_eq!((sensor.order, sensor.echoes, sensor.rows, sensor.columns), (kind, echoes, BEAMS, COLS));
        assert_eq!(sensor.rings, BEAMS, "{kind:?}: every laser holds points");
        assert_eq!((cloud.rows, cloud.cols), (BEAMS, COLS));
        assert!(
            report.summary().contains("from the calibration file: 20 lasers x 1000 columns"),
            "{}",
            report.summary()
        );
        for (k, &(r, c, _)) in cells.iter().enumerate() {
            assert_eq!(report.cell_of_point[k], Some((r * COLS + c) as u32), "{kind:?} point {k}");
        }
    }
    // A ring field of laser ids (0-based, the calibration's order): each ring takes its laser's row.
    let laser_of_row: Vec<u16> =
        (0..BEAMS).map(|row| row_of_laser.iter().position(|&r| r == row).unwrap() as u16).collect();
    let cells = firing();
    let points: Vec<Vec3> = cells.iter().map(|&(r, c)| point(r, c, 0.0)).collect();
    let rings: Vec<u16> = cells.iter().map(|&(r, _)| laser_of_row[r]).collect();
    let (_, report) = run(&points, Some(&rings)).unwrap();
    let sensor = report.sensor.clone().expect("recovered");
    assert_eq!((sensor.order, sensor.columns, sensor.calibrated), (RecoveredOrder::RingField, COLS, true));
    for (k, &(r, c)) in cells.iter().enumerate() {
        assert_eq!(report.cell_of_point[k], Some((r * COLS + c) as u32), "ring field point {k}");
    }
    // A ring beyond the calibration's lasers is refused, naming the ring.
    let mut beyond = rings.clone();
    beyond[5] = BEAMS as u16;
    let e = run(&points, Some(&beyond)).unwrap_err().to_string();
    assert!(e.contains("ring 20 holds points, out of range 0 ..= 19 (the calibration file's lasers)"), "{e}");
}
