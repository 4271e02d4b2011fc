//! The ROS 2 bag reader (MCAP container, CDR messages, PointCloud2 decoded by the PCD reader) given
//! a valid bag that was truncated or had bytes corrupted, or arbitrary CDR bytes, returns a value or
//! an error and never panics; a truncated bag is read up to its last whole message and the cut
//! reported.

use std::collections::BTreeMap;
use std::path::Path;

use proptest::prelude::*;
use sim::io::pcd::PcdLayout;
use sim::io::ros2::messages::{Header, from_cdr};
use sim::io::ros2::pointcloud2::{frame, from_pcd};
use sim::io::ros2::{Bag, BagCompression, BagWriter, PointCloud2};
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
    // zstd chunks where this build writes them (the default), else uncompressed ones.
    let compression = if cfg!(feature = "bag-compression") { BagCompression::Zstd } else { BagCompression::None };
    let mut w = BagWriter::create_with(&dir.path().join("b"), compression).unwrap();
    for k in 0..2 {
        w.write_pointcloud("/points", &msg, k * 100, &BTreeMap::new()).unwrap();
    }
    let bag = w.finish().unwrap();
    std::fs::read(bag.join("b_0.mcap")).unwrap()
}

/// What reading every cloud of `/points` in `bytes` through the PCD reader's decoder gave: the
/// clouds read whole (`None` on any refusal) and whether the file was reported cut short; only a
/// panic fails the test.
fn read_bag(bytes: &[u8]) -> (Option<usize>, bool) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fuzz.mcap");
    std::fs::write(&path, bytes).unwrap();
    let Ok(bag) = Bag::open(&path) else { return (None, false) };
    let Ok(mut clouds) = bag.clouds("/points") else { return (None, false) };
    let mut read = Some(0);
    for m in clouds.by_ref() {
        let name = Path::new("m");
        let ok = m.is_ok_and(|m| {
            m.decode().is_ok_and(|pc| {
                frame(name, &pc, None)
                    .is_ok_and(|f| f.read_into(&mut OrderedCloud::default(), None, Default::default()).is_ok())
            })
        });
        read = read.filter(|_| ok).map(|n| n + 1);
    }
    (read, !clouds.truncations().is_empty())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn truncated_bags_are_read_up_to_the_cut(cut in 1usize..4000) {
        let bytes = valid_bag();
        prop_assert_eq!(read_bag(&bytes), (Some(2), false), "the untouched bag reads");
        let cut = cut.min(bytes.len());
        let (read, truncated) = read_bag(&bytes[..bytes.len() - cut]);
        prop_assert!(truncated || read.is_none(), "a bag cut by {} bytes is reported cut (or refused)", cut);
        prop_assert!(read.is_none_or(|n| n <= 2), "{:?}", read);
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
            let _ = frame(Path::new("m"), &pc, None).map(|f| f.len());
        }
    }
}
