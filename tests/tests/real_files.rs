//! Our scans through the paths real files take (`gt_tests::real_files`): a frame written as a KITTI
//! `.bin` in scan order is unfolded into its true cells and classified as on its own grid; the same
//! file shuffled is ordered from the beam table. A subset of the scenes and rigs here (the whole
//! matrix, every scene family x `hdl64e-roof` / `vlp16-roof` / `os1-64-roof`, is
//! `cargo run --release -p gt-tests --example real_files_targets`).

use classifier::ordering::{OrderingPath, PathChoice};
use gt_tests::real_files::compare_bin;

#[test]
fn scan_ordered_bin_unfolds_into_true_cells_with_the_grid_f1() {
    for (scene, rig) in [("highway", "hdl64e-roof"), ("city", "vlp16-roof"), ("forest-sparse", "os1-64-roof")] {
        let c = compare_bin(scene, rig, 90210, "nitsch", false, PathChoice::Auto);
        assert_eq!(c.report.path, OrderingPath::Unfolded, "{scene} {rig}: {}", c.report.summary());
        assert_eq!(c.report.kept(), c.points, "{scene} {rig}: every point keeps a cell");
        assert!(c.true_cell >= 0.995, "{scene} {rig}: {:.4} in their true cell", c.true_cell);
        assert!((c.f1_bin - c.f1_grid).abs() <= 0.005, "{scene} {rig}: F1 {:.4} vs {:.4}", c.f1_bin, c.f1_grid);
    }
}

#[test]
fn shuffled_bin_falls_back_to_the_beam_table() {
    let c = compare_bin("city", "hdl64e-roof", 90210, "nitsch", true, PathChoice::Auto);
    assert_eq!(c.report.path, OrderingPath::BeamTable, "{}", c.report.summary());
    assert!(c.report.fallback.is_some());
    assert_eq!(c.report.kept(), c.points);
    assert!(c.true_cell >= 0.97, "{:.4} in their true cell", c.true_cell);
    assert!((c.f1_bin - c.f1_grid).abs() <= 0.005, "F1 {:.4} vs {:.4}", c.f1_bin, c.f1_grid);
}

#[test]
fn every_layout_gives_the_decisions_of_the_organized_bottom_first_file() {
    for a in gt_tests::real_files::layout_agreement("city", "os1-64-roof", 90210, "nitsch") {
        assert!(a.returns > 10_000, "{}: {} returns", a.layout, a.returns);
        // The ouster layout stores ranges in whole millimetres; the rest is the same points.
        let allowed = if a.layout.starts_with("ouster") { a.returns / 1000 } else { 0 };
        assert!(
            a.differing <= allowed,
            "{}: {} of {} decisions differ ({})",
            a.layout,
            a.differing,
            a.returns,
            a.summary
        );
    }
}
