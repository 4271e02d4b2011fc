//! Integration tests of `groundtruth dataset` through the binary: the SemanticKITTI layout read
//! back with the project's KITTI reader (frame and label counts equal a plain `scan`, poses equal
//! the analytic trajectory within 1 mm), sharded runs (2 and 3 shards, 1 and 2 threads) equal to
//! the unsharded run byte for byte, `--resume`, bad input refused before anything is written, and
//! `dataset verify`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::common;

use common::{err, files, ok, run, s};

/// A fresh scratch directory for this file's test `name`.
fn tmp(name: &str) -> PathBuf {
    common::tmp("dataset", name)
}

/// Two short sequences on the built-in flat scene: straight at 10 m/s, and an arc at 10 m/s and
/// 20 deg/s with the sensor 0.1 m higher.
const SMALL: &str = r#"
name = "test"
[[sequences]]
id = 0
scene = "flat"
seed = 4
rig = "vlp16-roof"
frames = 3
speed_m_per_s = 10.0
formats = ["ply"]

[[sequences]]
id = 7
scene = "flat"
seed = 5
rig = "vlp16-roof"
mount = { z_m = 1.95 }
frames = 4
speed_m_per_s = 10.0
yaw_rate_deg_per_s = 20.0
"#;

fn generate(config: &Path, out: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["dataset", "--config", s(config), "--out", s(out)];
    args.extend_from_slice(extra);
    serde_json::from_str(&ok(run(&args))).unwrap()
}

#[test]
fn layout_counts_and_poses() {
    let d = tmp("layout");
    let config = d.join("d.toml");
    std::fs::write(&config, SMALL).unwrap();
    let out = d.join("ds");
    let summary = generate(&config, &out, &[]);
    assert_eq!(summary["frames_written"], 7);
    let all = files(&out);
    for f in ["manifest.json", "groundtruth.yaml", "sequences/00/calib.txt", "sequences/07/times.txt"] {
        assert!(all.contains_key(f), "no {f}");
    }
    assert_eq!(all.keys().filter(|k| k.ends_with(".bin")).count(), 7);
    assert_eq!(all.keys().filter(|k| k.ends_with(".label")).count(), 7);
    assert_eq!(all.keys().filter(|k| k.starts_with("sequences/00/ply/")).count(), 3);

    // Read back with the project's reader: the same returns and labels as a plain scan.
    let scan_dir = d.join("scan");
    ok(run(&[
        "scan",
        "--scene",
        "flat",
        "--seed",
        "4",
        "--rig",
        "vlp16-roof",
        "--frames",
        "3",
        "--speed",
        "10",
        "--format",
        "kitti",
        "--out",
        s(&scan_dir),
    ]));
    for k in 0..3 {
        let seq = out.join("sequences/00");
        let ours = sim::io::kitti::read(
            &seq.join(format!("velodyne/{k:06}.bin")),
            Some(&seq.join(format!("labels/{k:06}.label"))),
        )
        .unwrap();
        let plain = sim::io::kitti::read(
            &scan_dir.join(format!("frame_{k:06}.bin")),
            Some(&scan_dir.join(format!("frame_{k:06}.label"))),
        )
        .unwrap();
        assert!(ours.returns() > 1000);
        assert_eq!(ours.returns(), plain.returns());
        let count = |c: &sim::OrderedCloud| {
            let mut m = BTreeMap::new();
            for l in &c.label {
                *m.entry(l.0).or_insert(0usize) += 1;
            }
            m
        };
        assert_eq!(count(&ours), count(&plain), "labels per class, frame {k}");
        assert_eq!(
            all[&format!("sequences/00/velodyne/{k:06}.bin")],
            std::fs::read(scan_dir.join(format!("frame_{k:06}.bin"))).unwrap()
        );
    }

    // Poses against the analytic trajectory (flat ground: no pitch or roll), within 1 mm.
    let poses = |seq: &str| -> Vec<Vec<f64>> {
        std::fs::read_to_string(out.join(seq).join("poses.txt"))
            .unwrap()
            .lines()
            .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
            .collect()
    };
    let straight = poses("sequences/00");
    assert_eq!(straight.len(), 3);
    for (k, p) in straight.iter().enumerate() {
        let x = 10.0 * 0.1 * k as f64; // 10 m/s, 10 Hz
        let expect = [1.0, 0.0, 0.0, x, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        for (a, b) in p.iter().zip(expect) {
            assert!((a - b).abs() < 1e-3, "frame {k}: {p:?}");
        }
    }
    // The arc: the sensor sits a = 1.3 m ahead of the vehicle origin (roof mount, no rotation), so
    // in the first scan's sensor frame it is at (x_k + a cos t - a, y_k + a sin t, 0), turned by t.
    let (v, w, a) = (10.0f64, 20f64.to_radians(), 1.3f64);
    for (k, p) in poses("sequences/07").iter().enumerate() {
        let t = w * 0.1 * k as f64;
        let (x, y) = (v / w * t.sin(), v / w * (1.0 - t.cos()));
        let (c, sn) = (t.cos(), t.sin());
        let expect = [c, -sn, 0.0, x + a * c - a, sn, c, 0.0, y + a * sn, 0.0, 0.0, 1.0, 0.0];
        for (got, want) in p.iter().zip(expect) {
            assert!((got - want).abs() < 1e-3, "frame {k}: {p:?} vs {expect:?}");
        }
    }
    let times = std::fs::read_to_string(out.join("sequences/07/times.txt")).unwrap();
    let times: Vec<f64> = times.lines().map(|l| l.parse().unwrap()).collect();
    assert_eq!(times.len(), 4);
    for (k, t) in times.iter().enumerate() {
        assert!((t - 0.1 * k as f64).abs() < 1e-9, "{times:?}");
    }

    // verify passes and reports the counts; a truncated .bin fails it.
    let report = ok(run(&["dataset", "verify", s(&out)]));
    assert!(report.contains("ok: 2 sequence(s), 7 frame(s)"), "{report}");
    let bin = out.join("sequences/07/velodyne/000002.bin");
    let bytes = std::fs::read(&bin).unwrap();
    std::fs::write(&bin, &bytes[..bytes.len() - 5]).unwrap();
    let e = err(run(&["dataset", "verify", s(&out)]));
    assert!(e.contains("000002") && e.contains("problem"), "{e}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn shards_resume_and_threads_give_the_same_bytes() {
    let d = tmp("shards");
    let config = d.join("d.toml");
    std::fs::write(&config, SMALL).unwrap();
    let whole = d.join("whole");
    generate(&config, &whole, &["--threads", "1"]);
    let reference = files(&whole);
    for n in [2, 3] {
        // All shards into one directory, as the Slurm array does.
        let shared = d.join(format!("shared-{n}"));
        for i in 0..n {
            let shard = format!("{i}/{n}");
            let summary = generate(&config, &shared, &["--shard", &shard, "--threads", "2"]);
            assert_eq!(summary["frames_in_shard"], (7 + n - 1 - i) / n);
        }
        assert_eq!(files(&shared), reference, "{n} shards in one directory");
        // Shards in separate directories, combined by copying.
        let combined = d.join(format!("combined-{n}"));
        for i in 0..n {
            let part = d.join(format!("part-{n}-{i}"));
            generate(&config, &part, &["--shard", &format!("{i}/{n}")]);
            for (name, bytes) in files(&part) {
                let p = combined.join(&name);
                std::fs::create_dir_all(p.parent().unwrap()).unwrap();
                std::fs::write(p, bytes).unwrap();
            }
        }
        assert_eq!(files(&combined), reference, "{n} shards copied together");
    }
    // A killed run: a frame's .label missing (it is written last); --resume writes only that frame.
    std::fs::remove_file(whole.join("sequences/07/labels/000001.label")).unwrap();
    let summary = generate(&config, &whole, &["--resume"]);
    assert_eq!((summary["frames_written"].as_u64(), summary["frames_skipped"].as_u64()), (Some(1), Some(6)));
    assert_eq!(files(&whole), reference);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_input_is_refused_before_anything_is_written() {
    let d = tmp("bad");
    let cases = [
        (SMALL.replace("scene = \"flat\"\nseed = 4", "scene = \"mars\"\nseed = 4"), "`scene`: `mars`"),
        (SMALL.replace("rig = \"vlp16-roof\"\nframes = 3", "rig = \"vlp99\"\nframes = 3"), "vlp99"),
        (SMALL.replace("frames = 3", "frames = 0"), "`sequences[0]`: invalid value for `frames`: 0"),
        (SMALL.replace("id = 7", "id = 0"), "duplicate"),
        (SMALL.replace("id = 7", "id = 100"), "sequences[1].id"),
        (format!("{SMALL}colour = 1\n"), "unknown field `colour`"),
        (
            SMALL.replace(
                "frames = 3\nspeed_m_per_s = 10.0",
                "frames = 3\nspeed_m_per_s = 0.0\nwaypoints_m = [[0, 0], [5, 0]]",
            ),
            "speed_m_per_s",
        ),
        // The built-in flat scene spans -200 ..= 200 m.
        (SMALL.replace("frames = 3\nspeed_m_per_s = 10.0", "frames = 30\nspeed_m_per_s = 100.0"), "leaves the scene"),
        (
            SMALL.replace(
                "frames = 3\nspeed_m_per_s = 10.0",
                "frames = 3\nspeed_m_per_s = 50.0\nwaypoints_m = [[198, 0], [500, 0]]",
            ),
            "leaves the scene",
        ),
    ];
    for (k, (text, needle)) in cases.iter().enumerate() {
        let config = d.join(format!("bad-{k}.toml"));
        std::fs::write(&config, text).unwrap();
        let out = d.join(format!("out-{k}"));
        let e = err(run(&["dataset", "--config", s(&config), "--out", s(&out)]));
        assert!(e.contains(needle), "case {k}: `{e}` lacks `{needle}`");
        assert!(!out.exists(), "case {k}: wrote {}", out.display());
    }
    // A directory holding another dataset.
    let config = d.join("ok.toml");
    std::fs::write(&config, SMALL).unwrap();
    let out = d.join("taken");
    generate(&config, &out, &["--shard", "0/7"]);
    std::fs::write(&config, SMALL.replace("seed = 4", "seed = 9")).unwrap();
    let e = err(run(&["dataset", "--config", s(&config), "--out", s(&out)]));
    assert!(e.contains("holds another dataset"), "{e}");
    let e = err(run(&["dataset", "--config", s(&config)]));
    assert!(e.contains("--out"), "{e}");
    let _ = std::fs::remove_dir_all(&d);
}
