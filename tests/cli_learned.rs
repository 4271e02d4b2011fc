//! Integration tests of the learned method and of `eval dataset` through the binary:
//! - `train --method learned` on a small dataset file trains in seconds, deterministically (the
//!   same model bytes twice, and at 1 and 2 threads), and the model beats a stated F1 on scene
//!   seeds it never saw, scored by `eval dataset` on a dataset `groundtruth dataset` wrote;
//! - `eval dataset`: the JSON document's structure and counts, `--out` pictures, `--ground`,
//!   the protocols, and every bad input refused naming the file or flag, with nothing written.

use std::path::{Path, PathBuf};

use crate::common;

use common::{err, ok, run, s};

/// A fresh scratch directory for this file's test `name`.
fn tmp(name: &str) -> PathBuf {
    common::tmp("learned", name)
}

/// A small training set: four scene families, two rigs, randomised mounts and noise, 8 sequences
/// of 2 frames, 20 trees.
const TRAIN: &str = r#"
name = "ci-small"
[generate]
seed = 5
sequences = 8
frames = 2
scenes = ["city", "rural", "forest-moderate", "ramp-down"]
rigs = ["vlp16-roof", "os1-64-roof"]
scene_seed = [1, 99999]
mount_z_m = [1.2, 2.2]
pitch_deg = [-3.0, 3.0]
noise_scale = [0.5, 2.0]
dropout = [0.0, 0.1]
[train]
method = "learned"
trees = 20
depth = 6
eta = 0.3
samples_per_frame = 8000
validation_every = 4
"#;

/// Held-out frames: other scene seeds (from 200000 on) of two families, the default mounts.
const HELD_OUT: &str = r#"
name = "ci-held-out"
[[sequences]]
id = 0
scene = "city"
seed = 200001
rig = "vlp16-roof"
frames = 2
speed_m_per_s = 8.0
[[sequences]]
id = 1
scene = "rural"
seed = 200002
rig = "os1-64-roof"
frames = 2
speed_m_per_s = 8.0
"#;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn held_out_dataset(dir: &Path) -> PathBuf {
    let config = dir.join("held-out.toml");
    std::fs::write(&config, HELD_OUT).unwrap();
    let data = dir.join("held-out");
    ok(run(&["dataset", "--config", s(&config), "--out", s(&data)]));
    data
}

#[test]
fn a_small_model_trains_deterministically_and_beats_nitsch_on_unseen_seeds() {
    let dir = tmp("train");
    let config = dir.join("train.toml");
    std::fs::write(&config, TRAIN).unwrap();
    let (a, b) = (dir.join("a.json"), dir.join("b.json"));
    let out = ok(run(&["train", "--method", "learned", "--config", s(&config), "--out", s(&a), "--threads", "2"]));
    assert!(out.contains("trained 20 trees"), "{out}");
    ok(run(&["train", "--method", "learned", "--config", s(&config), "--out", s(&b), "--threads", "1"]));
    assert!(std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(), "the same model at 1 and 2 threads");
    let model = json(&a);
    assert_eq!(model["format"], "groundtruth-learned-oblivious-trees");
    assert_eq!(model["trees"].as_array().unwrap().len(), 20);
    // Scored on scene seeds it never saw.
    let data = held_out_dataset(&dir);
    let scores = dir.join("scores.json");
    ok(run(&[
        "eval",
        "dataset",
        "--input",
        s(&data),
        "--methods",
        "nitsch,learned",
        "--model",
        s(&a),
        "--json",
        s(&scores),
    ]));
    let doc = json(&scores);
    let f1 = |m: &str| doc["methods"][m]["pooled"]["f1"].as_f64().unwrap();
    // Measured: learned 0.99+ on these frames, nitsch 0.97-0.98.
    assert!(f1("learned") >= 0.985, "learned F1 {}", f1("learned"));
    assert!(f1("learned") > f1("nitsch"), "learned {} vs nitsch {}", f1("learned"), f1("nitsch"));
    // A model of another format is refused, naming the file.
    let e = err(run(&["eval", "dataset", "--input", s(&data), "--methods", "learned", "--model", s(&config)]));
    assert!(e.contains("train.toml") && e.contains("invalid model JSON"), "{e}");
}

/// `train --config` takes every scene a dataset file takes: here a generator family with its
/// parameters (a steep ramp down), which it used to refuse as an empty scene name.
#[test]
fn training_takes_a_family_with_its_parameters() {
    let dir = tmp("family");
    let config = dir.join("train.toml");
    std::fs::write(
        &config,
        r#"
name = "ci-family"
[[sequences]]
id = 0
family = "ramp"
params = { slope_deg = -17.0, distance_m = 5.0 }
seed = 3
rig = "vlp16-roof"
frames = 1
[[sequences]]
id = 1
scene = "city"
seed = 4
rig = "vlp16-roof"
frames = 1
[train]
method = "learned"
trees = 2
samples_per_frame = 2000
validation_every = 2
"#,
    )
    .unwrap();
    let model = dir.join("m.json");
    let out = ok(run(&["train", "--method", "learned", "--config", s(&config), "--out", s(&model)]));
    assert!(out.contains("2 sequences, 2 frames") && out.contains("trained 2 trees"), "{out}");
    let scenes = &json(&model)["trained_on"]["scenes"];
    assert_eq!(scenes, &serde_json::json!(["city", "ramp"]), "{scenes}");
}

#[test]
fn eval_dataset_writes_scores_pictures_and_refuses_bad_input() {
    let dir = tmp("eval");
    let data = held_out_dataset(&dir);
    let (scores, pictures) = (dir.join("scores.json"), dir.join("pictures"));
    let out = ok(run(&[
        "eval",
        "dataset",
        "--input",
        s(&data),
        "--methods",
        "nitsch,ransac",
        "--json",
        s(&scores),
        "--out",
        s(&pictures),
    ]));
    assert!(out.contains("2 sequence(s), 4 frame(s)") && out.contains("rig and mount from its manifest"), "{out}");
    let doc = json(&scores);
    let nitsch = &doc["methods"]["nitsch"];
    let frames = nitsch["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 4);
    // Pooled counts are the sums of the frames', and the bands' sums too.
    for k in ["tp", "fp", "tn", "fn"] {
        let sum: u64 = frames.iter().map(|f| f["scores"][k].as_u64().unwrap()).sum();
        assert_eq!(nitsch["pooled"][k].as_u64().unwrap(), sum, "{k}");
        let bands: u64 = nitsch["by_range"].as_object().unwrap().values().map(|b| b[k].as_u64().unwrap()).sum();
        assert_eq!(bands, sum, "{k} by range");
    }
    assert!(nitsch["pooled"]["f1"].as_f64().unwrap() > 0.9);
    assert_eq!(doc["range_bands"], serde_json::json!(["0-10m", "10-20m", "20-40m", "40m+"]));
    for m in ["nitsch", "ransac"] {
        for f in ["00_000000", "00_000001", "01_000000", "01_000001"] {
            assert!(pictures.join(m).join(format!("{f}.png")).is_file(), "{m} {f}");
        }
    }
    // Roads only: fewer ground points.
    let roads = dir.join("roads.json");
    ok(run(&["eval", "dataset", "--input", s(&data), "--methods", "nitsch", "--ground", "40,60", "--json", s(&roads)]));
    let r = json(&roads);
    assert_eq!(r["protocol"]["name"], "semantickitti+ground");
    let ground = |d: &serde_json::Value| {
        let p = &d["methods"]["nitsch"]["pooled"];
        p["tp"].as_u64().unwrap() + p["fn"].as_u64().unwrap()
    };
    assert!(ground(&r) < ground(&doc));
    // Roads left out (as WADS's falling snow is, `--ignore 110`): fewer points scored, the ground
    // among them the same as with roads counted as non-ground.
    let left = dir.join("left.json");
    let args = ["eval", "dataset", "--input", s(&data), "--methods", "nitsch", "--ground", "44,48,49,60,72"];
    ok(run(&[&args[..], &["--ignore", "40", "--json", s(&left)]].concat()));
    let l = json(&left);
    assert_eq!(l["protocol"]["name"], "semantickitti+ground+ignore");
    assert!(l["protocol"]["ignored"].as_array().unwrap().contains(&serde_json::json!(40)), "{}", l["protocol"]);
    let scored = |d: &serde_json::Value| {
        let p = &d["methods"]["nitsch"]["pooled"];
        ["tp", "fp", "fn", "tn"].iter().map(|k| p[k].as_u64().unwrap()).sum::<u64>()
    };
    assert!(scored(&l) < scored(&doc));

    // Bad input: each refused with the flag or file named, and no JSON written.
    let written = dir.join("never.json");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["--ground".into(), "40,41".into()], "41"),
        (vec!["--ground".into(), "road".into()], "--ground"),
        (vec!["--ignore".into(), "72".into()], "--ignore"),
        (vec!["--ignore".into(), "112".into()], "112"),
        (vec!["--protocol".into(), "kitti".into()], "--protocol"),
        (vec!["--methods".into(), "nope".into()], "unknown method"),
        (vec!["--sequences".into(), "05".into()], "--sequences"),
        (vec!["--max-frames".into(), "0".into()], "--max-frames"),
    ];
    for (extra, needle) in cases {
        let mut args = vec![
            "eval".to_string(),
            "dataset".into(),
            "--input".into(),
            s(&data).into(),
            "--json".into(),
            s(&written).into(),
        ];
        args.extend(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let e = err(run(&args));
        assert!(e.contains(needle), "{args:?}: {e}");
        assert!(!written.exists());
    }
    // A folder that is no dataset; a sequence without labels; a label count that differs; an
    // empty sequence; a truncated cloud.
    let e = err(run(&["eval", "dataset", "--input", s(&dir.join("pictures"))]));
    assert!(e.contains("not a SemanticKITTI-layout dataset"), "{e}");
    let bad = dir.join("bad/sequences/00");
    std::fs::create_dir_all(bad.join("velodyne")).unwrap();
    std::fs::write(bad.join("velodyne/000000.bin"), [0u8; 32]).unwrap();
    let e = err(run(&["eval", "dataset", "--input", s(&dir.join("bad"))]));
    assert!(e.contains("no `labels/`"), "{e}");
    std::fs::create_dir_all(bad.join("labels")).unwrap();
    std::fs::write(bad.join("labels/000000.label"), [0u8; 12]).unwrap();
    let e = err(run(&["eval", "dataset", "--input", s(&dir.join("bad")), "--json", s(&written)]));
    assert!(e.contains("000000.label") && e.contains("3 labels") && e.contains("2 points"), "{e}");
    assert!(!written.exists());
    std::fs::write(bad.join("velodyne/000000.bin"), [0u8; 30]).unwrap();
    let e = err(run(&["eval", "dataset", "--input", s(&dir.join("bad"))]));
    assert!(e.contains("000000.bin") && e.contains("30 bytes"), "{e}");
    std::fs::remove_file(bad.join("velodyne/000000.bin")).unwrap();
    let e = err(run(&["eval", "dataset", "--input", s(&dir.join("bad"))]));
    assert!(e.contains("no `.bin` frames"), "{e}");
    // Training refuses another method's flags and a dataset without our manifest and --rig.
    let e = err(run(&["train", "--method", "learned", "--scene", "city", "--out", s(&written)]));
    assert!(e.contains("--scene"), "{e}");
    let e = err(run(&["train", "--method", "learned", "--dataset", s(&dir.join("bad")), "--out", s(&written)]));
    assert!(e.contains("--rig"), "{e}");
    assert!(!written.exists());
}

#[test]
fn eval_takes_one_mode_and_refuses_flags_of_another_the_old_spellings_still_work() {
    let dir = tmp("eval-modes");
    let json_path = dir.join("never.json");
    let j = s(&json_path);
    // A flag of another mode is a usage error from the argument parser, before any work.
    for (args, flag) in [
        (
            vec!["eval", "scene", "--scene", "flat", "--rig", "vlp16-roof", "--protocol", "patchwork", "--json", j],
            "--protocol",
        ),
        (vec!["eval", "dataset", "--input", "x", "--frames", "2", "--json", j], "--frames"),
        (vec!["eval", "paper", "mcdaniel", "--methods", "nitsch", "--json", j], "--methods"),
        (vec!["eval", "paper", "forests", "--json", j], "forests"),
        (vec!["eval", "scene", "--rig", "vlp16-roof", "--json", j], "--scene"),
    ] {
        let e = err(run(&args));
        assert!(
            e.contains(flag)
                && (e.contains("unexpected argument") || e.contains("invalid value") || e.contains("required")),
            "{args:?}: {e}"
        );
        assert!(!json_path.exists());
    }
    // `eval scene` scores, and the flat spelling of the previous release gives the same numbers
    // with a deprecation message.
    let (new, old) = (dir.join("new.json"), dir.join("old.json"));
    let common = ["--rig", "vlp16-roof", "--frames", "1", "--methods", "nitsch,ransac"];
    let mut a = vec!["eval", "scene", "--scene", "flat-objects", "--speed-m-per-s", "5", "--json", s(&new)];
    a.extend(common);
    ok(run(&a));
    let mut b = vec!["eval", "--scene", "flat-objects", "--speed", "5", "--json", s(&old)];
    b.extend(common);
    let out = run(&b);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("deprecated") && stderr.contains("eval scene"), "{stderr}");
    assert_eq!(std::fs::read(&new).unwrap(), std::fs::read(&old).unwrap());
    let f1 = json(&new)["methods"]["nitsch"]["f1"].as_f64().unwrap();
    assert!(f1 > 0.9, "nitsch F1 {f1}");
}
