//! Every reader (PCD, PLY cloud, PLY mesh, KITTI `.bin` + `.label`, LAS) given arbitrary bytes, a
//! truncated valid file or a valid file with corrupted bytes returns a value or an error, never
//! panics; and a truncated binary file is always refused.

use std::path::Path;

use glam::Vec3;
use proptest::prelude::*;
use sim::io::{kitti, las, pcd, ply};
use sim::scene::ply::{read_mesh_bytes, write_mesh};
use sim::{OrderedCloud, SceneMesh, SemanticClass, Surface};

fn small_cloud() -> OrderedCloud {
    let mut c = OrderedCloud::empty(3, 5, 1);
    for i in 0..c.len() {
        if i % 4 != 0 {
            c.point_in_vehicle[i] = Vec3::new(i as f32, 1.0, -0.5);
            c.range_m[i] = c.point_in_vehicle[i].length();
            c.label[i] = SemanticClass::ROAD;
            c.ground[i] = true;
        }
    }
    c
}

fn valid_files() -> Vec<(&'static str, Vec<u8>)> {
    let c = small_cloud();
    let mut mesh = SceneMesh::new();
    mesh.push_box(Vec3::ZERO, Vec3::ONE, Surface::object(SemanticClass::CAR, 2));
    let dir = tempfile::tempdir().unwrap();
    let mesh_path = dir.path().join("m.ply");
    write_mesh(&mesh_path, &mesh).unwrap();
    let (bin, label, _) = kitti::encode(&c, None).unwrap();
    let mut kitti_both = bin.clone();
    kitti_both.extend_from_slice(&label);
    vec![
        ("pcd", pcd::encode(&c, false).unwrap()),
        ("pcd", pcd::encode(&c, true).unwrap()),
        ("ply", ply::encode(&c).unwrap().0),
        ("mesh", std::fs::read(&mesh_path).unwrap()),
        ("kitti", kitti_both),
        ("las", las::encode(Path::new("x.las"), &c).unwrap().0),
    ]
}

/// Runs the reader named `kind` on `bytes`; `Ok` or `Err` are both fine, only a panic fails.
fn read_any(kind: &str, bytes: &[u8]) -> bool {
    let p = Path::new("fuzz.bin");
    match kind {
        "pcd" => pcd::read_bytes(p, bytes).is_ok(),
        "ply" => ply::read_bytes(p, bytes).is_ok(),
        "mesh" => read_mesh_bytes(p, bytes).is_ok(),
        "las" => las::read_bytes(p, bytes).is_ok(),
        _ => {
            // Split the bytes into a .bin part (multiple of 16 when possible) and a .label part.
            let split = bytes.len() * 4 / 5 / 16 * 16;
            let (bin, label) = (&bytes[..split], Some((Path::new("fuzz.label"), &bytes[split..])));
            let mut out = kitti::KittiPoints::default();
            let in_place = kitti::records_or_points_into(p, bin, label, &mut out).is_ok();
            let read = kitti::read_bytes(p, bin, label).is_ok();
            assert_eq!(in_place, read, "the two readers refuse the same files");
            read
        }
    }
}

const KINDS: [&str; 5] = ["pcd", "ply", "mesh", "kitti", "las"];

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(kind in 0usize..5, bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        read_any(KINDS[kind], &bytes);
    }

    #[test]
    fn header_prefixed_garbage_never_panics(which in 0usize..6, keep in 0usize..400, tail in proptest::collection::vec(any::<u8>(), 0..300)) {
        let files = valid_files();
        let (kind, bytes) = &files[which];
        let mut b = bytes[..keep.min(bytes.len())].to_vec();
        b.extend_from_slice(&tail);
        read_any(kind, &b);
    }

    #[test]
    fn truncations_are_refused(which in 0usize..6, cut in 1usize..2000) {
        let files = valid_files();
        let (kind, bytes) = &files[which];
        prop_assert!(read_any(kind, bytes), "the untouched file reads");
        let cut = cut.min(bytes.len());
        let truncated = &bytes[..bytes.len() - cut];
        let ok = read_any(kind, truncated);
        // A cut ASCII file may still parse (`0.25` cut to `0.2`); KITTI has no header to disagree with.
        if *kind != "kitti" && which != 1 {
            prop_assert!(!ok, "{kind} cut by {cut} bytes must be refused");
        }
    }

    #[test]
    fn corrupted_bytes_never_panic(which in 0usize..6, edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)) {
        let files = valid_files();
        let (kind, bytes) = &files[which];
        let mut b = bytes.clone();
        for (at, v) in edits {
            let k = at.index(b.len());
            b[k] = v;
        }
        read_any(kind, &b);
    }
}

/// The `mcap_bag` fuzz target's crash of 2026-11-28 (98 bytes): an Attachment record shorter than
/// its header, which the footer's summary start points at; mcap 0.26's `parse_record` sliced past
/// its end (a panic). Now the summary is passed over and the read-through refuses the record.
#[test]
fn bag_with_a_short_attachment_is_refused() {
    let bytes: [u8; 110] = [
        137, 77, 67, 65, 80, 48, 13, 10, 9, 33, 0, 0, 0, 0, 0, 0, 0, 36, 4, 0, 163, 0, 0, 0, 65, 80, 48, 13, 0, 0, 43,
        3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 115, 137, 80, 10, 1, 23, 0, 137, 77, 67, 0, 0, 5, 0, 0, 0, 0, 0, 0,
        232, 218, 153, 143, 97, 98, 105, 0, 0, 2, 20, 0, 0, 0, 0, 0, 0, 0, 8, 0, 0, 0, 0, 0, 0, 0, 41, 243, 255, 13, 0,
        0, 0, 0, 184, 1, 118, 219, 137, 77, 67, 65, 80, 48, 13, 10,
    ];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("short_attachment.mcap");
    std::fs::write(&path, bytes).unwrap();
    let bag = sim::io::ros2::Bag::open(&path).unwrap();
    let e = bag.topics().unwrap_err().to_string();
    assert!(e.contains("attachment record shorter") && e.contains("short_attachment.mcap"), "{e}");
}
