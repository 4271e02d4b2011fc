//! Round trips of every frame writer (PCD binary and ASCII, PLY, KITTI, LAS) and the errors the
//! readers give for wrong, truncated or inconsistent files.

use std::path::Path;

use glam::{Affine3A, Vec3};
use sim::io::formats::{FrameContext, write_frame};
use sim::io::{kitti, las as las_io, pcd, ply};
use sim::scene::ply::{read_mesh, write_mesh};
use sim::{OrderedCloud, SceneMesh, SemanticClass, SimError, Surface};

/// A synthetic `planes x rows x cols` cloud: every 7th cell has no return; the rest lie on a
/// ground ring (lower half of the rows) or on a wall (upper half), with varied fields.
fn synthetic(rows: usize, cols: usize, planes: usize) -> OrderedCloud {
    let mut c = OrderedCloud::empty(rows, cols, planes);
    for plane in 0..planes {
        for row in 0..rows {
            for col in 0..cols {
                let i = c.index(plane, row, col);
                c.ring[i] = row as u16;
                c.column[i] = col as u32;
                c.sensor[i] = (col % 3) as u8;
                c.time_s[i] = 1.0e-5 * i as f64 + 0.1;
                if i % 7 == 3 || (plane > 0 && col % 2 == 0) {
                    continue;
                }
                let az = col as f32 / cols as f32 * std::f32::consts::TAU;
                let ground = row < rows / 2;
                let r = if ground { 5.0 + row as f32 } else { 20.0 + 0.5 * plane as f32 };
                let p = Vec3::new(r * az.cos(), r * az.sin(), if ground { -1.8 } else { row as f32 * 0.3 });
                c.point_in_vehicle[i] = p;
                c.range_m[i] = p.length();
                c.intensity[i] = (i % 100) as f32 / 99.0;
                c.echo[i] = plane as u8;
                let class = if ground {
                    [SemanticClass::ROAD, SemanticClass::TERRAIN][col % 2]
                } else {
                    [SemanticClass::CAR, SemanticClass::BUILDING, SemanticClass::VEGETATION][col % 3]
                };
                c.label[i] = class;
                c.instance[i] = if ground { 0 } else { 1 + (col as u32 % 70_000) };
                c.ground[i] = ground;
                c.normal[i] = if ground { Vec3::Z } else { -p.normalize() };
            }
        }
    }
    c
}

/// Asserts `b` (read back) equals `a` cell by cell, NaN matching NaN.
fn assert_same_grid(a: &OrderedCloud, b: &OrderedCloud) {
    assert_eq!((a.rows, a.cols, a.planes), (b.rows, b.cols, b.planes));
    for i in 0..a.len() {
        let (pa, pb) = (a.point_in_vehicle[i], b.point_in_vehicle[i]);
        assert!(pa == pb || (pa.is_nan() && pb.is_nan()), "cell {i}: {pa} vs {pb}");
        let (ra, rb) = (a.range_m[i], b.range_m[i]);
        assert!(ra == rb || (ra.is_nan() && rb.is_nan()), "cell {i} range");
        assert_eq!(a.intensity[i], b.intensity[i], "cell {i} intensity");
        assert_eq!(a.ring[i], b.ring[i]);
        assert_eq!(a.column[i], b.column[i]);
        assert_eq!(a.sensor[i], b.sensor[i]);
        assert_eq!(a.time_s[i], b.time_s[i], "cell {i} time");
        assert_eq!(a.echo[i], b.echo[i]);
        assert_eq!(a.label[i], b.label[i]);
        assert_eq!(a.instance[i], b.instance[i]);
        assert_eq!(a.ground[i], b.ground[i]);
        assert_eq!(a.normal[i], b.normal[i]);
    }
}

/// The returns of `a` in grid order.
fn returns(a: &OrderedCloud) -> Vec<usize> {
    (0..a.len()).filter(|&i| a.has_return(i)).collect()
}

fn bad_file_message(e: SimError, path: &Path) -> String {
    match e {
        SimError::BadFile { path: p, message } => {
            assert_eq!(p, path, "the error names the file");
            message
        }
        other => panic!("expected BadFile, got {other}"),
    }
}

#[test]
fn pcd_binary_and_ascii_round_trip_every_field() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = synthetic(6, 40, 2);
    for ascii in [false, true] {
        let path = dir.path().join(format!("a{ascii}.pcd"));
        assert_eq!(pcd::write(&path, &cloud, ascii).unwrap(), 6 * 40 * 2);
        let text = std::fs::read(&path).unwrap();
        let head = String::from_utf8_lossy(&text[..600]);
        assert!(head.contains("WIDTH 40\nHEIGHT 12\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 480\n"), "{head}");
        let back = pcd::read(&path).unwrap();
        assert_same_grid(&cloud, &back);
    }
}

#[test]
fn ply_round_trip_returns_in_grid_order() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = synthetic(8, 30, 1);
    let path = dir.path().join("a.ply");
    let n = ply::write(&path, &cloud).unwrap();
    let idx = returns(&cloud);
    assert_eq!(n, idx.len());
    let back = ply::read(&path).unwrap();
    assert_eq!((back.rows, back.cols), (1, idx.len()));
    for (k, &i) in idx.iter().enumerate() {
        assert_eq!(back.point_in_vehicle[k], cloud.point_in_vehicle[i]);
        assert_eq!(back.intensity[k], cloud.intensity[i]);
        assert_eq!(back.ring[k], cloud.ring[i]);
        assert_eq!(back.time_s[k], cloud.time_s[i]);
        assert_eq!(back.label[k], cloud.label[i]);
        assert_eq!(back.instance[k], cloud.instance[i]);
        assert_eq!(back.ground[k], cloud.ground[i]);
        assert_eq!(back.normal[k], cloud.normal[i]);
    }
}

#[test]
fn kitti_round_trip_in_sensor_frame_with_calibration() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = synthetic(8, 30, 1);
    let vehicle_from_sensor = Affine3A::from_rotation_translation(
        glam::Quat::from_rotation_z(0.3) * glam::Quat::from_rotation_y(-0.05),
        Vec3::new(1.2, 0.0, 1.9),
    );
    let ctx = FrameContext { index: 7, sensor_from_vehicle: Some(vehicle_from_sensor.inverse()) };
    let formats = sim::io::formats::Formats { kitti: true, ..Default::default() };
    let files = write_frame(dir.path(), &cloud, &ctx, &formats).unwrap();
    let names: Vec<&str> = files.iter().map(|f| f.file.as_str()).collect();
    assert_eq!(names, ["frame_000007.bin", "frame_000007.label", "frame_000007.calib.txt"]);
    // The file holds the returns in scan order: top row first, each row from the front column
    // (cols / 2) counter-clockwise (down the columns, wrapping).
    let idx = kitti::scan_order(&cloud);
    let mut sorted = idx.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, returns(&cloud));
    assert!(idx.windows(2).all(|w| w[0] / cloud.cols >= w[1] / cloud.cols), "rows go down");
    assert_eq!(files[0].points, idx.len());
    assert_eq!(files[1].points, idx.len());
    let bin = dir.path().join("frame_000007.bin");
    let back = kitti::read(&bin, Some(&dir.path().join("frame_000007.label"))).unwrap();
    let calib_path = dir.path().join("frame_000007.calib.txt");
    let tr = kitti::parse_calib(&calib_path, &std::fs::read_to_string(&calib_path).unwrap()).unwrap();
    for (k, &i) in idx.iter().enumerate() {
        let p = tr.transform_point3(back.point_in_vehicle[k]);
        assert!((p - cloud.point_in_vehicle[i]).length() < 1e-4, "point {k}: {p} vs {}", cloud.point_in_vehicle[i]);
        assert_eq!(back.intensity[k], cloud.intensity[i]);
        assert_eq!(back.label[k], cloud.label[i]);
        assert_eq!(back.instance[k], cloud.instance[i] & 0xFFFF);
        assert_eq!(back.ground[k], cloud.ground[i]);
    }
}

#[test]
fn las_points_classes_time_and_ring() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = synthetic(8, 30, 1);
    let path = dir.path().join("a.las");
    let n = las_io::write(&path, &cloud).unwrap();
    let idx = returns(&cloud);
    assert_eq!(n, idx.len());
    let mut reader = las::Reader::from_path(&path).unwrap();
    assert_eq!(reader.header().version(), las::Version::new(1, 4));
    let points: Vec<las::Point> = reader.read_all().unwrap().points().map(|p| p.unwrap()).collect();
    assert_eq!(points.len(), idx.len());
    let class2 = points.iter().filter(|p| p.classification == las::point::Classification::Ground).count();
    assert_eq!(class2, cloud.ground_returns());
    for (p, &i) in points.iter().zip(&idx) {
        let q = cloud.point_in_vehicle[i];
        assert!((p.x - f64::from(q.x)).abs() <= 0.6e-4 && (p.z - f64::from(q.z)).abs() <= 0.6e-4);
        assert_eq!(p.gps_time, Some(cloud.time_s[i]));
        assert_eq!(p.point_source_id, cloud.ring[i]);
        assert_eq!(u16::from(p.user_data), cloud.label[i].0);
        assert_eq!(p.extra_bytes, cloud.instance[i].to_le_bytes().to_vec());
        let expect = las_io::asprs_class(cloud.label[i], cloud.ground[i]);
        assert_eq!(u8::from(p.classification), expect);
    }
    assert_eq!(las_io::asprs_class(SemanticClass::BUILDING, false), 6);
    assert_eq!(las_io::asprs_class(SemanticClass::CAR, false), 64);
}

#[test]
fn write_frame_lists_every_file_with_counts() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = synthetic(4, 50, 1);
    let ctx = FrameContext { index: 0, sensor_from_vehicle: None };
    let formats = sim::io::formats::Formats::parse("pcd,ply,kitti,las").unwrap();
    let files = write_frame(dir.path(), &cloud, &ctx, &formats).unwrap();
    let got: Vec<(&str, &str, usize)> = files.iter().map(|f| (f.file.as_str(), f.format.as_str(), f.points)).collect();
    let r = cloud.returns();
    assert_eq!(
        got,
        [
            ("frame_000000.pcd", "pcd", 200),
            ("frame_000000.ply", "ply", r),
            ("frame_000000.bin", "kitti-bin", r),
            ("frame_000000.label", "kitti-label", r),
            ("frame_000000.las", "las", r),
        ]
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 5, "no temp files left");
    let e = sim::io::formats::Formats::parse("pcd,xyz").unwrap_err().to_string();
    assert!(e.contains("xyz") && e.contains("pcd, pcd-ascii, ply, kitti, las"), "{e}");
    if !cfg!(feature = "laz") {
        let e = sim::io::formats::Formats::parse("laz").unwrap_err().to_string();
        assert!(e.contains("--features sim/laz"), "{e}");
    }
}

#[test]
fn pcd_header_that_disagrees_with_data_is_refused() {
    let cloud = synthetic(2, 10, 1);
    let bytes = pcd::encode(&cloud, false).unwrap();
    let path = Path::new("t.pcd");
    let m = bad_file_message(pcd::read_bytes(path, &bytes[..bytes.len() - 5]).unwrap_err(), path);
    assert!(m.contains("declares 20 points") && m.contains("holds"), "{m}");
    // Bytes after the declared records (a tool that wrote a few more, as a real PandarQT frame
    // has): the declared points read, the rest counted and left unread, as PCL reads the file.
    let mut longer = bytes.clone();
    longer.extend_from_slice(&[0xAB; 37]);
    let frame = pcd::PcdFrame::parse(path, &longer).unwrap();
    assert_eq!(frame.trailing_bytes(), 37);
    let same = |b: &[u8]| pcd::encode(&pcd::read_bytes(path, b).unwrap(), false).unwrap();
    assert_eq!(same(&longer), same(&bytes));
    assert_eq!(pcd::PcdFrame::parse(path, &bytes).unwrap().trailing_bytes(), 0);
    let text = String::from_utf8_lossy(&pcd::encode(&cloud, true).unwrap()).replace("POINTS 20", "POINTS 21");
    let m = bad_file_message(pcd::read_bytes(path, text.as_bytes()).unwrap_err(), path);
    assert!(m.contains("POINTS 21"), "{m}");
    let text =
        String::from_utf8_lossy(&pcd::encode(&cloud, true).unwrap()).replace("DATA ascii", "DATA binary_compressed");
    let m = bad_file_message(pcd::read_bytes(path, text.as_bytes()).unwrap_err(), path);
    assert!(m.contains("binary_compressed") && m.contains("uncompressed size"), "{m}");
}

/// PCL's `binary_compressed`: our binary records made field-major and LZF-coded (literal runs
/// only, which is valid LZF) read back as the same grid.
#[test]
fn pcd_binary_compressed_reads_back() {
    let cloud = synthetic(3, 9, 1);
    let bin = pcd::encode(&cloud, false).unwrap();
    let data_at = bin.windows(12).position(|w| w == b"DATA binary\n").unwrap() + 12;
    let (header, records) = bin.split_at(data_at);
    let sizes = [4usize, 4, 4, 4, 2, 8, 4, 4, 1, 4, 1, 1, 4, 4, 4, 4];
    let rec = sizes.iter().sum::<usize>();
    assert_eq!(rec, pcd::RECORD_BYTES);
    let n = records.len() / rec;
    let mut fields = Vec::new();
    let mut offset = 0;
    for s in sizes {
        for i in 0..n {
            fields.extend_from_slice(&records[i * rec + offset..i * rec + offset + s]);
        }
        offset += s;
    }
    let mut lzf = Vec::new();
    for chunk in fields.chunks(32) {
        lzf.push((chunk.len() - 1) as u8);
        lzf.extend_from_slice(chunk);
    }
    let mut file = String::from_utf8_lossy(header).replace("DATA binary", "DATA binary_compressed").into_bytes();
    file.extend_from_slice(&(lzf.len() as u32).to_le_bytes());
    file.extend_from_slice(&(fields.len() as u32).to_le_bytes());
    file.extend_from_slice(&lzf);
    let back = pcd::read_bytes(Path::new("c.pcd"), &file).unwrap();
    assert_same_grid(&cloud, &back);
    let m =
        bad_file_message(pcd::read_bytes(Path::new("c.pcd"), &file[..file.len() - 3]).unwrap_err(), Path::new("c.pcd"));
    assert!(m.contains("compressed size"), "{m}");
}

#[test]
fn foreign_pcd_unorganized_with_other_types() {
    let path = Path::new("foreign.pcd");
    let text = "# made elsewhere\nVERSION .7\nFIELDS x y z rgb label\nSIZE 8 8 8 4 2\nTYPE F F F U I\nCOUNT 1 1 1 1 1\n\
                WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3 0 40\nnan nan nan 0 0\n-4.5 0 0.25 7 10\n";
    let c = pcd::read_bytes(path, text.as_bytes()).unwrap();
    assert_eq!((c.rows, c.cols, c.returns()), (1, 3, 2));
    assert_eq!(c.point_in_vehicle[2], Vec3::new(-4.5, 0.0, 0.25));
    assert_eq!(c.label[0], SemanticClass::ROAD);
    assert!(c.ground[0] && !c.ground[2], "ground from the label when there is no ground field");
    assert!((c.range_m[0] - 14f32.sqrt()).abs() < 1e-6);
}

#[test]
fn kitti_label_length_must_match_bin() {
    let bin = vec![0u8; 16 * 5];
    let label = vec![0u8; 4 * 4];
    let (bp, lp) = (Path::new("x.bin"), Path::new("x.label"));
    let m = bad_file_message(kitti::read_bytes(bp, &bin, Some((lp, &label))).unwrap_err(), lp);
    assert!(m.contains("4 labels") && m.contains("5 points"), "{m}");
    let m = bad_file_message(kitti::read_bytes(bp, &bin[..70], None).unwrap_err(), bp);
    assert!(m.contains("not a multiple of 16"), "{m}");
}

/// The records read in place where the bytes are aligned, decoded where they are not: the same
/// points, intensities and labels either way, and the same refusals.
#[test]
fn kitti_records_in_place_or_decoded_agree() {
    let cloud = synthetic(4, 10, 1);
    let (bin, label, n) = kitti::encode(&cloud, None).unwrap();
    let (bp, lp) = (Path::new("x.bin"), Path::new("x.label"));
    let want = kitti::points_from_bytes(bp, &bin, Some((lp, &label))).unwrap();
    // Aligned (a `Vec<u32>`'s bytes) and one byte off.
    let words: Vec<u32> = bin.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect();
    let aligned: &[u8] = bytemuck::cast_slice(&words);
    // The same bytes starting one byte past a 4-byte boundary.
    let mut shifted = vec![0u8; bin.len() + 4];
    let start = (4 - shifted.as_ptr() as usize % 4) % 4 + 1;
    shifted[start..start + bin.len()].copy_from_slice(&bin);
    let misaligned = &shifted[start..start + bin.len()];
    let mut out = kitti::KittiPoints::default();
    let records = kitti::records_or_points_into(bp, aligned, Some((lp, &label)), &mut out).unwrap().expect("in place");
    assert_eq!(records.len(), n);
    for (k, r) in records.iter().enumerate() {
        assert_eq!((Vec3::new(r[0], r[1], r[2]), r[3]), (want.points[k], want.intensity[k]), "record {k}");
    }
    assert!(out.points.is_empty() && out.labels == want.labels);
    assert_eq!(misaligned.as_ptr() as usize % 4, 1);
    let got = kitti::records_or_points_into(bp, misaligned, Some((lp, &label)), &mut out).unwrap();
    assert!(got.is_none());
    assert_eq!(out, want);
    let m = bad_file_message(kitti::records_or_points_into(bp, &aligned[..70], None, &mut out).unwrap_err(), bp);
    assert!(m.contains("not a multiple of 16"), "{m}");
    let m = bad_file_message(
        kitti::records_or_points_into(bp, aligned, Some((lp, &label[4..])), &mut out).unwrap_err(),
        lp,
    );
    assert!(m.contains("labels"), "{m}");
}

#[test]
fn ply_truncated_is_refused() {
    let cloud = synthetic(4, 10, 1);
    let (bytes, _) = ply::encode(&cloud).unwrap();
    let path = Path::new("t.ply");
    let m = bad_file_message(ply::read_bytes(path, &bytes[..bytes.len() - 1]).unwrap_err(), path);
    assert!(m.contains("data"), "{m}");
}

#[test]
fn scene_mesh_round_trip_and_foreign_ascii_quads() {
    let dir = tempfile::tempdir().unwrap();
    let mut mesh = SceneMesh::new();
    mesh.push_heightfield(
        (0.0, 0.0),
        1.0,
        (3, 2),
        |x, y| 0.1 * x - 0.2 * y,
        |_, _| Surface::stuff(SemanticClass::ROAD),
    );
    mesh.push_box(Vec3::new(5.0, 0.0, 0.0), Vec3::new(6.0, 1.0, 1.5), Surface::object(SemanticClass::CAR, 3));
    let path = dir.path().join("m.ply");
    write_mesh(&path, &mesh).unwrap();
    assert_eq!(read_mesh(&path).unwrap(), mesh);

    let ascii = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
                 element face 2\nproperty list uchar int vertex_indices\nend_header\n\
                 0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 1 2 3\n3 0 1 4\n";
    let m = sim::scene::ply::read_mesh_bytes(Path::new("q.ply"), ascii.as_bytes()).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]], "the quad is fan-triangulated");
    assert!(m.surfaces.iter().all(|s| s.class.0 == 0 && s.instance == 0 && s.reflectivity == 0.3));
    let bad = ascii.replace("3 0 1 4", "3 0 1 9");
    let p = Path::new("q.ply");
    let msg = bad_file_message(sim::scene::ply::read_mesh_bytes(p, bad.as_bytes()).unwrap_err(), p);
    assert!(msg.contains("vertex 9"), "{msg}");
}

/// LAZ holds the same points as LAS (only with `--features laz`).
#[cfg(feature = "laz")]
#[test]
fn laz_reads_back_with_the_same_points() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = synthetic(8, 30, 1);
    let path = dir.path().join("a.laz");
    let n = las_io::write_with(&path, &cloud, true).unwrap();
    let mut reader = las::Reader::from_path(&path).unwrap();
    let points: Vec<las::Point> = reader.read_all().unwrap().points().map(|p| p.unwrap()).collect();
    assert_eq!(points.len(), n);
    let class2 = points.iter().filter(|p| p.classification == las::point::Classification::Ground).count();
    assert_eq!(class2, cloud.ground_returns());
    let plain = las_io::encode(&path, &cloud).unwrap().0;
    assert!(std::fs::metadata(&path).unwrap().len() < plain.len() as u64, "compressed is smaller");
}
