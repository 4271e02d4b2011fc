//! Weather through the binary: `scan --weather`, a scene file's `[weather]` table (and the flag
//! over it), a dataset's top-level and per-sequence weather, a sweep over weather kinds and over
//! fog visibility, and bad specs refused with the field and its range before anything is written.

use std::path::{Path, PathBuf};

use crate::common;

use common::{err, ok, run, s};

/// A fresh scratch directory for this file's test `name`.
fn tmp(name: &str) -> PathBuf {
    common::tmp("weather", name)
}

/// Label ids of a SemanticKITTI `.label` file and how often each occurs.
fn label_counts(path: &Path) -> std::collections::BTreeMap<u16, usize> {
    let bytes = std::fs::read(path).unwrap();
    let mut counts = std::collections::BTreeMap::new();
    for c in bytes.chunks_exact(4) {
        *counts.entry(u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as u16).or_insert(0) += 1;
    }
    counts
}

#[test]
fn scan_weather_flag_and_scene_table() {
    let dir = tmp("scan");
    let out = dir.join("fog");
    ok(run(&[
        "scan",
        "--scene",
        "city",
        "--rig",
        "hdl64e-roof",
        "--format",
        "kitti",
        "--weather",
        "fog:visibility_m=40",
        "--out",
        s(&out),
    ]));
    let labels = label_counts(&out.join("frame_000000.label"));
    let fog = labels.get(&150).copied().unwrap_or(0);
    assert!(fog > 5000, "{labels:?}");
    let manifest = std::fs::read_to_string(out.join("manifest.json")).unwrap();
    assert!(manifest.contains("\"weather\": \"fog:visibility_m=40\""), "{manifest}");

    // A scene file with [weather]: snow unless the flag says otherwise.
    let scene = dir.join("snowy.toml");
    std::fs::write(&scene, "version = 1\nfamily = \"highway\"\n[weather]\nkind = \"snow\"\nrate_mm_h = 1.5\n").unwrap();
    let snowy = dir.join("snowy");
    ok(run(&["scan", "--scene", s(&scene), "--rig", "vlp16-roof", "--format", "kitti", "--out", s(&snowy)]));
    let labels = label_counts(&snowy.join("frame_000000.label"));
    assert!(labels.get(&152).copied().unwrap_or(0) > 100, "{labels:?}");
    let clear = dir.join("clear");
    ok(run(&[
        "scan",
        "--scene",
        s(&scene),
        "--rig",
        "vlp16-roof",
        "--format",
        "kitti",
        "--weather",
        "clear",
        "--out",
        s(&clear),
    ]));
    let labels = label_counts(&clear.join("frame_000000.label"));
    assert!(!labels.keys().any(|&k| (150..=152).contains(&k)), "{labels:?}");
}

#[test]
fn bad_weather_is_refused_naming_the_field() {
    let dir = tmp("bad");
    for (spec, needle) in [
        ("fog:visibility_m=0.5", "weather.visibility_m"),
        ("fog:visibility_m=-10", "1 ..= 100000"),
        ("fog:visibility_m=NaN", "weather.visibility_m"),
        ("rain:rate_mm_h=-2", "weather.rate_mm_h"),
        ("snow:rate_mm_h=25", "0 ..= 5"),
        ("hail:rate_mm_h=2", "clear, fog, rain, snow"),
        ("snow:visibility_m=50", "snow takes rate_mm_h"),
    ] {
        let out = dir.join("never");
        let e = err(run(&["scan", "--scene", "flat", "--weather", spec, "--out", s(&out)]));
        assert!(e.contains(needle), "{spec}: {e}");
        assert!(!out.exists(), "{spec}: wrote {}", out.display());
    }
    // In a scene file: an unknown field and a bad value.
    let scene = dir.join("bad.toml");
    std::fs::write(&scene, "version = 1\nfamily = \"flat\"\n[weather]\nkind = \"fog\"\nvisibility = 50.0\n").unwrap();
    let e = err(run(&["scan", "--scene", s(&scene), "--out", s(&dir.join("never"))]));
    assert!(e.contains("visibility"), "{e}");
    std::fs::write(&scene, "version = 1\nfamily = \"flat\"\n[weather]\nkind = \"fog\"\nvisibility_m = 0.0\n").unwrap();
    let e = err(run(&["scan", "--scene", s(&scene), "--out", s(&dir.join("never"))]));
    assert!(e.contains("visibility_m") && e.contains("1 ..= 100000"), "{e}");
}

#[test]
fn dataset_weather_per_sequence_and_default() {
    let dir = tmp("dataset");
    let config = dir.join("d.toml");
    std::fs::write(
        &config,
        r#"
[weather]
kind = "snow"
rate_mm_h = 3.0

[[sequences]]
id = 0
scene = "flat"
rig = "vlp16-roof"
frames = 1

[[sequences]]
id = 1
scene = "flat"
rig = "vlp16-roof"
frames = 1
weather = { kind = "fog", visibility_m = 25.0 }
"#,
    )
    .unwrap();
    let out = dir.join("out");
    ok(run(&["dataset", "--config", s(&config), "--out", s(&out)]));
    // (Snow rather than rain: rain's drops are too faint to show beyond the receiver's overlap.)
    let snow = label_counts(&out.join("sequences/00/labels/000000.label"));
    let fog = label_counts(&out.join("sequences/01/labels/000000.label"));
    assert!(snow.get(&152).copied().unwrap_or(0) > 0 && !snow.contains_key(&150), "{snow:?}");
    assert!(fog.get(&150).copied().unwrap_or(0) > 1000 && !fog.contains_key(&152), "{fog:?}");
    let yaml = std::fs::read_to_string(out.join("groundtruth.yaml")).unwrap();
    assert!(yaml.contains("150: \"fog\"") && yaml.contains("152: \"snow\""), "label config lacks the weather classes");

    std::fs::write(&config, "[[sequences]]\nid = 0\nscene = \"flat\"\nrig = \"vlp16-roof\"\nframes = 1\nweather = { kind = \"snow\", rate_mm_h = -1.0 }\n").unwrap();
    let e = err(run(&["dataset", "--config", s(&config), "--out", s(&dir.join("never"))]));
    assert!(e.contains("sequences[0]") && e.contains("weather.rate_mm_h") && e.contains("0 ..= 5"), "{e}");
    assert!(!dir.join("never").exists());
}

#[test]
fn sweep_over_weather_kinds_and_visibility() {
    let dir = tmp("sweep");
    let kinds = dir.join("kinds.toml");
    std::fs::write(
        &kinds,
        "scenes = [\"flat\"]\nrigs = [\"vlp16-roof\"]\nseeds = [0]\nmethods = [\"ransac\"]\nweather = [\"clear\", \"fog:visibility_m=30\", \"snow:rate_mm_h=2\"]\n",
    )
    .unwrap();
    let out = dir.join("kinds");
    ok(run(&["sweep", "--config", s(&kinds), "--out", s(&out)]));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let w = header.iter().position(|&h| h == "weather").expect("a weather column");
    let returns = header.iter().position(|&h| h == "returns").unwrap();
    let ground = header.iter().position(|&h| h == "ground_returns").unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3);
    let get =
        |kind: &str, col: usize| -> f64 { rows.iter().find(|r| r[w].starts_with(kind)).unwrap()[col].parse().unwrap() };
    // Fog of 30 m turns most of the flat ground beyond ~15 m into fog returns.
    assert!(get("fog", ground) < 0.8 * get("clear", ground), "{csv}");
    assert!(get("snow", returns) > 0.0);

    let vis = dir.join("vis.toml");
    std::fs::write(
        &vis,
        "scenes = [\"flat\"]\nrigs = [\"vlp16-roof\"]\nseeds = [0]\nmethods = [\"ransac\"]\n[weather]\nkind = \"fog\"\nvisibility_m = [20, 60, 200]\n",
    )
    .unwrap();
    let out = dir.join("vis");
    ok(run(&["sweep", "--config", s(&vis), "--out", s(&out)]));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert!(csv.lines().next().unwrap().contains("weather.fog.visibility_m"), "{csv}");
    let png = dir.join("vis.png");
    ok(run(&[
        "sweep",
        "plot",
        s(&out),
        "--x",
        "weather.fog.visibility_m",
        "--metric",
        "ground_returns",
        "--out",
        s(&png),
    ]));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);

    std::fs::write(
        &vis,
        "scenes = [\"flat\"]\nrigs = [\"vlp16-roof\"]\nseeds = [0]\nmethods = [\"ransac\"]\n[weather]\nkind = \"fog\"\nvisibility_m = [0.5, 60]\n",
    )
    .unwrap();
    let e = err(run(&["sweep", "--config", s(&vis), "--out", s(&dir.join("never"))]));
    assert!(e.contains("visibility_m") && e.contains("1 ..= 100000"), "{e}");
}
