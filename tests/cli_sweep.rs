//! Integration tests of `groundtruth sweep` through the binary: bad input refused before work,
//! sharded + merged runs equal to the unsharded run byte for byte (sorted) at 1 and 2 threads,
//! a run killed with SIGKILL and resumed loses and repeats no row, plots and the report.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_groundtruth");

/// A small sweep: 2 seeds x 3 heights x 3 pitches of `lux-roof-4` on `flat-objects` = 18 configurations.
const SMALL: &str = r#"
scenes = ["flat-objects"]
rigs = ["lux-roof-4"]
seeds = [0, 1]
methods = ["nitsch", "ransac"]
[mount]
z_m = [1.4, 1.6, 1.8]
pitch_deg = { from = -2, to = 2, step = 2 }
"#;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn sweep(args: &[&str]) -> Output {
    Command::new(BIN).arg("sweep").args(args).output().unwrap()
}

fn ok(out: Output) -> String {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

fn err(out: Output) -> String {
    assert!(!out.status.success(), "accepted: {}", String::from_utf8_lossy(&out.stdout));
    String::from_utf8(out.stderr).unwrap()
}

fn sorted_lines(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines.sort();
    lines
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn sharded_and_merged_equals_unsharded_at_1_and_2_threads() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "small.toml", SMALL);
    let whole = dir.path().join("whole");
    let summary = ok(sweep(&["--config", s(&cfg), "--out", s(&whole), "--threads", "2"]));
    let summary: serde_json::Value = serde_json::from_str(summary.trim()).unwrap();
    assert_eq!(summary["configurations"], 18);
    assert_eq!(summary["rows"], 36);
    // One scene generation and BVH per (scene, seed), not per configuration.
    assert_eq!(summary["scenes_prepared"], 2);
    let reference = sorted_lines(&whole.join("results.csv"));
    assert_eq!(reference.len(), 37);
    let header: Vec<&str> = reference.iter().find(|l| l.starts_with("key,")).unwrap().split(',').collect();
    assert_eq!(&header[..8], ["key", "scene", "rig", "seed", "body", "z_m", "pitch_deg", "method"]);
    let rows: Vec<Vec<&str>> =
        reference.iter().filter(|l| !l.starts_with("key,")).map(|l| l.split(',').collect()).collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    for r in &rows {
        let returns: u64 = r[col("returns")].parse().unwrap();
        let ground: u64 = r[col("ground_returns")].parse().unwrap();
        assert!(returns > 1000 && ground > 100 && ground <= returns, "{r:?}");
        let f1: f64 = r[col("f1")].parse().unwrap();
        assert!((0.0..=1.0).contains(&f1));
        let blind: f64 = r[col("blind_zone_m")].parse().unwrap();
        assert!(blind > 2.0 && blind < 30.0, "{blind}");
    }
    // Nitsch on flat ground is near perfect; tilting the rig down (+pitch) shrinks the blind zone.
    let nitsch_f1: Vec<f64> =
        rows.iter().filter(|r| r[col("method")] == "nitsch").map(|r| r[col("f1")].parse().unwrap()).collect();
    assert!(nitsch_f1.iter().all(|&f| f > 0.9), "{nitsch_f1:?}");
    let blind_at = |pitch: &str| -> f64 {
        rows.iter()
            .find(|r| r[col("seed")] == "0" && r[col("z_m")] == "1.6" && r[col("pitch_deg")] == pitch)
            .map(|r| r[col("blind_zone_m")].parse().unwrap())
            .unwrap()
    };
    assert!(blind_at("2") < blind_at("0") && blind_at("0") < blind_at("-2"));
    // The JSON lines hold the same rows.
    let json = std::fs::read_to_string(whole.join("results.jsonl")).unwrap();
    assert_eq!(json.lines().count(), 36);
    let first: serde_json::Value = serde_json::from_str(json.lines().next().unwrap()).unwrap();
    assert!(first["key"].as_str().unwrap().len() == 32 && first["f1"].is_number());

    // Plots (a line per method with a band over the 2 seeds; a heat map) and the report.
    let png = dir.path().join("f1.png");
    ok(sweep(&["plot", s(&whole), "--x", "pitch_deg", "--metric", "f1", "--out", s(&png)]));
    let img = image::open(&png).unwrap().to_rgb8();
    assert!(img.pixels().any(|p| p.0 == [31, 119, 180]) && img.pixels().any(|p| p.0 == [214, 39, 40]));
    let svg = dir.path().join("heat.svg");
    let args = ["plot", s(&whole), "--x", "pitch_deg", "--y", "z_m", "--metric", "recall", "--where", "method=nitsch"];
    ok(sweep(&[&args[..], &["--out", s(&svg)]].concat()));
    assert!(std::fs::read_to_string(&svg).unwrap().contains("mount height z (m)"));
    let e = err(sweep(&["plot", s(&whole), "--x", "height", "--metric", "f1", "--out", s(&png)]));
    assert!(e.contains("not a swept parameter"), "{e}");
    let e = err(sweep(&["plot", s(&whole), "--x", "z_m", "--metric", "speed", "--out", s(&png)]));
    assert!(e.contains("not a metric"), "{e}");
    ok(sweep(&["report", s(&whole)]));
    let md = std::fs::read_to_string(whole.join("report.md")).unwrap();
    for needle in ["| nitsch | best |", "| nitsch | worst |", "| ransac | best |", "plots/f1_vs_pitch_deg.png"] {
        assert!(md.contains(needle), "{needle}: {md}");
    }
    assert!(whole.join("plots/f1_vs_pitch_deg.png").exists());

    for threads in ["1", "2"] {
        let shards: Vec<PathBuf> = (0..3).map(|i| dir.path().join(format!("shard{threads}-{i}"))).collect();
        for (i, d) in shards.iter().enumerate() {
            let shard = format!("{i}/3");
            ok(sweep(&["--config", s(&cfg), "--out", s(d), "--shard", &shard, "--threads", threads]));
            assert_eq!(sorted_lines(&d.join("results.csv")).len(), 1 + 12);
        }
        let merged = dir.path().join(format!("merged{threads}"));
        let m = ok(sweep(&["merge", s(&shards[2]), s(&shards[0]), s(&shards[1]), "--out", s(&merged)]));
        assert!(m.contains("\"missing\":0"), "{m}");
        assert_eq!(sorted_lines(&merged.join("results.csv")), reference, "threads {threads}");
        assert_eq!(sorted_lines(&merged.join("results.jsonl")), sorted_lines(&whole.join("results.jsonl")));
    }
}

#[test]
fn killed_run_resumes_without_losing_or_repeating_rows() {
    let dir = tempfile::tempdir().unwrap();
    // 8 seeds x 6 x 5 = 240 configurations on one thread: long enough to be killed part way.
    let cfg = write(
        dir.path(),
        "kill.toml",
        r#"
scenes = ["flat-objects"]
rigs = ["lux-roof-4"]
seeds = { from = 0, to = 7 }
methods = ["nitsch", "ransac"]
[mount]
z_m = { from = 1.2, to = 2.2, step = 0.2 }
pitch_deg = [-2.0, -1.0, 0.0, 1.0, 2.0]
"#,
    );
    let out = dir.path().join("out");
    let mut child = Command::new(BIN)
        .args(["sweep", "--config", s(&cfg), "--out", s(&out), "--threads", "1"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let csv = out.join("results.csv");
    loop {
        // Whole lines only: the last one may be half written when it is read.
        let n = std::fs::read_to_string(&csv).map(|t| t.matches('\n').count()).unwrap_or(0);
        if n > 10 {
            break;
        }
        assert!(child.try_wait().unwrap().is_none(), "the sweep ended before it could be killed");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let before = sorted_lines(&csv).len() - 1;
    assert!(before < 480, "{before} rows: the sweep finished before the kill");
    // Without --resume the directory is refused; with it, the run completes.
    let e = err(sweep(&["--config", s(&cfg), "--out", s(&out)]));
    assert!(e.contains("--resume"), "{e}");
    let summary = ok(sweep(&["--config", s(&cfg), "--out", s(&out), "--resume", "--threads", "2"]));
    let summary: serde_json::Value = serde_json::from_str(summary.trim()).unwrap();
    let already = summary["already_done"].as_u64().unwrap();
    // At least 5 configurations had their rows in results.csv; a configuration counts as done only
    // once its results.jsonl rows follow (written after the CSV's), so the kill may cut the last one.
    assert!(already >= 4 && summary["ran"].as_u64().unwrap() == 240 - already, "{summary}");
    let resumed = sorted_lines(&csv);
    let mut unique = resumed.clone();
    unique.dedup();
    assert_eq!(unique.len(), resumed.len(), "a row is repeated");
    let clean = dir.path().join("clean");
    ok(sweep(&["--config", s(&cfg), "--out", s(&clean), "--threads", "2"]));
    assert_eq!(resumed, sorted_lines(&clean.join("results.csv")));
    assert_eq!(sorted_lines(&out.join("results.jsonl")), sorted_lines(&clean.join("results.jsonl")));
    // A resume of a finished sweep runs nothing.
    let again = ok(sweep(&["--config", s(&cfg), "--out", s(&out), "--resume"]));
    assert!(again.contains("\"ran\":0"), "{again}");
}

#[test]
fn bad_input_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "small.toml", SMALL);
    let out = dir.path().join("out");
    let bad = |text: &str, needle: &str| {
        let f = write(dir.path(), "bad.toml", text);
        let e = err(sweep(&["--config", s(&f), "--out", s(&out)]));
        assert!(e.contains(needle), "{needle}: {e}");
        assert!(!out.exists(), "{needle}: work started");
    };
    bad(&format!("{SMALL}height_m = [1.0]\n"), "height_m");
    bad(&SMALL.replace("z_m = [1.4, 1.6, 1.8]", "z_m = []"), "empty");
    bad(&SMALL.replace("from = -2, to = 2", "from = 2, to = -2"), "reversed");
    bad(&SMALL.replace("step = 2", "step = 0"), "step");
    bad(&SMALL.replace("z_m =", "height ="), "unknown mount parameter `mount.height`");
    bad(&SMALL.replace("\"flat-objects\"", "\"moon\""), "unknown scene `moon`");
    bad(&SMALL.replace("\"nitsch\"", "\"magic\""), "magic");
    bad(
        &format!(
            "{SMALL}x_m = {{ from = 0, to = 999 }}\ny_m = {{ from = 0, to = 99 }}\nyaw_deg = {{ from = 0, to = 99 }}\n"
        ),
        "--allow-large",
    );
    for shard in ["5/4", "0/0", "4/4", "x"] {
        let e = err(sweep(&["--config", s(&cfg), "--out", s(&out), "--shard", shard]));
        assert!(e.contains("--shard"), "{shard}: {e}");
    }
    assert!(!out.exists());
    // An output directory holding another sweep's results.
    ok(sweep(&["--config", s(&cfg), "--out", s(&out)]));
    let other = write(dir.path(), "other.toml", &SMALL.replace("[1.4, 1.6, 1.8]", "[1.5]"));
    let e = err(sweep(&["--config", s(&other), "--out", s(&out), "--resume"]));
    assert!(e.contains("another job"), "{e}");
    // Merging directories of two different sweeps is refused.
    let out2 = dir.path().join("out2");
    ok(sweep(&["--config", s(&other), "--out", s(&out2)]));
    let e = err(sweep(&["merge", s(&out), s(&out2), "--out", s(&dir.path().join("m"))]));
    assert!(e.contains("another sweep"), "{e}");
}
