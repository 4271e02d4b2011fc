//! End-to-end scan tests: analytic distances with ideal sensors, rig layouts, determinism across
//! thread counts, multi-echo planes and motion distortion.

use glam::Vec3;
use sim::Rig;
use sim::scan::{ScanConfig, Scanner, scan};
use sim::scene::builtin;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap()
}

#[test]
fn ideal_returns_on_flat_ground_hit_the_analytic_point() {
    let mesh = builtin::flat();
    let rig = Rig::preset("vlp16-roof").unwrap();
    let config = ScanConfig { ideal: true, ..ScanConfig::default() };
    let frame = &scan(&mesh, &rig, &config).unwrap()[0];
    let cloud = &frame.cloud;
    let vehicle_from_sensor = rig.sensors[0].mount.vehicle_from_sensor();
    let pattern = rig.sensors[0].spec.pattern();
    let mut checked = 0;
    for row in 0..cloud.rows {
        for col in 0..cloud.cols {
            let i = cloud.index(0, row, col);
            if !cloud.has_return(i) {
                continue;
            }
            let f = pattern.at(usize::from(cloud.ring[i]), cloud.column[i] as usize).unwrap();
            let origin = vehicle_from_sensor.transform_point3(f.origin_in_sensor);
            let dir = vehicle_from_sensor.transform_vector3(f.dir_in_sensor);
            // Ray-plane z = 0.
            let t = -origin.z / dir.z;
            let expected = origin + dir * t;
            assert!((cloud.point_in_vehicle[i] - expected).length() < 1e-4, "cell ({row},{col})");
            assert!((cloud.range_m[i] - t).abs() < 1e-4);
            assert!(cloud.ground[i]);
            assert!((cloud.normal[i] - Vec3::Z).length() < 1e-5);
            checked += 1;
        }
    }
    // The 8 downward lasers (-15..-1 deg) see the ground within 100 m all round (-1 deg reaches 106 m: out of range).
    assert_eq!(checked, 7 * 1808, "returns of the -15..-3 deg lasers");
}

#[test]
fn rig_layouts_merge_rows_by_elevation_and_share_columns() {
    let mesh = builtin::flat();
    for (name, rows, cols) in [("lux-roof-4", 16, 441), ("lux-highway-7", 28, 882), ("hdl64e-roof", 64, 2083)] {
        let rig = Rig::preset(name).unwrap();
        let scanner = Scanner::new(&mesh, &rig, ScanConfig { ideal: true, ..ScanConfig::default() }).unwrap();
        assert_eq!((scanner.layout().rows, scanner.layout().cols), (rows, cols), "{name}");
        // Rows go up in vehicle-frame elevation: check on the rays of the central merged column.
        let mut last = f32::NEG_INFINITY;
        for row in 0..scanner.rows() {
            let rays = scanner.row_rays(0, row).rays;
            let mid = rays[rays.len() / 2];
            let elev = mid.dir.z.asin();
            assert!(elev >= last - 1e-3, "{name}: row {row} elevation {elev} below {last}");
            last = elev;
        }
    }
}

/// The bytes of every file the writers produce for a frame (all formats).
fn file_bytes(cloud: &sim::OrderedCloud) -> Vec<Vec<u8>> {
    use sim::io::formats::{Formats, FrameContext, write_frame};
    let dir = tempfile::tempdir().unwrap();
    let formats = Formats::parse("pcd,ply,kitti,las").unwrap();
    let files =
        write_frame(dir.path(), cloud, &FrameContext { index: 0, sensor_from_vehicle: None }, &formats).unwrap();
    assert!(files.len() >= 4);
    files.iter().map(|f| std::fs::read(dir.path().join(&f.file)).unwrap()).collect()
}

#[test]
fn output_is_identical_at_one_and_two_threads() {
    let mesh = builtin::flat_objects();
    let rig = Rig::preset("lux-roof-4").unwrap();
    let config =
        ScanConfig { seed: 42, frames: 2, speed_m_per_s: 10.0, yaw_rate_rad_per_s: 0.1, ..ScanConfig::default() };
    let one = pool(1).install(|| scan(&mesh, &rig, &config).unwrap());
    let two = pool(2).install(|| scan(&mesh, &rig, &config).unwrap());
    for (a, b) in one.iter().zip(&two) {
        assert!(file_bytes(&a.cloud) == file_bytes(&b.cloud), "frame {} files differ between 1 and 2 threads", a.index);
    }
    let other_seed = scan(&mesh, &rig, &ScanConfig { seed: 43, ..config.clone() }).unwrap();
    assert!(file_bytes(&one[0].cloud) != file_bytes(&other_seed[0].cloud), "another seed draws other noise");
}

#[test]
fn multi_echo_lux_reports_second_echoes_where_a_beam_straddles_an_edge() {
    let rig = Rig::preset("lux").unwrap();
    // Place a box whose left edge runs exactly through the axis of one beam of the lowest layer at
    // 6 m: one half of the beam hits the box, the other half the ground behind it.
    let flat = builtin::flat();
    let probe = Scanner::new(&flat, &rig, ScanConfig::default()).unwrap();
    let rays = probe.row_rays(0, 0);
    let b = rays.beams.len() / 2;
    let beam = rays.rays[b * rays.sub_rays];
    let p = beam.origin + beam.dir * 6.0;
    let mut mesh = builtin::flat();
    mesh.push_box(
        Vec3::new(p.x, p.y - 3.0, 0.0),
        Vec3::new(p.x + 1.0, p.y, 2.0),
        sim::Surface::object(sim::SemanticClass::OTHER_OBJECT, 9),
    );
    let frame = &scan(&mesh, &rig, &ScanConfig::default()).unwrap()[0];
    let c = &frame.cloud;
    assert_eq!(c.planes, 3);
    let plane_cells = c.rows * c.cols;
    let second: Vec<usize> = (plane_cells..2 * plane_cells).filter(|&i| c.has_return(i)).collect();
    assert!(!second.is_empty(), "the straddled beam reports a second echo");
    for &i in &second {
        let first = i - plane_cells;
        assert!(c.has_return(first), "a second echo has a first");
        assert!(c.range_m[i] >= c.range_m[first] + 1.0 - 0.2, "echoes are at least the separation apart");
        assert_eq!(c.echo[i], 1);
        assert_eq!(c.instance[first], 9, "first echo on the box");
        assert!(c.ground[i], "second echo on the ground behind");
    }
    let ideal = &scan(&mesh, &rig, &ScanConfig { ideal: true, ..ScanConfig::default() }).unwrap()[0];
    assert_eq!(ideal.cloud.planes, 1, "ideal scans report one echo");
}

#[test]
fn a_moving_vehicle_shows_motion_distortion_and_poses() {
    let mesh = builtin::flat_objects();
    let rig = Rig::preset("vlp16-roof").unwrap();
    let still = &scan(&mesh, &rig, &ScanConfig { ideal: true, ..ScanConfig::default() }).unwrap()[0];
    let config = ScanConfig { ideal: true, frames: 3, speed_m_per_s: 20.0, ..ScanConfig::default() };
    let moving = scan(&mesh, &rig, &config).unwrap();
    // Frame k starts at k * 0.1 s, 2 m further along x.
    for f in &moving {
        assert!((f.vehicle_pose.x_m - 2.0 * f.index as f64).abs() < 1e-9);
        assert!(f.vehicle_pose.z_m.abs() < 1e-6, "flat ground under the wheels");
    }
    // The box front face (x = 9.5 m in the world) is seen in the vehicle frame nearer by speed * shot time.
    let c = &moving[0].cloud;
    let mut checked = 0;
    for i in 0..c.len() {
        if c.has_return(i) && c.instance[i] == 1 && c.normal[i].x < -0.99 {
            let t = c.time_s[i];
            let expected_x = 9.5 - 20.0 * t as f32;
            assert!(
                (c.point_in_vehicle[i].x - expected_x).abs() < 1e-3,
                "x {} vs {expected_x}",
                c.point_in_vehicle[i].x
            );
            checked += 1;
        }
    }
    assert!(checked > 10, "box face seen ({checked} points)");
    assert_ne!(still.cloud.returns(), 0);
}

#[cfg(feature = "reference")]
#[test]
fn the_reference_backend_gives_the_same_ideal_scan() {
    let mesh = builtin::flat_objects();
    let rig = Rig::preset("lux").unwrap();
    let a = &scan(&mesh, &rig, &ScanConfig { ideal: true, ..ScanConfig::default() }).unwrap()[0].cloud;
    let b =
        &scan(&mesh, &rig, &ScanConfig { ideal: true, backend: sim::cast::Backend::Parry, ..ScanConfig::default() })
            .unwrap()[0]
            .cloud;
    assert_eq!(a.returns(), b.returns());
    for i in 0..a.len() {
        if a.has_return(i) {
            assert!((a.range_m[i] - b.range_m[i]).abs() < 1e-4);
            assert_eq!(a.label[i], b.label[i]);
        }
    }
}

#[test]
fn bad_config_is_refused_with_the_field_named() {
    let mesh = builtin::flat();
    let rig = Rig::preset("lux").unwrap();
    for (config, field) in [
        (ScanConfig { frames: 0, ..ScanConfig::default() }, "frames"),
        (ScanConfig { speed_m_per_s: f32::NAN, ..ScanConfig::default() }, "speed_m_per_s"),
        (ScanConfig { yaw_rate_rad_per_s: 50.0, ..ScanConfig::default() }, "yaw_rate_rad_per_s"),
    ] {
        let err = Scanner::new(&mesh, &rig, config).err().expect("refused").to_string();
        assert!(err.contains(field), "{err}");
    }
}
