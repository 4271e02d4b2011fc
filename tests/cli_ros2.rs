//! ROS 2 bags through the binary:
//! - `scan --format mcap` writes a rosbag2 directory whose messages hold the manifest's point
//!   counts, the same bytes at 1 and 2 threads; `dataset` writes one per sequence;
//! - `classify`, `eval --dataset` and `bench classify` read a bag (ours, or one our writer makes of
//!   hand-built clouds) and decide as they do on the same clouds as PCD files;
//! - a bag with one PointCloud2 topic is read without `--topic`; a file cut short is read up to its
//!   last whole message with a warning naming it;
//! - bad input: a missing topic among several, an unknown topic (the topics listed), a topic of
//!   another type, a JSON or ROS 1 channel, a file cut before its first message, and bad messages
//!   among good ones (classified, the bad ones counted and named by file, topic and index), with
//!   nothing half-written.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use sim::io::ros2::messages::{Header, PointCloud2, PointField, datatype};
use sim::io::ros2::{Bag, BagWriter};

const BIN: &str = env!("CARGO_BIN_EXE_groundtruth");

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run groundtruth")
}

fn ok(args: &[&str]) -> String {
    let out = run(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn fails(args: &[&str]) -> String {
    let out = run(args);
    assert!(!out.status.success(), "{args:?} should fail");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn scan(out: &Path, rig: &str, layout: &str, extra: &[&str]) -> serde_json::Value {
    let o = out.to_str().unwrap();
    let mut args = vec!["scan", "--scene", "ramp-down", "--rig", rig, "--seed", "3", "--frames", "3", "--speed", "6"];
    args.extend(["--format", "mcap,pcd", "--pcd-layout", layout, "--out", o]);
    args.extend(extra);
    ok(&args);
    serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap()
}

/// Every message of `topic` in the bag at `path` as (index, CDR bytes), read by the library's
/// reader of recordings (as stored).
fn messages(path: &Path, topic: &str) -> Vec<(usize, Vec<u8>)> {
    let recording = classifier::recording::Recording::open(path, Some(topic)).unwrap();
    let mut frames = recording.frames(classifier::recording::Ordering::AsStored).unwrap();
    let mut out = Vec::new();
    while let Some(frame) = frames.next_frame() {
        let frame = frame.unwrap();
        let m = frame.message.unwrap();
        out.push((m.index, m.cdr.clone()));
    }
    out
}

fn files_in(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|e| e == ext)).collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn a_scan_bag_holds_the_manifest_counts_and_classifies_as_its_pcd_files() {
    let tmp = tempfile::tempdir().unwrap();
    for (rig, layout) in [("vlp16-roof", "velodyne"), ("os1-64-roof", "ouster"), ("hdl64e-roof", "groundtruth")] {
        let dir = tmp.path().join(layout);
        let manifest = scan(&dir, rig, layout, &[]);
        let bag = Bag::open(&dir.join("bag")).unwrap();
        let topics = bag.topics().unwrap();
        let names: Vec<&str> = topics.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["/roof/points", "/tf", "/tf_static"], "{layout}");
        assert_eq!(topics.iter().map(|t| t.count).collect::<Vec<_>>(), [3, 3, 1]);
        // Every message's width x height is the manifest's count for it.
        let counts: Vec<u64> = messages(&dir.join("bag"), "/roof/points")
            .iter()
            .map(|(_, cdr)| {
                let pc = sim::io::ros2::messages::from_cdr::<PointCloud2<'_>>(cdr).unwrap();
                (pc.width * pc.height) as u64
            })
            .collect();
        let listed: Vec<u64> = manifest["frames"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| {
                f["files"].as_array().unwrap().iter().find(|e| e["format"] == "mcap:/roof/points").unwrap()["points"]
                    .as_u64()
                    .unwrap()
            })
            .collect();
        assert_eq!(counts, listed, "{layout}");
        // The bag's clouds decide as the PCD files do, message by message.
        for method in ["nitsch", "learned"] {
            let (a, b) = (dir.join(format!("bag-{method}")), dir.join(format!("pcd-{method}")));
            let s = dir.to_str().unwrap();
            ok(&[
                "classify",
                "--method",
                method,
                "--input",
                &format!("{s}/bag"),
                "--topic",
                "/roof/points",
                "--out",
                a.to_str().unwrap(),
            ]);
            ok(&["classify", "--method", method, "--input", s, "--out", b.to_str().unwrap()]);
            let (ga, gb) = (files_in(&a, "ground"), files_in(&b, "ground"));
            assert_eq!(ga.len(), 3);
            for (x, y) in ga.iter().zip(&gb) {
                let (x, y) = (std::fs::read(x).unwrap(), std::fs::read(y).unwrap());
                assert_eq!(x, y, "{layout} {method}");
                assert!(
                    x.iter().filter(|&&g| g == 1).count() * 2 > x.len() / 2,
                    "{layout}: a ramp scene is mostly ground"
                );
            }
            // The result bag: the same messages, each with a `ground` field holding the decisions
            // (our layout's own `ground`, the truth, renamed `ground_truth`).
            for (index, cdr) in messages(&a.join("ground_bag"), "/roof/points") {
                let pc = sim::io::ros2::messages::from_cdr::<PointCloud2<'_>>(&cdr).unwrap();
                let f = pc.fields.iter().find(|f| f.name == "ground").unwrap();
                let decisions: Vec<u8> =
                    pc.data.chunks_exact(pc.point_step as usize).map(|p| p[f.offset as usize]).collect();
                assert_eq!(decisions, std::fs::read(a.join(format!("frame_{index:06}.ground"))).unwrap());
                assert_eq!(pc.fields.iter().any(|f| f.name == "ground_truth"), layout == "groundtruth");
            }
        }
    }
}

#[test]
fn scan_bags_are_the_same_bytes_at_any_thread_count_and_list_every_sensor() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    scan(&a, "lux-roof-4", "groundtruth", &["--threads", "1"]);
    scan(&b, "lux-roof-4", "groundtruth", &["--threads", "2"]);
    let (x, y) = (std::fs::read(a.join("bag/bag_0.mcap")).unwrap(), std::fs::read(b.join("bag/bag_0.mcap")).unwrap());
    assert!(x == y, "the bag differs between 1 and 2 threads");
    let meta = std::fs::read_to_string(a.join("bag/metadata.yaml")).unwrap();
    assert!(meta.contains("storage_identifier: mcap") && meta.contains("message_count: 16"), "{meta}");
    let topics = Bag::open(&a.join("bag")).unwrap().pointcloud_topics().unwrap();
    assert_eq!(topics.len(), 4, "one topic per sensor: {topics:?}");
    // Uncompressed chunks: larger, the same messages.
    let c = tmp.path().join("c");
    scan(&c, "lux-roof-4", "groundtruth", &["--bag-compression", "none"]);
    let z = std::fs::read(c.join("bag/bag_0.mcap")).unwrap();
    assert!(z.len() > x.len(), "uncompressed {} vs zstd {}", z.len(), x.len());
    let err = fails(&[
        "scan",
        "--format",
        "mcap",
        "--bag-compression",
        "lz5",
        "--out",
        tmp.path().join("d").to_str().unwrap(),
    ]);
    assert!(err.contains("bag compression") && err.contains("zstd or none"), "{err}");
    assert!(!tmp.path().join("d/bag").exists());
}

/// A cloud of `n` points on the ground plane ahead of the sensor, `x y z intensity ring label`
/// at offsets 0 4 8 16 20 24 (padding at 12 and 22) in a 32-byte point, organized `rows x cols`.
fn cloud(rows: u32, cols: u32) -> PointCloud2<'static> {
    let f = |name: &str, offset: u32, dt: u8| PointField { name: name.into(), offset, datatype: dt, count: 1 };
    let mut data = Vec::new();
    for r in 0..rows {
        for c in 0..cols {
            let az = c as f32 / cols as f32 * std::f32::consts::TAU;
            let range = 4.0 + 2.0 * r as f32;
            let mut p = [0u8; 32];
            p[0..4].copy_from_slice(&(range * az.cos()).to_le_bytes());
            p[4..8].copy_from_slice(&(range * az.sin()).to_le_bytes());
            p[8..12].copy_from_slice(&(-1.8f32).to_le_bytes());
            p[16..20].copy_from_slice(&50f32.to_le_bytes());
            p[20..22].copy_from_slice(&(r as u16).to_le_bytes());
            p[24..28].copy_from_slice(&40u32.to_le_bytes()); // SemanticKITTI road
            data.extend_from_slice(&p);
        }
    }
    PointCloud2 {
        header: Header { frame_id: "lidar".into(), ..Header::default() },
        height: rows,
        width: cols,
        fields: vec![
            f("x", 0, datatype::FLOAT32),
            f("y", 4, datatype::FLOAT32),
            f("z", 8, datatype::FLOAT32),
            f("intensity", 16, datatype::FLOAT32),
            f("ring", 20, datatype::UINT16),
            f("label", 24, datatype::UINT32),
        ],
        is_bigendian: false,
        point_step: 32,
        row_step: 32 * cols,
        data: std::borrow::Cow::Owned(data),
        is_dense: true,
    }
}

/// A bag of five clouds on `/points`, of which messages 1 and 3 are broken (`row_step` that
/// disagrees with the data; no `z`), and a `/tf` topic of another type.
fn mixed_bag(dir: &Path) -> PathBuf {
    let path = dir.join("mixed");
    let mut w = BagWriter::create(&path).unwrap();
    let none = BTreeMap::new();
    for k in 0..5u64 {
        let mut c = cloud(8, 360);
        if k == 1 {
            c.row_step += 4;
        }
        if k == 3 {
            c.fields.retain(|f| f.name != "z");
        }
        w.write_pointcloud("/points", &c, k * 100_000_000, &none).unwrap();
    }
    w.write_tf(&sim::io::ros2::messages::TfMessage { transforms: Vec::new() }, false, 0).unwrap();
    w.finish().unwrap()
}

#[test]
fn bad_messages_are_skipped_and_named_and_bad_bags_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let bag = mixed_bag(tmp.path());
    let b = bag.to_str().unwrap();
    let out = tmp.path().join("out");
    let o = out.to_str().unwrap();
    // Good messages classified; the bad ones named with file, topic and index, and counted.
    let cmd = run(&[
        "classify",
        "--method",
        "learned",
        "--rig",
        "vlp16-roof",
        "--input",
        b,
        "--topic",
        "/points",
        "--out",
        o,
    ]);
    let (stdout, stderr) = (String::from_utf8_lossy(&cmd.stdout), String::from_utf8_lossy(&cmd.stderr));
    assert!(cmd.status.success(), "{stderr}");
    assert!(stdout.contains("3 messages of /points classified, 2 skipped"), "{stdout}");
    for (k, why) in [(1, "data bytes"), (3, "no float field `z`")] {
        let line =
            stderr.lines().find(|l| l.contains(&format!("/points message {k}:"))).unwrap_or_else(|| panic!("{stderr}"));
        assert!(line.contains(b) && line.contains(why), "{line}");
    }
    let names: Vec<String> =
        files_in(&out, "ground").iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(names, ["frame_000000.ground", "frame_000002.ground", "frame_000004.ground"]);
    let g = std::fs::read(out.join("frame_000000.ground")).unwrap();
    assert_eq!(g.len(), 8 * 360);
    let share = g.iter().filter(|&&x| x == 1).count() as f64 / g.len() as f64;
    assert!(share > 0.85, "a flat plane 1.8 m below the sensor is ground: {share}");
    // eval --dataset on the same bag: the labelled good messages scored, the bad ones skipped.
    let stdout = ok(&["eval", "--dataset", b, "--topic", "/points", "--rig", "vlp16-roof", "--methods", "nitsch"]);
    assert!(stdout.contains("3 message(s) scored, 2 skipped"), "{stdout}");
    // bench classify refuses the broken message, naming it.
    let err = fails(&["bench", "classify", "--method", "nitsch", "--input", b, "--topic", "/points", "--repeats", "1"]);
    assert!(err.contains("/points message 1"), "{err}");

    // Without --topic, the bag's one PointCloud2 topic is read.
    let o1 = tmp.path().join("no-topic");
    let stdout =
        ok(&["classify", "--method", "nitsch", "--rig", "vlp16-roof", "--input", b, "--out", o1.to_str().unwrap()]);
    assert!(stdout.contains("3 messages of /points classified, 2 skipped"), "{stdout}");
    assert_eq!(files_in(&o1, "ground").len(), 3);
    // With two PointCloud2 topics, --topic is needed: refused, the topics listed.
    let two = tmp.path().join("two");
    let mut w = BagWriter::create(&two).unwrap();
    for t in ["/front/points", "/rear/points"] {
        w.write_pointcloud(t, &cloud(8, 360), 0, &BTreeMap::new()).unwrap();
    }
    w.finish().unwrap();
    let o4 = tmp.path().join("two-out");
    let err =
        fails(&["classify", "--method", "nitsch", "--input", two.to_str().unwrap(), "--out", o4.to_str().unwrap()]);
    assert!(
        err.contains("give --topic") && err.contains("/front/points (1 messages), /rear/points (1 messages)"),
        "{err}"
    );
    // An unknown topic, one of another type: refused, the PointCloud2 topics listed.
    for (topic, needle) in [(Some("/nope"), "no PointCloud2 topic `/nope`"), (Some("/tf"), "tf2_msgs/msg/TFMessage")] {
        let o2 = tmp.path().join("refused");
        let mut args = vec!["classify", "--method", "nitsch", "--input", b, "--out", o2.to_str().unwrap()];
        if let Some(t) = topic {
            args.extend(["--topic", t]);
        }
        let err = fails(&args);
        assert!(err.contains(needle), "{err}");
        if topic != Some("/tf") {
            assert!(err.contains("/points (5 messages)"), "{err}");
        }
        assert!(files_in(&o2, "ground").is_empty() && !o2.join("ground_bag").exists(), "nothing written: {err}");
    }
    // A file cut short (its summary and footer lost, as when a recorder is killed): read up to
    // its last whole message, with a warning naming it; exit 0.
    let mcap = bag.join("mixed_0.mcap");
    let bytes = std::fs::read(&mcap).unwrap();
    let cut = tmp.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() - 30]).unwrap();
    let o3 = tmp.path().join("cut-out");
    let out = run(&["classify", "--method", "nitsch", "--input", cut.to_str().unwrap(), "--out", o3.to_str().unwrap()]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stderr}");
    for text in [&stdout, &stderr] {
        assert!(text.contains("cut.mcap") && text.contains("cut short") && text.contains("message 4"), "{text}");
    }
    assert_eq!(files_in(&o3, "ground").len(), 3);
    // Cut before its first whole message: nothing to classify, refused naming the file.
    std::fs::write(&cut, &bytes[..60]).unwrap();
    let o5 = tmp.path().join("cut-early");
    let err = fails(&[
        "classify",
        "--method",
        "nitsch",
        "--input",
        cut.to_str().unwrap(),
        "--topic",
        "/points",
        "--out",
        o5.to_str().unwrap(),
    ]);
    assert!(err.contains("cut.mcap") && err.contains("cut short"), "{err}");
    assert!(files_in(&o5, "ground").is_empty() && !o5.join("ground_bag").exists(), "{err}");
    // Not a bag at all.
    let junk = tmp.path().join("junk.mcap");
    std::fs::write(&junk, b"not an mcap file at all").unwrap();
    let err = fails(&[
        "classify",
        "--method",
        "nitsch",
        "--input",
        junk.to_str().unwrap(),
        "--topic",
        "/points",
        "--out",
        o3.to_str().unwrap(),
    ]);
    assert!(err.contains("junk.mcap"), "{err}");
}

/// An MCAP file with a PointCloud2-named channel in another encoding (JSON; ROS 1).
fn foreign_encoding(path: &Path, schema_encoding: &str, message_encoding: &str) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::Writer::new(file).unwrap();
    let schema = w.add_schema("sensor_msgs/msg/PointCloud2", schema_encoding, b"{}").unwrap();
    let channel = w.add_channel(schema, "/points", message_encoding, &BTreeMap::new()).unwrap();
    let header = mcap::records::MessageHeader { channel_id: channel, sequence: 0, log_time: 0, publish_time: 0 };
    w.write_to_known_channel(&header, b"{\"height\": 1}").unwrap();
    w.finish().unwrap();
}

#[test]
fn json_and_ros1_channels_are_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    for (name, schema_enc, msg_enc) in [("json.mcap", "jsonschema", "json"), ("ros1.mcap", "ros1msg", "ros1")] {
        let path = tmp.path().join(name);
        foreign_encoding(&path, schema_enc, msg_enc);
        let out = tmp.path().join(format!("{name}-out"));
        let err = fails(&[
            "classify",
            "--method",
            "nitsch",
            "--input",
            path.to_str().unwrap(),
            "--topic",
            "/points",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(err.contains(name) && err.contains(&format!("in `{msg_enc}`")) && err.contains("cdr (ROS 2)"), "{err}");
        assert!(!out.join("ground_bag").exists());
    }
}

#[test]
fn dataset_writes_a_bag_per_sequence_and_eval_scores_it() {
    let tmp = tempfile::tempdir().unwrap();
    let config = tmp.path().join("d.toml");
    std::fs::write(
        &config,
        "[[sequences]]\nid = 0\nscene = \"rural\"\nseed = 7\nrig = \"vlp16-roof\"\nframes = 3\nspeed_m_per_s = 8.0\nformats = [\"mcap\"]\n\n\
         [[sequences]]\nid = 1\nscene = \"city\"\nseed = 8\nrig = \"os1-64-roof\"\nframes = 2\nspeed_m_per_s = 8.0\n",
    )
    .unwrap();
    let (c, d) = (config.to_str().unwrap(), tmp.path().join("ds"));
    ok(&["dataset", "--config", c, "--out", d.to_str().unwrap()]);
    let bag = d.join("sequences/00/bag");
    assert!(bag.join("metadata.yaml").is_file() && !d.join("sequences/01/bag").exists());
    let topics = Bag::open(&bag).unwrap().topics().unwrap();
    assert_eq!(topics.iter().find(|t| t.name == "/roof/points").unwrap().count, 3);
    let stdout = ok(&["eval", "--dataset", bag.to_str().unwrap(), "--topic", "/roof/points", "--methods", "learned"]);
    assert!(stdout.contains("3 message(s) scored, 0 skipped"), "{stdout}");
    let f1: f64 =
        stdout.lines().find(|l| l.starts_with("learned")).unwrap().split_whitespace().nth(3).unwrap().parse().unwrap();
    assert!(f1 > 0.95, "learned F1 {f1} on a rural sequence's bag");
    // A bag holds a whole sequence: a shard cannot write it, and nothing is claimed.
    let e = tmp.path().join("sharded");
    let err = fails(&["dataset", "--config", c, "--out", e.to_str().unwrap(), "--shard", "0/2"]);
    assert!(err.contains("sequence 0") && err.contains("mcap"), "{err}");
    assert!(!e.exists());
}

#[test]
fn bench_classify_times_a_bag() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    scan(&dir, "vlp16-roof", "velodyne", &[]);
    let bag = dir.join("bag");
    let stdout = ok(&[
        "bench",
        "classify",
        "--method",
        "nitsch",
        "--input",
        bag.to_str().unwrap(),
        "--topic",
        "/roof/points",
        "--repeats",
        "2",
    ]);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["messages"], 3);
    assert_eq!(v["topic"], "/roof/points");
    for k in ["read_ms", "order_ms", "classify_ms", "total_ms"] {
        assert!(v[k]["mean"].as_f64().unwrap() >= 0.0, "{k}");
    }
}
