//! The ROS drivers' organized PCD layouts (`sim::io::pcd::PcdLayout`): what each writes, and that
//! the reader follows their conventions (top-first ouster rows, zero no-returns, millimetre
//! `range`, nanosecond `t`) and refuses broken files naming them.

use std::path::Path;

use glam::{Affine3A, Vec3};
use sim::OrderedCloud;
use sim::io::pcd::{PcdLayout, encode_layout, read_bytes_with_info};
use sim::scene::SemanticClass;

/// 6 rows x 20 columns; every 5th cell without a return.
fn cloud() -> OrderedCloud {
    let (rows, cols) = (6, 20);
    let mut c = OrderedCloud::empty(rows, cols, 1);
    for row in 0..rows {
        for col in 0..cols {
            let i = row * cols + col;
            c.ring[i] = row as u16;
            c.time_s[i] = 0.5 + 1e-4 * col as f64;
            if i % 5 == 2 {
                continue;
            }
            let az = col as f32 * 0.3;
            let p = Vec3::new((4.0 + row as f32) * az.cos(), (4.0 + row as f32) * az.sin(), -1.5 + 0.4 * row as f32);
            c.point_in_vehicle[i] = p;
            c.range_m[i] = p.length();
            c.intensity[i] = 0.5;
            c.label[i] = if row < 3 { SemanticClass::ROAD } else { SemanticClass::BUILDING };
            c.ground[i] = row < 3;
        }
    }
    c
}

#[test]
fn layout_names_parse_and_unknown_ones_are_refused() {
    for name in PcdLayout::NAMES {
        assert_eq!(PcdLayout::parse(name).unwrap().name(), name);
    }
    let e = PcdLayout::parse("livox").unwrap_err().to_string();
    assert!(e.contains("livox") && e.contains("groundtruth, velodyne, ouster"), "{e}");
}

#[test]
fn velodyne_layout_is_bottom_first_with_nan_no_returns() {
    let c = cloud();
    let bytes = encode_layout(&c, PcdLayout::Velodyne, false, None).unwrap();
    let text = String::from_utf8_lossy(&bytes[..300]).to_string();
    assert!(text.contains("FIELDS x y z intensity ring time label\n"), "{text}");
    assert!(text.contains("WIDTH 20\nHEIGHT 6\n") && !text.contains("groundtruth"), "{text}");
    let (back, info) = read_bytes_with_info(Path::new("v.pcd"), &bytes).unwrap();
    assert!(info.has_ring && info.organized && !info.ours && !info.range_in_mm);
    assert_eq!(info.zero_cells, 0);
    for i in 0..c.len() {
        assert_eq!(back.ring[i], c.ring[i]);
        assert_eq!(back.has_return(i), c.has_return(i), "cell {i}");
        if c.has_return(i) {
            assert_eq!(back.point_in_vehicle[i], c.point_in_vehicle[i]);
            assert_eq!(back.label[i], c.label[i]);
            assert!((back.time_s[i] - (c.time_s[i] - 0.5)).abs() < 1e-6);
        }
    }
}

#[test]
fn ouster_layout_is_top_first_with_zero_no_returns_and_millimetre_ranges() {
    let c = cloud();
    let (rows, cols) = (c.rows, c.cols);
    // In the sensor frame, as the driver writes.
    let sensor_from_vehicle = Affine3A::from_translation(Vec3::new(0.0, 0.0, -1.8));
    let bytes = encode_layout(&c, PcdLayout::Ouster, false, Some(&sensor_from_vehicle)).unwrap();
    let text = String::from_utf8_lossy(&bytes[..300]).to_string();
    assert!(text.contains("FIELDS x y z intensity t reflectivity ring ambient range label\n"), "{text}");
    assert!(text.contains("TYPE F F F F U U U U U U\n"), "{text}");
    let (back, info) = read_bytes_with_info(Path::new("o.pcd"), &bytes).unwrap();
    assert!(info.has_ring && info.range_in_mm && info.time_in_ns);
    assert_eq!(info.zero_cells, c.len() - c.returns());
    for k in 0..rows {
        for col in 0..cols {
            // File row k = ring k = grid row rows - 1 - k (the top beam first).
            let (i, g) = (k * cols + col, (rows - 1 - k) * cols + col);
            assert_eq!(back.ring[i], k as u16);
            assert_eq!(back.has_return(i), c.has_return(g), "file cell {i}");
            if c.has_return(g) {
                let p = sensor_from_vehicle.transform_point3(c.point_in_vehicle[g]);
                assert!((back.point_in_vehicle[i] - p).length() < 1e-5);
                assert!((back.range_m[i] - c.range_m[g]).abs() <= 0.0005, "{} vs {}", back.range_m[i], c.range_m[g]);
                assert!((back.time_s[i] - (c.time_s[g] - 0.5)).abs() < 1e-8);
                assert_eq!(back.label[i], c.label[g]);
            }
        }
    }
}

#[test]
fn truncated_layout_files_are_refused_naming_the_file() {
    let c = cloud();
    for layout in [PcdLayout::Velodyne, PcdLayout::Ouster] {
        let bytes = encode_layout(&c, layout, false, None).unwrap();
        let e = read_bytes_with_info(Path::new("cut.pcd"), &bytes[..bytes.len() - 7]).unwrap_err().to_string();
        assert!(e.contains("cut.pcd"), "{e}");
    }
}

#[test]
fn reading_into_a_used_cloud_gives_what_a_fresh_one_gets() {
    // A cloud whose every field is set away from the defaults, in a larger grid.
    let mut big = OrderedCloud::empty(9, 30, 1);
    for i in 0..big.len() {
        big.point_in_vehicle[i] = Vec3::new(1.0 + i as f32, 2.0, 3.0);
        big.range_m[i] = 4.0;
        big.intensity[i] = 0.9;
        big.ring[i] = 7;
        big.column[i] = 3;
        big.sensor[i] = 2;
        big.time_s[i] = 0.25;
        big.echo[i] = 0;
        big.label[i] = SemanticClass::CAR;
        big.instance[i] = 11;
        big.ground[i] = true;
        big.normal[i] = Vec3::Z;
    }
    let c = cloud();
    let xyz_only = {
        let mut t = String::from(
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n",
        );
        t.push_str("1 2 3\nnan nan nan\n0 0 0\n");
        t.into_bytes()
    };
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("ours.pcd", sim::io::pcd::encode(&c, false).unwrap()),
        ("ours_ascii.pcd", sim::io::pcd::encode(&c, true).unwrap()),
        ("velodyne.pcd", encode_layout(&c, PcdLayout::Velodyne, false, None).unwrap()),
        ("ouster.pcd", encode_layout(&c, PcdLayout::Ouster, false, None).unwrap()),
        ("xyz.pcd", xyz_only),
    ];
    for (name, bytes) in &files {
        let path = Path::new(name);
        let (fresh, _) = read_bytes_with_info(path, bytes).unwrap();
        for (before_name, before) in &files {
            let mut used = big.clone();
            sim::io::pcd::read_bytes_into(Path::new(before_name), before, &mut used).unwrap();
            used.range_m.iter_mut().for_each(|r| *r += 1.0);
            sim::io::pcd::read_bytes_into(path, bytes, &mut used).unwrap();
            // Debug output compares NaN no-returns as equal.
            assert_eq!(format!("{used:?}"), format!("{fresh:?}"), "{name} read after {before_name}");
        }
        let mut used = big.clone();
        sim::io::pcd::read_bytes_into(path, bytes, &mut used).unwrap();
        assert_eq!(format!("{used:?}"), format!("{fresh:?}"), "{name} read into a larger used cloud");
    }
}

/// nebula's Hesai and RoboSense clouds name the laser `channel`: read as the ring (and `ring`
/// wins where a file has both).
#[test]
fn nebula_channel_field_is_the_ring() {
    let body: Vec<u8> = [(1.0f32, 2u16, 9u16), (2.0, 5, 11)]
        .iter()
        .flat_map(|&(x, channel, ring)| {
            let mut rec = Vec::new();
            for v in [x, 0.5, -1.0] {
                rec.extend_from_slice(&v.to_le_bytes());
            }
            rec.extend_from_slice(&channel.to_le_bytes());
            rec.extend_from_slice(&ring.to_le_bytes());
            rec
        })
        .collect();
    let file = |fields: &str| {
        let mut f = format!(
            "VERSION 0.7\nFIELDS {fields}\nSIZE 4 4 4 2 2\nTYPE F F F U U\nCOUNT 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA binary\n"
        )
        .into_bytes();
        f.extend_from_slice(&body);
        f
    };
    let (cloud, info) = read_bytes_with_info(Path::new("nebula.pcd"), &file("x y z channel other")).unwrap();
    assert!(info.has_ring);
    assert_eq!(cloud.ring, vec![2, 5]);
    let (cloud, _) = read_bytes_with_info(Path::new("both.pcd"), &file("x y z channel ring")).unwrap();
    assert_eq!(cloud.ring, vec![9, 11]);
}
