//! The targets of ordering recovery on our own scans, every bundled scene family x `hdl64e-roof`,
//! `vlp16-roof`, `os1-64-roof` (frame 0, seed 90210 unless given): F1 of `nitsch` through the KITTI
//! `.bin` (scan order, unfolded) against the frame's own grid (the organized `.pcd`), the fraction of
//! points in their true cell, and the same for a shuffled `.bin` (beam table); then every PCD layout
//! and both `.bin` orders against the organized bottom-first file, decision by decision.
//!
//! `cargo run --release -p gt-tests --example real_files_targets [-- SEED [SCENE-FILTER]]`

use classifier::ordering::PathChoice;
use gt_tests::real_files::compare_bin;

fn main() {
    let seed: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(90210);
    // Optional second argument: only scenes whose name contains it.
    let only = std::env::args().nth(2).unwrap_or_default();
    let (mut worst_df1, mut worst_cell, mut worst_shuffled) = (0.0f64, 1.0f64, 1.0f64);
    println!("scene rig points path f1_grid f1_bin d_f1 true_cell | shuffled: path true_cell f1_bin");
    for rig in ["hdl64e-roof", "vlp16-roof", "os1-64-roof"] {
        for scene in scenes::bundled_names().into_iter().filter(|s| s.contains(only.as_str())) {
            let a = compare_bin(scene, rig, seed, "nitsch", false, PathChoice::Auto);
            let b = compare_bin(scene, rig, seed, "nitsch", true, PathChoice::Auto);
            let d = (a.f1_bin - a.f1_grid).abs();
            worst_df1 = worst_df1.max(d);
            worst_cell = worst_cell.min(a.true_cell);
            worst_shuffled = worst_shuffled.min(b.true_cell);
            println!(
                "{scene} {rig} {} {} {:.4} {:.4} {:.4} {:.4} | {} {:.4} {:.4}{}",
                a.points,
                a.report.path.name(),
                a.f1_grid,
                a.f1_bin,
                d,
                a.true_cell,
                b.report.path.name(),
                b.true_cell,
                b.f1_bin,
                a.report.fallback.as_ref().map(|f| format!("  (fallback: {f})")).unwrap_or_default()
            );
        }
    }
    println!(
        "worst |dF1| {worst_df1:.4}, worst true-cell {worst_cell:.4}, worst shuffled true-cell {worst_shuffled:.4}"
    );
    println!("layouts against the organized bottom-first file (decisions differing / returns):");
    for (scene, rig) in [("city", "hdl64e-roof"), ("highway", "vlp16-roof"), ("city", "os1-64-roof")] {
        for a in gt_tests::real_files::layout_agreement(scene, rig, seed, "nitsch") {
            println!("  {scene} {rig} {}: {} / {}", a.layout, a.differing, a.returns);
        }
    }
}
