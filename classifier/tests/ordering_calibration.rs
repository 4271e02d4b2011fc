//! Calibration files: our TOML and text formats, the velodyne driver's YAML (flow and block style),
//! Ouster's metadata JSON; bad files refused naming the file.

use std::path::Path;

use classifier::ordering::Calibration;

fn parse(name: &str, text: &str, expected: Option<usize>) -> Result<Calibration, String> {
    Calibration::parse(Path::new(name), text, expected).map_err(|e| e.to_string())
}

#[test]
fn toml_and_text_tables() {
    let c = parse(
        "unit.toml",
        "columns = 1024\n[[lasers]]\nelevation_deg = 2.0\nazimuth_offset_deg = -1.5\nvertical_offset_m = 0.2\n[[lasers]]\nelevation_deg = -1.0\n",
        None,
    )
    .unwrap();
    assert_eq!(c.columns, Some(1024));
    assert_eq!(c.lasers.len(), 2);
    assert_eq!(
        (c.lasers[0].elevation_deg, c.lasers[0].azimuth_offset_deg, c.lasers[0].vertical_offset_m),
        (2.0, -1.5, 0.2)
    );
    assert_eq!((c.lasers[1].elevation_deg, c.lasers[1].horizontal_offset_m), (-1.0, 0.0));
    let table = c.to_table(1024);
    assert_eq!(table.cols, 1024);
    assert!((table.elevations_rad[0] - 2f32.to_radians()).abs() < 1e-7);
    assert!((table.vertical_offsets_m[0] - 0.2).abs() < 1e-7);
    let t = parse("unit.txt", "# elevation azimuth\n15.0 0.5\n\n-15.0\n0.0 -0.5  # middle\n", None).unwrap();
    let e: Vec<f64> = t.lasers.iter().map(|l| l.elevation_deg).collect();
    assert_eq!(e, [15.0, -15.0, 0.0]);
    assert_eq!(t.lasers[2].azimuth_offset_deg, -0.5);
}

#[test]
fn velodyne_yaml_flow_and_block_style_in_laser_id_order() {
    let flow = "lasers:\n- {dist_correction: 1.43, laser_id: 1, rot_correction: -0.01, vert_correction: -0.1, vert_offset_correction: 0.2}\n- {laser_id: 0, rot_correction: 0.02, vert_correction: 0.03, horiz_offset_correction: 0.026}\nnum_lasers: 2\ndistance_resolution: 0.002\n";
    let c = parse("hdl.yaml", flow, Some(2)).unwrap();
    assert!((c.lasers[0].elevation_deg - 0.03f64.to_degrees()).abs() < 1e-12);
    assert!((c.lasers[0].azimuth_offset_deg - 0.02f64.to_degrees()).abs() < 1e-12);
    assert_eq!(c.lasers[0].horizontal_offset_m, 0.026);
    assert!((c.lasers[1].elevation_deg + 0.1f64.to_degrees()).abs() < 1e-12);
    assert_eq!(c.lasers[1].vertical_offset_m, 0.2);
    let block = "lasers:\n  - laser_id: 0\n    rot_correction: 0.0\n    vert_correction: -0.2\n  - laser_id: 1\n    rot_correction: 0.0\n    vert_correction: 0.1\nnum_lasers: 2\n";
    let b = parse("vlp.yml", block, None).unwrap();
    assert!((b.lasers[1].elevation_deg - 0.1f64.to_degrees()).abs() < 1e-12);
}

#[test]
fn ouster_metadata_json() {
    let json = r#"{"beam_intrinsics": {"beam_altitude_angles": [16.6, 5.5, -5.5, -16.6], "beam_azimuth_angles": [3.1, 1.0, -1.0, -3.1]}, "config_params": {"lidar_mode": "1024x10"}}"#;
    let c = parse("os1.json", json, Some(4)).unwrap();
    assert_eq!(c.columns, Some(1024));
    assert_eq!(c.lasers[0].elevation_deg, 16.6);
    assert_eq!(c.lasers[3].azimuth_offset_deg, -3.1);
    let flat = r#"{"beam_altitude_angles": [1.0, 0.0], "beam_azimuth_angles": [0.0, 0.0], "lidar_mode": "2048x10"}"#;
    assert_eq!(parse("m.json", flat, None).unwrap().columns, Some(2048));
}

#[test]
fn bad_calibrations_are_refused_naming_the_file() {
    let cases = [
        ("a.txt", "1.0\n0.0\n", Some(64), "2 lasers, but the sensor has 64"),
        ("b.txt", "1.0\nNaN\n", None, "laser 1: elevation NaN"),
        ("c.txt", "1.0\n", None, "1 lasers; needs 2"),
        ("d.txt", "1.0\n1.0\n", None, "two lasers at elevation 1"),
        (
            "e.json",
            r#"{"beam_altitude_angles": [1.0, 0.0], "beam_azimuth_angles": [0.0]}"#,
            None,
            "2 altitude angles but 1",
        ),
        (
            "f.yaml",
            "lasers:\n- {laser_id: 0, vert_correction: 0.1}\n- {laser_id: 0, vert_correction: 0.2}\n",
            None,
            "laser_id 0 repeated",
        ),
        (
            "g.yaml",
            "lasers:\n- {laser_id: 0, vert_correction: 0.1}\n- {laser_id: 1, vert_correction: 0.2}\nnum_lasers: 64\n",
            None,
            "num_lasers 64",
        ),
        ("h.toml", "[[lasers]]\nelevation_deg = 1.0\nspeed = 3\n", None, "unknown field"),
        ("i.xls", "1\n2\n", None, "unknown extension"),
        ("j.txt", "1.0 2.0 3.0\n0.0\n", None, "line 1"),
    ];
    for (name, text, expected, want) in cases {
        let e = parse(name, text, expected).unwrap_err();
        assert!(e.contains(name) && e.contains(want), "{name}: {e}");
    }
    let missing = Calibration::load(Path::new("/nonexistent/unit.toml"), None).unwrap_err().to_string();
    assert!(missing.contains("/nonexistent/unit.toml"), "{missing}");
}
