//! Integration tests of the scan spec through the binary: `scan --spec FILE` makes the same bytes
//! as the same scan given by flags; every manifest holds the spec it was made from and `scan --spec`
//! on it remakes the files byte for byte; the deprecated unit spellings still work (with a warning
//! on stderr); an unknown key, a key without its unit and a mount outside the one set of limits are
//! refused with the same message by `scan --spec`, dataset files and sweep files, nothing written.

use std::path::{Path, PathBuf};

use crate::common;

use common::{err, files, ok, run, s};

/// A fresh scratch directory for this file's test `name`.
fn tmp(name: &str) -> PathBuf {
    common::tmp("spec", name)
}

fn manifest(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap()
}

#[test]
fn a_spec_file_makes_the_bytes_the_flags_make_and_the_manifest_remakes_them() {
    let d = tmp("remake");
    let (flags, from_spec, from_manifest) = (d.join("flags"), d.join("spec"), d.join("manifest"));
    let out = run(&[
        "scan",
        "--scene",
        "city",
        "--rig",
        "vlp16-roof",
        "--seed",
        "3",
        "--frames",
        "2",
        "--speed",
        "7.5",
        "--yaw-rate",
        "0.2",
        "--weather",
        "fog:visibility_m=60",
        "--format",
        "pcd,kitti",
        "--out",
        s(&flags),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let warnings = String::from_utf8_lossy(&out.stderr);
    assert!(
        warnings.contains("--speed is deprecated")
            && warnings.contains("--yaw-rate (radians per second) is deprecated")
    );
    // The manifest's old fields keep the rad/s the flag gave, to the bit; its spec says deg/s.
    let m = manifest(&flags);
    assert_eq!(m["yaw_rate_rad_per_s"].as_f64().unwrap() as f32, 0.2f32);
    let spec = &m["spec"];
    assert_eq!(spec["scene"], "city");
    assert_eq!(spec["yaw_rate_deg_per_s"].as_f64().unwrap().to_radians() as f32, 0.2f32);
    assert_eq!(spec["weather"]["kind"], "fog");

    // The same scan as a TOML spec (new spellings).
    let toml = format!(
        "scene = \"city\"\nrig = \"vlp16-roof\"\nseed = 3\nframes = 2\nspeed_m_per_s = 7.5\nyaw_rate_deg_per_s = {}\n\
         weather = {{ kind = \"fog\", visibility_m = 60.0 }}\n",
        spec["yaw_rate_deg_per_s"].as_f64().unwrap()
    );
    std::fs::write(d.join("scan.toml"), toml).unwrap();
    ok(run(&["scan", "--spec", s(&d.join("scan.toml")), "--format", "pcd,kitti", "--out", s(&from_spec)]));
    assert_eq!(files(&flags), files(&from_spec), "scan --spec makes other bytes than the flags");

    // The manifest's spec, as a file, remakes every file byte for byte.
    std::fs::write(d.join("manifest-spec.json"), serde_json::to_string_pretty(spec).unwrap()).unwrap();
    ok(run(&["scan", "--spec", s(&d.join("manifest-spec.json")), "--format", "pcd,kitti", "--out", s(&from_manifest)]));
    assert_eq!(files(&flags), files(&from_manifest));
}

#[test]
fn new_unit_spellings_equal_the_old_ones() {
    let d = tmp("units");
    ok(run(&["scan", "--frames", "2", "--speed-m-per-s", "5", "--yaw-rate-deg-per-s", "10", "--out", s(&d.join("a"))]));
    let m = manifest(&d.join("a"));
    assert_eq!(m["yaw_rate_rad_per_s"].as_f64().unwrap() as f32, 10f64.to_radians() as f32);
    assert_eq!(m["speed_m_per_s"].as_f64().unwrap(), 5.0);
    // Old and new spellings together are a usage error; so are description flags beside --spec.
    assert!(err(run(&["scan", "--speed", "5", "--speed-m-per-s", "5", "--out", s(&d.join("b"))])).contains("--speed"));
    std::fs::write(d.join("s.toml"), "scene = \"flat\"\nrig = \"vlp16-roof\"\nframes = 1\n").unwrap();
    let e = err(run(&["scan", "--spec", s(&d.join("s.toml")), "--scene", "city", "--out", s(&d.join("c"))]));
    assert!(e.contains("--scene") && e.contains("--spec"), "{e}");
    assert!(!d.join("b").exists() && !d.join("c").exists());
    // The built-in scene and a family are reachable by name.
    ok(run(&["scan", "--scene", "ramp", "--out", s(&d.join("family"))]));
}

/// The message every front end gives for each bad input.
const BAD: [(&str, &str); 3] = [
    ("colour = 1\n", "unknown field `colour`"),
    ("yaw_rate = 0.3\n", "invalid value for `yaw_rate`: a key without the unit every front end takes"),
    ("mount = { z_m = 150.0 }\n", "invalid value for `mount.z_m`: 150 (allowed: -100 ..= 100)"),
];

#[test]
fn bad_input_gets_the_same_message_from_every_front_end() {
    let d = tmp("bad");
    for (k, (extra, message)) in BAD.iter().enumerate() {
        // scan --spec
        let spec = d.join(format!("spec{k}.toml"));
        std::fs::write(&spec, format!("scene = \"flat\"\nrig = \"vlp16-roof\"\nframes = 1\n{extra}")).unwrap();
        let out = d.join(format!("scan{k}"));
        let e = err(run(&["scan", "--spec", s(&spec), "--out", s(&out)]));
        assert!(e.contains(message), "scan --spec, {extra}: {e}");
        assert!(!out.exists());
        // A dataset file's sequence.
        let dataset = d.join(format!("dataset{k}.toml"));
        let text = format!("[[sequences]]\nid = 0\nscene = \"flat\"\nrig = \"vlp16-roof\"\nframes = 1\n{extra}");
        std::fs::write(&dataset, text).unwrap();
        let out = d.join(format!("dataset{k}"));
        let e = err(run(&["dataset", "--config", s(&dataset), "--out", s(&out)]));
        assert!(e.contains(message), "dataset, {extra}: {e}");
        assert!(!out.exists());
    }
    // A sweep file: a unit-less key and a mount value outside the limits.
    let base = "scenes = [\"flat\"]\nrigs = [\"vlp16-roof\"]\nseeds = [0]\nmethods = [\"nitsch\"]\n";
    for (extra, message) in
        [("yaw_rate = 0.3\n", BAD[1].1), ("colour = 1\n", BAD[0].1), ("[mount]\nz_m = [150.0]\n", BAD[2].1)]
    {
        let sweep = d.join("sweep.toml");
        let text = if extra.starts_with('[') { format!("{base}{extra}") } else { format!("{extra}{base}") };
        std::fs::write(&sweep, text).unwrap();
        let out = d.join("sweep");
        let e = err(run(&["sweep", "--config", s(&sweep), "--out", s(&out)]));
        assert!(e.contains(message), "sweep, {extra}: {e}");
        assert!(!out.exists());
    }
    // A flag out of range names the spec's field and range.
    let e = err(run(&["scan", "--yaw-rate-deg-per-s", "200", "--out", s(&d.join("flag"))]));
    assert!(e.contains("invalid value for `yaw_rate_deg_per_s`: 200 (allowed: -114.59 ..= 114.59)"), "{e}");
}

#[test]
fn a_dataset_manifest_holds_each_sequences_spec() {
    let d = tmp("dataset");
    let text = "[[sequences]]\nid = 2\nscene = \"flat\"\nseed = 4\nrig = \"vlp16-roof\"\nframes = 2\n\
                speed_m_per_s = 5.0\nmount = { mode = \"relative\", z_m = 0.2 }\n";
    std::fs::write(d.join("d.toml"), text).unwrap();
    ok(run(&["dataset", "--config", s(&d.join("d.toml")), "--out", s(&d.join("out"))]));
    let m = manifest(&d.join("out"));
    let spec = &m["sequences"][0]["spec"];
    assert_eq!((spec["seed"].as_u64(), spec["backend"].as_str()), (Some(4), Some("bvh")));
    assert_eq!(spec["mount"]["mode"], "relative");
    // The mount as scanned: the rig's own height plus 0.2 m.
    let rig_z = m["sequences"][0]["mounts"][0]["z_m"].as_f64().unwrap() as f32;
    assert_eq!(rig_z, 1.85f32 + 0.2, "{}", m["sequences"][0]["mounts"]);
}
