//! The reader of recordings on every input kind, written by the simulator's writers in a temporary
//! directory: PCD (ours and a driver's), PLY, LAS, KITTI `.bin` with its `.label`, a directory of
//! them, a ROS 2 bag (with and without a topic, one topic or two), a SemanticKITTI-layout dataset
//! (frames with their labels and sequences); a bag cut short at several byte offsets reads as the
//! first messages of the whole bag, with a warning naming the last one.

use std::collections::BTreeMap;
use std::path::Path;

use classifier::ordering::SensorSetup;
use classifier::recording::{InputLayout, Ordering, Recording, RecordingError};
use classifier::synthetic::{SyntheticSensor, car, flat_ground};
use sim::OrderedCloud;
use sim::io::pcd::{PcdLayout, encode_layout};
use sim::io::ros2::BagWriter;
use sim::io::ros2::messages::Header;
use sim::io::ros2::pointcloud2::from_pcd;

/// A VLP-16-like frame (16 rings from -15 to 15 deg, 900 columns) 1.8 m over a floor, a car ahead;
/// `k` moves the car.
fn frame(k: usize) -> OrderedCloud {
    let sensor = SyntheticSensor::spinning(16, 900, -15.0, 15.0, 1.8);
    let mut cloud = sensor.scan(&[flat_ground(), car(8.0 + k as f32, 2.0, 0.0)]);
    // The synthetic scan's ranges as the writers expect them (from the sensor).
    for i in 0..cloud.len() {
        if cloud.point_in_vehicle[i].is_finite() {
            cloud.range_m[i] = (cloud.point_in_vehicle[i] - sensor.origin).length();
        }
    }
    cloud
}

/// Every frame of `path` (and `topic`), ordered with `setup`: (index, layout, returns, ground
/// decisions of `nitsch` per input point).
/// The VLP-16's beam table, no mount (the frames are written where the sensor is).
fn vlp16() -> SensorSetup {
    let rig = sim::Rig::load("vlp16-roof").unwrap();
    SensorSetup { vehicle_from_sensor: glam::Affine3A::IDENTITY, ..SensorSetup::new(Some(&rig), None).unwrap() }
}

fn read_all(path: &Path, topic: Option<&str>, setup: &SensorSetup) -> Vec<(usize, InputLayout, usize, Vec<u8>)> {
    let recording = Recording::open(path, topic).unwrap();
    let mut frames = recording.frames(Ordering::Ordered(setup)).unwrap();
    let mut method = classifier::method("nitsch", &classifier::MethodOptions::default()).unwrap();
    let mut out = Vec::new();
    while let Some(f) = frames.next_frame() {
        let f = f.unwrap();
        let ground =
            method.classify(&classifier::FrameInput { index: f.index, cloud: f.cloud, world_from_vehicle: None });
        let decisions = f.decisions_per_point(&ground.unwrap());
        out.push((f.index, f.provenance.layout, f.cloud.returns(), decisions));
    }
    assert!(frames.warnings().is_empty(), "{:?}", frames.warnings());
    out
}

/// A bag of `n` frames on `/points` (the velodyne driver's layout), plus `/tf`.
fn write_bag(dir: &Path, n: usize) -> std::path::PathBuf {
    let path = dir.join("bag");
    let mut w = BagWriter::create(&path).unwrap();
    for k in 0..n {
        let pcd = encode_layout(&frame(k), PcdLayout::Velodyne, false, None).unwrap();
        let msg = from_pcd(&pcd, Header::default()).unwrap();
        w.write_pointcloud("/points", &msg, k as u64 * 100_000_000, &BTreeMap::new()).unwrap();
    }
    w.write_tf(&sim::io::ros2::messages::TfMessage { transforms: Vec::new() }, false, 0).unwrap();
    w.finish().unwrap()
}

#[test]
fn every_input_kind_reads_as_ordered_frames_with_provenance() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cloud = frame(0);
    let returns = cloud.returns();
    let files = d.join("files");
    std::fs::create_dir_all(&files).unwrap();
    sim::io::pcd::write(&files.join("frame_000000.pcd"), &cloud, false).unwrap();
    sim::io::pcd::write_layout(&files.join("frame_000001.pcd"), &cloud, PcdLayout::Velodyne, false, None).unwrap();
    sim::io::ply::write(&files.join("frame_000002.ply"), &cloud).unwrap();
    sim::io::las::write(&files.join("frame_000003.las"), &cloud).unwrap();
    let (bin, label, _) = sim::io::kitti::encode(&cloud, None).unwrap();
    std::fs::write(files.join("frame_000004.bin"), bin).unwrap();
    std::fs::write(files.join("frame_000004.label"), label).unwrap();
    std::fs::write(files.join("notes.txt"), "not a cloud").unwrap();
    let setup = vlp16();
    let frames = read_all(&files, None, &setup);
    let kinds: Vec<(usize, InputLayout)> = frames.iter().map(|f| (f.0, f.1)).collect();
    assert_eq!(
        kinds,
        [
            (0, InputLayout::Pcd),
            (1, InputLayout::Pcd),
            (2, InputLayout::Ply),
            (3, InputLayout::Las),
            (4, InputLayout::KittiBin)
        ]
    );
    for (index, layout, got, decisions) in &frames {
        // Every return is kept, with a decision per input point.
        assert_eq!(*got, returns, "{index} {layout:?}");
        assert!(decisions.len() >= returns, "{index} {layout:?}");
    }
    // Our own layout is read as written: a floor 1.8 m down is mostly ground.
    let ground = frames[0].3.iter().filter(|&&g| g == 1).count();
    assert!(ground * 10 > returns * 7, "{ground} of {returns}");
    // One file alone reads as the same frame as in the directory.
    let one = read_all(&files.join("frame_000004.bin"), None, &setup);
    assert_eq!(one, frames[4..]);
    // A bag: without --topic (its one PointCloud2 topic), the same clouds as the driver's PCD.
    let bag = write_bag(d, 2);
    let messages = read_all(&bag, None, &setup);
    assert_eq!(messages.len(), 2);
    assert_eq!((messages[0].0, messages[0].1), (0, InputLayout::PointCloud2));
    assert_eq!(messages[0].3, frames[1].3, "a message decides as the PCD of the same cloud");
    assert_eq!(read_all(&bag.join("bag_0.mcap"), Some("/points"), &setup), messages);
    // As stored: the message's own grid and the PCD reader's cloud, bit for bit.
    let recording = Recording::open(&bag, None).unwrap();
    let mut stored = recording.frames(Ordering::AsStored).unwrap();
    let f = stored.next_frame().unwrap().unwrap();
    let pcd = sim::io::pcd::read(&files.join("frame_000001.pcd")).unwrap();
    assert_eq!((f.cloud.rows, f.cloud.cols), (pcd.rows, pcd.cols));
    assert_eq!(f.provenance.to_string(), format!("{}#/points[0]", bag.display()));
    assert!(
        f.cloud.point_in_vehicle.iter().zip(&pcd.point_in_vehicle).all(|(a, b)| a == b || (a.is_nan() && b.is_nan()))
    );
    // Two PointCloud2 topics and none named: refused, both listed; a topic for a file: refused.
    let two = d.join("two");
    let mut w = BagWriter::create(&two).unwrap();
    for t in ["/a/points", "/b/points"] {
        let pcd = encode_layout(&frame(0), PcdLayout::Velodyne, false, None).unwrap();
        w.write_pointcloud(t, &from_pcd(&pcd, Header::default()).unwrap(), 0, &BTreeMap::new()).unwrap();
    }
    w.finish().unwrap();
    let e = Recording::open(&two, None).unwrap_err();
    assert!(matches!(e, RecordingError::Topic(_)), "{e}");
    assert!(e.to_string().contains("/a/points (1 messages), /b/points (1 messages)"), "{e}");
    let e = Recording::open(&files.join("frame_000000.pcd"), Some("/points")).unwrap_err();
    assert!(e.to_string().contains("--topic applies to a bag"), "{e}");
    let e = Recording::open(&d.join("missing"), None).unwrap_err();
    assert!(e.to_string().contains("neither a file nor a directory"), "{e}");
}

#[test]
fn a_semantickitti_directory_reads_as_labelled_frames_with_their_sequences() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Sequence 00 holds frames 0 and 1, sequence 01 frame 2; frame 0 also as a plain `.bin` with
    // its `.label` beside it.
    let mut written = Vec::new();
    for (seq, stem, k) in [("00", "000000", 0), ("00", "000001", 1), ("01", "000000", 2)] {
        let s = d.join("data/sequences").join(seq);
        std::fs::create_dir_all(s.join("velodyne")).unwrap();
        std::fs::create_dir_all(s.join("labels")).unwrap();
        let (bin, label, _) = sim::io::kitti::encode(&frame(k), None).unwrap();
        std::fs::write(s.join(format!("velodyne/{stem}.bin")), &bin).unwrap();
        std::fs::write(s.join(format!("labels/{stem}.label")), &label).unwrap();
        if k == 0 {
            std::fs::write(d.join("frame_000000.bin"), &bin).unwrap();
            std::fs::write(d.join("frame_000000.label"), &label).unwrap();
        }
        let classes: Vec<u16> = label.chunks_exact(4).map(|c| u16::from_le_bytes([c[0], c[1]])).collect();
        written.push((seq, stem, classes));
    }
    let setup = vlp16();
    let recording = Recording::open(&d.join("data"), None).unwrap();
    assert_eq!(recording.dataset().map(|l| l.sequences.len()), Some(2));
    let mut frames = recording.frames(Ordering::Ordered(&setup)).unwrap();
    let mut method = classifier::method("nitsch", &classifier::MethodOptions::default()).unwrap();
    let mut decisions = Vec::new();
    for (k, (seq, stem, classes)) in written.iter().enumerate() {
        let f = frames.next_frame().expect("a frame per .bin").unwrap();
        let labelled = f.labelled.expect("a labelled frame");
        // Provenance names the sequence and the `.bin`; the place in the recording and in its
        // sequence.
        assert_eq!(f.index, k);
        assert_eq!(labelled.index_in_sequence, [0, 1, 0][k]);
        assert_eq!(f.provenance.sequence.as_deref(), Some(*seq));
        assert!(f.provenance.file.ends_with(format!("sequences/{seq}/velodyne/{stem}.bin")), "{}", f.provenance);
        assert_eq!((f.provenance.layout, labelled.frame.stem.as_str()), (InputLayout::KittiBin, *stem));
        // The labels in file order, as written; carried through ordering as the cloud's labels.
        let got: Vec<u16> = labelled.points.classes.iter().map(|c| c.0).collect();
        assert_eq!(&got, classes);
        assert_eq!(labelled.points.records.len(), classes.len());
        let road = |l: &mut dyn Iterator<Item = u16>| l.filter(|&c| c == sim::SemanticClass::ROAD.0).count();
        let road_cells = road(&mut f.cloud.label.iter().map(|c| c.0));
        assert!(road_cells > 1000, "{road_cells}");
        assert_eq!(road_cells, road(&mut classes.iter().copied()));
        let ground =
            method.classify(&classifier::FrameInput { index: f.index, cloud: f.cloud, world_from_vehicle: None });
        decisions.push(f.decisions_per_point(&ground.unwrap()));
    }
    assert!(frames.next_frame().is_none());
    // A frame decides as the same `.bin` and `.label` read as a plain file.
    let plain = read_all(&d.join("frame_000000.bin"), None, &setup);
    assert_eq!(plain[0].3, decisions[0]);
    // One sequence's folder alone; as stored: `1 x N` in file order with the labels.
    let one = Recording::open(&d.join("data/sequences/01"), None).unwrap();
    let mut stored = one.frames(Ordering::AsStored).unwrap();
    let f = stored.next_frame().unwrap().unwrap();
    assert_eq!((f.cloud.rows, f.cloud.cols), (1, written[2].2.len()));
    assert!(f.cloud.label.iter().map(|c| c.0).eq(written[2].2.iter().copied()));
    assert_eq!(f.provenance.sequence.as_deref(), Some("01"));
    // A `.bin` without its `.label`: refused, naming it; a topic for a dataset: refused.
    std::fs::remove_file(d.join("data/sequences/01/labels/000000.label")).unwrap();
    let e = Recording::open(&d.join("data"), None).unwrap_err();
    assert!(matches!(e, RecordingError::Dataset(_)) && e.to_string().contains("000000.label"), "{e}");
    let e = Recording::open(&d.join("data"), Some("/points")).unwrap_err();
    assert!(e.to_string().contains("--topic applies to a bag"), "{e}");
    // A nuScenes-lidarseg folder: its sweep as nuScenes records, its class as SemanticKITTI's (24
    // driveable surface -> 40 road); KITTI records for it are refused.
    let mini = d.join("mini");
    std::fs::create_dir_all(mini.join("lidar")).unwrap();
    std::fs::create_dir_all(mini.join("lidarseg")).unwrap();
    std::fs::write(mini.join("lidar/tok.pcd.bin"), sim::io::nuscenes::encode(&[[5.0, 1.0, -1.8, 0.3, 2.0]])).unwrap();
    std::fs::write(mini.join("lidarseg/tok_lidarseg.bin"), [24u8]).unwrap();
    let recording = Recording::open(&mini, None).unwrap();
    let mut frames = recording.frames(Ordering::AsStored).unwrap();
    let f = frames.next_frame().unwrap().unwrap();
    assert_eq!((f.provenance.layout, f.provenance.sequence.as_deref()), (InputLayout::NuscenesBin, Some("mini")));
    assert_eq!((f.cloud.label[0], f.cloud.ring[0]), (sim::SemanticClass::ROAD, 2));
    let e = Recording::open(&mini, None).unwrap().with_layout(Some(classifier::recording::LayoutChoice::Kitti));
    let e = e.unwrap_err().to_string();
    assert!(e.contains("--layout kitti") && e.contains("nuScenes"), "{e}");
}

#[test]
fn a_bag_cut_short_reads_as_the_first_messages_of_the_whole_bag() {
    let dir = tempfile::tempdir().unwrap();
    let bag = write_bag(dir.path(), 8);
    let whole = bag.join("bag_0.mcap");
    let bytes = std::fs::read(&whole).unwrap();
    let setup = vlp16();
    let all = read_all(&bag, None, &setup);
    assert_eq!(all.len(), 8);
    let cut = dir.path().join("cut.mcap");
    let mut seen = std::collections::BTreeSet::new();
    for at in [bytes.len() - 30, bytes.len() * 9 / 10, bytes.len() * 2 / 3, bytes.len() / 2, bytes.len() / 4, 100] {
        std::fs::write(&cut, &bytes[..at]).unwrap();
        let recording = Recording::open(&cut, Some("/points")).unwrap();
        let mut frames = recording.frames(Ordering::Ordered(&setup)).unwrap();
        let mut method = classifier::method("nitsch", &classifier::MethodOptions::default()).unwrap();
        let mut got = Vec::new();
        let mut error = None;
        while let Some(f) = frames.next_frame() {
            match f {
                Ok(f) => {
                    let ground = method.classify(&classifier::FrameInput {
                        index: f.index,
                        cloud: f.cloud,
                        world_from_vehicle: None,
                    });
                    got.push((
                        f.index,
                        f.provenance.layout,
                        f.cloud.returns(),
                        f.decisions_per_point(&ground.unwrap()),
                    ));
                }
                Err(e) => error = Some(e.to_string()),
            }
        }
        let k = got.len();
        assert_eq!(got, all[..k], "cut at {at}: the first {k} messages");
        match k {
            0 => {
                let e = error.unwrap_or_default();
                assert!(e.contains("cut.mcap") && e.contains("cut short"), "cut at {at}: {e}");
            }
            _ => {
                assert!(error.is_none(), "cut at {at}: {error:?}");
                let w = frames.warnings().join("\n");
                assert!(w.contains("cut.mcap") && w.contains(&format!("message {}", k - 1)), "cut at {at}: {w}");
            }
        }
        seen.insert(k);
    }
    // The cuts fall before the first message, inside the bag and after the last message.
    assert!(seen.contains(&0) && seen.contains(&8) && seen.iter().any(|&k| k > 0 && k < 8), "{seen:?}");
}
