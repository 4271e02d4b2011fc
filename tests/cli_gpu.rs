//! `groundtruth scan --backend gpu` writes the same files as `--backend bvh` (on Mesa's lavapipe in
//! CI), for a moving vehicle (rays uploaded every frame) and a standing one (rays kept on the
//! device after the first frame). Without a GPU adapter the test is skipped with a message, unless
//! `GROUNDTRUTH_REQUIRE_GPU=1` makes that a failure.

use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_groundtruth");

#[test]
fn gpu_scan_writes_the_bvh_scans_files() {
    let dir = std::env::temp_dir().join(format!("gt-gpu-scan-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let scan = |backend: &str, speed: &str| {
        Command::new(BIN)
            .args(["scan", "--scene", "flat-objects", "--rig", "vlp16-roof", "--frames", "2", "--speed", speed])
            .args(["--format", "kitti,pcd", "--backend", backend, "--out"])
            .arg(dir.join(format!("{backend}-{speed}")))
            .output()
            .unwrap()
    };
    let gpu = scan("gpu", "5");
    if !gpu.status.success() {
        let err = String::from_utf8_lossy(&gpu.stderr);
        assert!(
            err.contains("no GPU adapter") && std::env::var("GROUNDTRUTH_REQUIRE_GPU").as_deref() != Ok("1"),
            "{err}"
        );
        eprintln!("skipped: {err}");
        return;
    }
    for (backend, speed) in [("bvh", "5"), ("gpu", "0"), ("bvh", "0")] {
        assert!(scan(backend, speed).status.success());
    }
    for speed in ["5", "0"] {
        for k in 0..2 {
            for ext in ["bin", "label", "pcd"] {
                let name = format!("frame_{k:06}.{ext}");
                let (a, b) = (
                    std::fs::read(dir.join(format!("gpu-{speed}")).join(&name)).unwrap(),
                    std::fs::read(dir.join(format!("bvh-{speed}")).join(&name)).unwrap(),
                );
                assert!(a.len() > 1000, "{name}");
                assert!(a == b, "{name} at speed {speed} differs between --backend gpu and --backend bvh");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
