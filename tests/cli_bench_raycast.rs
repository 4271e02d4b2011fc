//! `groundtruth bench raycast` on a ray file: every frame casts every ray, so the hits of `--frames
//! 3` are three times those of one frame, and a ray set aimed half at the ground and half at the
//! sky hits exactly the half aimed down.

use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_groundtruth");

fn hits(rays: &std::path::Path, frames: &str) -> u64 {
    let out = Command::new(BIN)
        .args(["bench", "raycast", "--scene", "flat", "--rays"])
        .arg(rays)
        .args(["--frames", frames, "--threads", "2"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}\n{stdout}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["rays"].as_u64(), Some(1000 * frames.parse::<u64>().unwrap()), "{stdout}");
    v["hits"].as_u64().unwrap()
}

#[test]
fn every_frame_casts_every_ray() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rays.bin");
    // 1,000 rays from 1.5 m above the flat scene's ground: 500 pitched 10-60 deg down (each meets
    // the ground within 9 m), 500 pitched 10-60 deg up (sky).
    let mut bytes = Vec::new();
    for k in 0..1000 {
        let azimuth = k as f32 * 0.37;
        let pitch = (10.0 + (k % 500) as f32 * 0.1).to_radians() * if k < 500 { -1.0 } else { 1.0 };
        let d = [pitch.cos() * azimuth.cos(), pitch.cos() * azimuth.sin(), pitch.sin()];
        for v in [0.0, 0.0, 1.5, d[0], d[1], d[2]] {
            bytes.extend_from_slice(&f32::to_le_bytes(v));
        }
    }
    std::fs::write(&path, bytes).unwrap();
    let one = hits(&path, "1");
    assert_eq!(one, 500);
    assert_eq!(hits(&path, "3"), 3 * one);
}
