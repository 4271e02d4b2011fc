//! The ROS 2 bag reader (MCAP container, CDR messages, PointCloud2 to PCD) given a valid bag that
//! was truncated or had bytes corrupted, or arbitrary CDR bytes, returns a value or an error and
//! never panics; a truncated bag is always refused.

use std::collections::BTreeMap;
use std::path::Path;

use proptest::prelude::*;
use sim::io::pcd::PcdLayout;
use sim::io::ros2::messages::{Header, from_cdr};
use sim::io::ros2::pointcloud2::{from_pcd, to_pcd};
use sim::io::ros2::{Bag, BagWriter, PointCloud2};
use sim::{OrderedCloud, SemanticClass};

/// A bag of two small clouds on `/points`, as bytes of its one MCAP file.
fn valid_bag() -> Vec<u8> {
    let mut c = OrderedCloud::empty(3, 5, 1);
    for i in 0..c.len() {
        if i % 4 != 0 {
            c.point_in_vehicle[i] = glam::Vec3::new(i as f32, 1.0, -0.5);
            c.range_m[i] = c.point_in_vehicle[i].length();
            c.label[i] = SemanticClass::ROAD;
        }
    }
    let pcd = sim::io::pcd::encode_layout(&c, PcdLayout::Velodyne, false, None).unwrap();
    let msg = from_pcd(&pcd, Header::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut w = BagWriter::create(&dir.path().join("b")).unwrap();
    for k in 0..2 {
        w.write_pointcloud("/points", &msg, k * 100, &BTreeMap::new()).unwrap();
    }
    let bag = w.finish().unwrap();
    std::fs::read(bag.join("b_0.mcap")).unwrap()
}

/// Reads every cloud of `/points` in `bytes` through to PCD and its reader: `Ok` when all went
/// through, `Err` on any refusal; only a panic fails the test.
fn read_bag(bytes: &[u8]) -> bool {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fuzz.mcap");
    std::fs::write(&path, bytes).unwrap();
    let Ok(bag) = Bag::open(&path) else { return false };
    let mut all = true;
    let read = bag.for_each_cloud("/points", |m| {
        let ok = m
            .decode()
            .and_then(|pc| to_pcd(&pc, None))
            .is_ok_and(|pcd| sim::io::pcd::read_bytes(Path::new("m.pcd"), &pcd).is_ok());
        all &= ok;
        Ok(())
    });
    read.is_ok() && all
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn truncated_bags_are_refused(cut in 1usize..4000) {
        let bytes = valid_bag();
        prop_assert!(read_bag(&bytes), "the untouched bag reads");
        let cut = cut.min(bytes.len());
        prop_assert!(!read_bag(&bytes[..bytes.len() - cut]), "a bag cut by {cut} bytes must be refused");
    }

    #[test]
    fn corrupted_bags_never_panic(edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)) {
        let mut b = valid_bag();
        for (at, v) in edits {
            let k = at.index(b.len());
            b[k] = v;
        }
        read_bag(&b);
    }

    #[test]
    fn arbitrary_cdr_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        if let Ok(pc) = from_cdr::<PointCloud2<'_>>(&bytes) {
            let _ = to_pcd(&pc, None);
        }
    }
}
