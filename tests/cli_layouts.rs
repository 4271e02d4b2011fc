//! Recordings as they come, through the binary:
//! - a nuScenes `.pcd.bin` (x y z intensity ring) is read with its true point count and ordered
//!   from its rings; renamed `.bin` it is recognised by its content, never read as KITTI records;
//!   `--layout` names the layout outright; the report says which layout and why;
//! - bad input: a 4-float file named `.pcd.bin`, a size that fits neither layout, rings that are
//!   not whole or beyond 127, an unknown `--layout`, `--layout` on a PCD: each refused naming the
//!   file and the field, nothing written;
//! - a bag of `height = 1`, `is_dense = false` clouds with NaN no-returns (as Ouster drivers
//!   publish them) is classified, the NaN points decided 0 in place; a cloud that declares itself
//!   dense but holds NaNs is read the same way, with a warning;
//! - `eval dataset` on a nuScenes-lidarseg folder (`lidar/*.pcd.bin`, `lidarseg/*_lidarseg.bin`).

use crate::common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use common::{err, files, ok, run, s, tmp};
use sim::io::ros2::BagWriter;
use sim::io::ros2::messages::{Header, PointCloud2, PointField, datatype};

/// Rings of the synthetic HDL-32E sweep, and columns per ring.
const RINGS: usize = 32;
const COLS: usize = 540;
/// The sensor's height above the flat ground, metres (nuScenes' roof LiDAR is about 1.84 m up).
const HEIGHT_M: f32 = 1.84;

/// A synthetic HDL-32E sweep in nuScenes' records, ring by ring: the beams below -2 deg hit flat
/// ground (lidarseg 24, driveable surface) within 60 m, the others a wall 25 m away (28, man-made).
/// Returns the records and the lidarseg class of each.
fn sweep() -> (Vec<[f32; 5]>, Vec<u8>) {
    let (mut records, mut classes) = (Vec::new(), Vec::new());
    for ring in 0..RINGS {
        let el = (-30.67f32 + 1.333 * ring as f32).to_radians();
        for col in 0..COLS {
            let az = col as f32 / COLS as f32 * std::f32::consts::TAU;
            let (range, class) = match HEIGHT_M / -el.sin() {
                r if el < (-2.0f32).to_radians() && r < 60.0 => (r, 24u8),
                _ => (25.0 / el.cos(), 28u8),
            };
            let (h, z) = (range * el.cos(), range * el.sin());
            records.push([h * az.cos(), h * az.sin(), z, (ring * 3 + col % 7) as f32, ring as f32]);
            classes.push(class);
        }
    }
    (records, classes)
}

fn write_sweep(path: &Path) -> usize {
    let (records, _) = sweep();
    std::fs::write(path, sim::io::nuscenes::encode(&records)).unwrap();
    records.len()
}

fn classify(input: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["classify", "--method", "nitsch", "--input", s(input), "--out", s(out)];
    args.extend(extra);
    run(&args)
}

#[test]
fn a_nuscenes_sweep_is_read_by_name_content_or_flag_with_its_rings() {
    let dir = tmp("layouts", "nuscenes");
    let sweep_path = dir.join("n008__LIDAR_TOP__1.pcd.bin");
    let n = write_sweep(&sweep_path);
    // 17,280 points = 345,600 bytes: a multiple of 16 and of 20, so KITTI records would fit too
    // (21,600 of them).
    assert_eq!((n * 20) % 16, 0);
    let out = ok(classify(&sweep_path, &dir.join("by_name"), &[]));
    assert!(out.contains("read as nuScenes .pcd.bin (x y z intensity ring), by its name"), "{out}");
    assert!(out.contains("path ring-field") && out.contains("32 rings with points"), "ordered from the rings: {out}");
    let by_name = std::fs::read(dir.join("by_name/frame_000000.ground")).unwrap();
    assert_eq!(by_name.len(), n, "one decision per nuScenes point, not per KITTI record");
    // Without a rig the sensor is named from the rings' elevations and the grid is its own (32 x
    // 540), not the HDL-64E's 64 x 2,170 on which nitsch called none of the sweep ground.
    assert!(out.contains("sensor matched: hdl32e (32 rings x 540 columns"), "{out}");
    let (_, classes) = sweep();
    let (mut tp, mut fp, mut fn_) = (0usize, 0usize, 0usize);
    for (&d, &c) in by_name.iter().zip(&classes) {
        match (d == 1, c == 24) {
            (true, true) => tp += 1,
            (true, false) => fp += 1,
            (false, true) => fn_ += 1,
            _ => {}
        }
    }
    let f1 = 2.0 * tp as f64 / (2 * tp + fp + fn_) as f64;
    assert!(f1 >= 0.9, "nitsch F1 {f1:.4} on the sweep's flat ground (tp {tp}, fp {fp}, fn {fn_})");

    // Renamed `.bin`: recognised by its content, the same decisions.
    let renamed = dir.join("renamed.bin");
    std::fs::copy(&sweep_path, &renamed).unwrap();
    let out = ok(classify(&renamed, &dir.join("by_content"), &[]));
    assert!(out.contains("renamed.bin: read as nuScenes .pcd.bin (x y z intensity ring), by its content"), "{out}");
    assert_eq!(std::fs::read(dir.join("by_content/frame_000000.ground")).unwrap(), by_name);

    // `--layout nuscenes` names it; `--layout kitti` reads the records the user asked for, and says so.
    let out = ok(classify(&renamed, &dir.join("by_flag"), &["--layout", "nuscenes"]));
    assert!(out.contains("by --layout"), "{out}");
    assert_eq!(std::fs::read(dir.join("by_flag/frame_000000.ground")).unwrap(), by_name);
    // Read as the KITTI records the user asked for, the bytes hold no ring order: refused, never
    // decided on a table they do not fit.
    let e = err(classify(&renamed, &dir.join("as_kitti"), &["--layout", "kitti"]));
    assert!(e.contains("renamed.bin") && e.contains("no ring order can be recovered"), "{e}");
    assert!(!dir.join("as_kitti/frame_000000.ground").exists());

    // bench classify says the layout and what decided it in its JSON.
    let out = ok(run(&["bench", "classify", "--input", s(&renamed), "--repeats", "1"]));
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(json["per_file"][0]["layout"], "nuscenes-bin");
    assert_eq!(json["per_file"][0]["layout_by"], "content");
    assert_eq!(json["per_file"][0]["points"], n);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn files_of_no_layout_bad_rings_and_bad_flags_are_refused_by_name() {
    let dir = tmp("layouts", "refusals");
    let (mut records, _) = sweep();
    records.truncate(64);
    let check = |name: &str, bytes: Vec<u8>, extra: &[&str], wants: &[&str]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let out_dir = dir.join(format!("out-{name}"));
        let e = err(classify(&path, &out_dir, extra));
        for w in wants {
            assert!(e.contains(w), "{name}: wants `{w}`: {e}");
        }
        assert!(!out_dir.exists() || files(&out_dir).is_empty(), "{name}: nothing written");
    };
    // A 4-float (KITTI) file named `.pcd.bin`: 3 records, 48 bytes.
    let kitti: Vec<u8> = [[10.5f32, 0.25, -1.5, 0.5]; 3].iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    check("four.pcd.bin", kitti.clone(), &[], &["four.pcd.bin", "48 bytes", "16-byte KITTI"]);
    // 80 bytes of KITTI records named `.pcd.bin`: the fifth value is no ring.
    let kitti5: Vec<u8> = [[10.5f32, 0.25, -1.5, 0.5]; 5].iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    check("five.pcd.bin", kitti5, &[], &["five.pcd.bin", "point 0 has ring 10.5", "0 ..= 127"]);
    // A size that fits neither layout.
    check("odd.bin", vec![0u8; 42], &[], &["odd.bin", "42 bytes fit neither layout"]);
    // Rings beyond 127 and not whole.
    let mut bad = records.clone();
    bad[7][4] = 200.0;
    check("high.pcd.bin", sim::io::nuscenes::encode(&bad), &[], &["high.pcd.bin", "point 7 has ring 200"]);
    bad[7][4] = 3.5;
    check("half.pcd.bin", sim::io::nuscenes::encode(&bad), &[], &["half.pcd.bin", "point 7 has ring 3.5"]);
    // `--layout nuscenes` on a KITTI file whose size is no whole number of nuScenes records.
    check("k.bin", kitti, &["--layout", "nuscenes"], &["k.bin", "nuScenes layout", "48 bytes"]);
    // An unknown `--layout`: clap lists the allowed values.
    let e = err(classify(&dir.join("k.bin"), &dir.join("out-unknown"), &["--layout", "velodyne"]));
    assert!(e.contains("velodyne") && e.contains("kitti") && e.contains("nuscenes"), "{e}");
    // `--layout` on a PCD.
    let mut cloud = sim::OrderedCloud::empty(1, 4, 1);
    for (i, p) in cloud.point_in_vehicle.iter_mut().enumerate() {
        *p = glam::Vec3::new(5.0, i as f32, -1.0);
    }
    let pcd = dir.join("c.pcd");
    sim::io::pcd::write(&pcd, &cloud, false).unwrap();
    let e = err(classify(&pcd, &dir.join("out-pcd"), &["--layout", "kitti"]));
    assert!(e.contains("c.pcd") && e.contains("--layout kitti applies to headerless .bin files"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A `height = 1`, `width = rows x cols` cloud of a 16-ring sensor (rings bottom-first), x y z
/// intensity ring at 0 4 8 12 16 in a 20-byte point, every `nan_every`-th point a NaN no-return.
fn unorganized_cloud(rows: u32, cols: u32, nan_every: usize, is_dense: bool) -> (PointCloud2<'static>, Vec<bool>) {
    let f = |name: &str, offset: u32, dt: u8| PointField { name: name.into(), offset, datatype: dt, count: 1 };
    let (mut data, mut nan) = (Vec::new(), Vec::new());
    let mut k = 0usize;
    for c in 0..cols {
        for r in 0..rows {
            let el = (-15.0f32 + 2.0 * r as f32).to_radians();
            let az = c as f32 / cols as f32 * std::f32::consts::TAU;
            let range = if el < 0.0 { 1.7 / -el.sin() } else { 20.0 / el.cos() };
            let is_nan = k.is_multiple_of(nan_every);
            let xyz = if is_nan {
                [f32::NAN; 3]
            } else {
                [range * el.cos() * az.cos(), range * el.cos() * az.sin(), range * el.sin()]
            };
            for v in xyz.into_iter().chain([30.0]) {
                data.extend_from_slice(&v.to_le_bytes());
            }
            data.extend_from_slice(&(r as u16).to_le_bytes());
            data.extend_from_slice(&[0, 0]);
            nan.push(is_nan);
            k += 1;
        }
    }
    let width = rows * cols;
    let cloud = PointCloud2 {
        header: Header { frame_id: "os_sensor".into(), ..Header::default() },
        height: 1,
        width,
        fields: vec![
            f("x", 0, datatype::FLOAT32),
            f("y", 4, datatype::FLOAT32),
            f("z", 8, datatype::FLOAT32),
            f("intensity", 12, datatype::FLOAT32),
            f("ring", 16, datatype::UINT16),
        ],
        is_bigendian: false,
        point_step: 20,
        row_step: 20 * width,
        data: std::borrow::Cow::Owned(data),
        is_dense,
    };
    (cloud, nan)
}

fn bag_of(dir: &Path, name: &str, clouds: &[PointCloud2<'_>]) -> PathBuf {
    let mut w = BagWriter::create(&dir.join(name)).unwrap();
    for (k, c) in clouds.iter().enumerate() {
        w.write_pointcloud("/ouster/points", c, k as u64 * 100_000_000, &BTreeMap::new()).unwrap();
    }
    w.finish().unwrap()
}

#[test]
fn nan_no_returns_of_a_one_row_cloud_are_decided_in_place_not_refused() {
    let dir = tmp("layouts", "nan");
    // 18 % of the points are NaN no-returns (Ouster's 23,540 of 131,072 was 18 %).
    let (sparse, nan) = unorganized_cloud(16, 512, 5, false);
    let bag = bag_of(&dir, "sparse", &[sparse.clone(), sparse]);
    let out = ok(classify(&bag, &dir.join("out"), &[]));
    assert!(out.contains("2 messages of /ouster/points classified, 0 skipped"), "{out}");
    assert!(!out.contains("warning"), "{out}");
    let decisions = std::fs::read(dir.join("out/frame_000000.ground")).unwrap();
    assert_eq!(decisions.len(), nan.len(), "one decision per input point, in input order");
    assert!(decisions.iter().zip(&nan).all(|(&d, &n)| !n || d == 0), "a no-return is never ground");
    assert_eq!(std::fs::read(dir.join("out/frame_000001.ground")).unwrap(), decisions);

    // A cloud that says it is dense but holds NaNs: read the same way, with a warning.
    let (dense, _) = unorganized_cloud(16, 512, 5, true);
    let bag = bag_of(&dir, "dense", &[dense]);
    let out = run(&["classify", "--method", "nitsch", "--input", s(&bag), "--out", s(&dir.join("dense_out"))]);
    let stdout = ok(out);
    assert!(
        stdout.contains("1 message(s) of `/ouster/points` declare is_dense = true but hold NaN points")
            && stdout.contains("1639 points"),
        "{stdout}"
    );
    assert_eq!(std::fs::read(dir.join("dense_out/frame_000000.ground")).unwrap(), decisions);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn eval_dataset_scores_a_nuscenes_lidarseg_folder() {
    let dir = tmp("layouts", "lidarseg");
    let data = dir.join("mini");
    std::fs::create_dir_all(data.join("lidar")).unwrap();
    std::fs::create_dir_all(data.join("lidarseg")).unwrap();
    let (records, mut classes) = sweep();
    // A few points of noise and of the ego vehicle: left out.
    classes[0] = 0;
    classes[1] = 31;
    for token in ["a1b2", "c3d4"] {
        std::fs::write(data.join(format!("lidar/{token}.pcd.bin")), sim::io::nuscenes::encode(&records)).unwrap();
        std::fs::write(data.join(format!("lidarseg/{token}_lidarseg.bin")), &classes).unwrap();
    }
    let json = dir.join("scores.json");
    let out = ok(run(&["eval", "dataset", "--input", s(&data), "--methods", "nitsch", "--json", s(&json)]));
    assert!(out.contains("2 frame(s)"), "{out}");
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(doc["format"], "nuscenes-lidarseg");
    let pooled = &doc["methods"]["nitsch"]["pooled"];
    let ground = classes.iter().filter(|&&c| c == 24).count() as u64;
    assert_eq!(pooled["tp"].as_u64().unwrap() + pooled["fn"].as_u64().unwrap(), 2 * ground);
    assert_eq!(pooled["points"].as_u64().unwrap(), 2 * (records.len() as u64 - 2), "noise and ego left out");

    // A sweep without its labels; labels of another length; a class beyond the taxonomy.
    std::fs::remove_file(data.join("lidarseg/c3d4_lidarseg.bin")).unwrap();
    let e = err(run(&["eval", "dataset", "--input", s(&data), "--methods", "nitsch"]));
    assert!(e.contains("c3d4_lidarseg.bin"), "{e}");
    std::fs::write(data.join("lidarseg/c3d4_lidarseg.bin"), &classes[1..]).unwrap();
    let e = err(run(&["eval", "dataset", "--input", s(&data), "--methods", "nitsch"]));
    assert!(e.contains("c3d4_lidarseg.bin") && e.contains(&format!("{} points", records.len())), "{e}");
    let mut bad = classes.clone();
    bad[9] = 40;
    std::fs::write(data.join("lidarseg/c3d4_lidarseg.bin"), &bad).unwrap();
    let e = err(run(&["eval", "dataset", "--input", s(&data), "--methods", "nitsch"]));
    assert!(e.contains("point 9 has class 40") && e.contains("0 ..= 31"), "{e}");
    let e = err(run(&["eval", "dataset", "--input", s(&data), "--methods", "nitsch", "--layout", "kitti"]));
    assert!(e.contains("--layout kitti") && e.contains("nuScenes-lidarseg"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
