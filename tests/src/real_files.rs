//! Our scans through the paths real files take: a frame written as a KITTI `.bin` (scan order, or
//! shuffled), read back, ordered ([`classifier::ordering`]) and classified, against the same frame
//! classified on its own grid (what the organized `.pcd` gives). Used by `tests/tests/real_files.rs`
//! and `examples/real_files_targets.rs`.

use classifier::ordering::{BeamTable, OrderingReport, PathChoice, PointAttributes, UnfoldParams, order_cloud};
use classifier::{Confusion, method_by_name};
use glam::Vec3;

/// One frame compared through the `.bin` path and on its own grid.
#[derive(Clone, Debug)]
pub struct BinComparison {
    /// F1 of the method on the frame's own grid (the organized PCD path).
    pub f1_grid: f64,
    /// F1 of the method through the `.bin` path, over the same points.
    pub f1_bin: f64,
    /// Fraction of the file's points ordered into their true cell (any plane counts as the cell).
    pub true_cell: f64,
    /// Fraction of points whose decision equals the grid path's decision.
    pub same_decision: f64,
    /// What ordering did.
    pub report: OrderingReport,
    /// Points in the file.
    pub points: usize,
}

/// Scans frame 0 of `scene` (bundled, `seed`) with the single-sensor rig preset `rig`, writes it
/// as KITTI `.bin` bytes (sensor frame, scan order; `shuffle` permutes the points with a fixed
/// permutation), reads them back, orders them with the rig's beam table (`choice`) and classifies
/// with `method` both ways.
pub fn compare_bin(
    scene: &str,
    rig: &str,
    seed: u64,
    method: &str,
    shuffle: bool,
    choice: PathChoice,
) -> BinComparison {
    let spec = crate::ScanSpec { scene: scene.to_string(), rig: rig.to_string(), seed, ..crate::ScanSpec::default() };
    let (frames, rig) = crate::scan_spec(&spec);
    assert_eq!(rig.sensors.len(), 1, "single-sensor rig");
    let cloud = &frames[0].cloud;
    let vehicle_from_sensor = rig.sensors[0].mount.vehicle_from_sensor();
    let sensor_from_vehicle = vehicle_from_sensor.inverse();
    let (bin, _, n) = sim::io::kitti::encode(cloud, Some(&sensor_from_vehicle)).expect("encode");
    let mut order = sim::io::kitti::scan_order(cloud);
    assert_eq!(order.len(), n);
    let flat = sim::io::kitti::read_bytes(std::path::Path::new("frame.bin"), &bin, None).expect("read");
    let mut points: Vec<Vec3> = flat.point_in_vehicle.clone();
    let mut intensity: Vec<f32> = flat.intensity.clone();
    if shuffle {
        // A fixed permutation (Fisher-Yates with a multiplicative hash).
        for k in (1..n).rev() {
            let j = ((k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 17) as usize % (k + 1);
            points.swap(k, j);
            intensity.swap(k, j);
            order.swap(k, j);
        }
    }
    let labels: Vec<sim::SemanticClass> = order.iter().map(|&c| cloud.label[c]).collect();
    let table = BeamTable::from_pattern(&rig.sensors[0].spec.pattern()).expect("table");
    let attributes = PointAttributes { intensity: Some(&intensity), labels: Some(&labels), time_s: None, rings: None };
    let (ordered, report) =
        order_cloud(&points, &attributes, &table, vehicle_from_sensor, choice, &UnfoldParams::default())
            .expect("order");
    let mut m = method_by_name(method, 0).expect("method");
    let grid_decisions =
        m.classify(&classifier::FrameInput { index: 0, cloud, world_from_vehicle: None }).expect("classify grid");
    let mut m = method_by_name(method, 0).expect("method");
    let bin_decisions = m
        .classify(&classifier::FrameInput { index: 0, cloud: &ordered, world_from_vehicle: None })
        .expect("classify bin");
    let per_point = classifier::ordering::decisions_per_point(&report, &bin_decisions);
    let (mut cg, mut cb) = (Confusion::default(), Confusion::default());
    let (mut true_cell, mut same) = (0usize, 0usize);
    let plane = cloud.rows * cloud.cols;
    for (k, &cell) in order.iter().enumerate() {
        let truth = cloud.ground[cell];
        cg.add(truth, grid_decisions[cell]);
        cb.add(truth, per_point[k] == 1);
        same += usize::from(grid_decisions[cell] == (per_point[k] == 1));
        if report.cell_of_point[k].is_some_and(|c| c as usize % plane == cell % plane) {
            true_cell += 1;
        }
    }
    BinComparison {
        f1_grid: cg.f1(),
        f1_bin: cb.f1(),
        true_cell: true_cell as f64 / n.max(1) as f64,
        same_decision: same as f64 / n.max(1) as f64,
        report,
        points: n,
    }
}

/// Per layout variant: its name, the returns compared and how many decisions differ from the
/// organized bottom-first file's (our layout) on the same points.
#[derive(Clone, Debug)]
pub struct LayoutAgreement {
    /// The variant.
    pub layout: String,
    /// Returns compared.
    pub returns: usize,
    /// Returns whose decision differs from our layout's.
    pub differing: usize,
    /// The ordering report's one-line summary.
    pub summary: String,
}

/// Scans frame 0 of `scene` with `rig` (single-sensor) and writes it as every organized layout
/// (ours; velodyne and ouster in the sensor frame, as the drivers write them; each also read as if
/// it had no `ring` field) and as a `.bin` in scan
/// order and shuffled; each is read back, ordered and classified with `method`, and its decisions
/// per point compared with our organized bottom-first file's.
pub fn layout_agreement(scene: &str, rig: &str, seed: u64, method: &str) -> Vec<LayoutAgreement> {
    use classifier::ordering::{decisions_per_point, order_organized};
    use sim::io::pcd::{PcdLayout, encode_layout, read_bytes_with_info};
    let spec = crate::ScanSpec { scene: scene.to_string(), rig: rig.to_string(), seed, ..crate::ScanSpec::default() };
    let (frames, rig_v) = crate::scan_spec(&spec);
    let cloud = &frames[0].cloud;
    let (rows, cols) = (cloud.rows, cloud.cols);
    let classify = |c: &sim::OrderedCloud| {
        let mut m = method_by_name(method, 0).expect("method");
        m.classify(&classifier::FrameInput { index: 0, cloud: c, world_from_vehicle: None }).expect("classify")
    };
    let path = std::path::Path::new("frame.pcd");
    let vehicle_from_sensor = rig_v.sensors[0].mount.vehicle_from_sensor();
    let sensor_from_vehicle = vehicle_from_sensor.inverse();
    let ours =
        read_bytes_with_info(path, &encode_layout(cloud, PcdLayout::Groundtruth, false, None).unwrap()).unwrap().0;
    let reference = classify(&ours);
    let mut out = Vec::new();
    for layout in [PcdLayout::Groundtruth, PcdLayout::Velodyne, PcdLayout::Ouster] {
        let bytes = encode_layout(cloud, layout, false, Some(&sensor_from_vehicle)).expect("encode");
        let (read, info) = read_bytes_with_info(path, &bytes).expect("read");
        for with_ring in [true, false] {
            if layout == PcdLayout::Groundtruth && !with_ring {
                continue;
            }
            // Our file is taken as it is; the drivers' are reordered as a real file would be.
            let (decisions, summary) = if info.ours {
                let d = classify(&read);
                (d.iter().map(|&g| u8::from(g)).collect::<Vec<u8>>(), "ours: as written".to_string())
            } else {
                let (ordered, report) = order_organized(read.clone(), info.has_ring && with_ring, vehicle_from_sensor)
                    .expect("order organized");
                (decisions_per_point(&report, &classify(&ordered)), report.summary())
            };
            // File cell -> grid cell of the scan.
            let grid_cell = |i: usize| {
                let (k, c) = (i / cols, i % cols);
                if layout == PcdLayout::Ouster { (rows - 1 - k) * cols + c } else { i }
            };
            let (mut returns, mut differing) = (0, 0);
            for (i, &d) in decisions.iter().enumerate().take(rows * cols) {
                let g = grid_cell(i);
                if cloud.has_return(g) {
                    returns += 1;
                    differing += usize::from((d == 1) != reference[g]);
                }
            }
            let name = format!("{}{}", layout.name(), if with_ring { "" } else { " without ring" });
            out.push(LayoutAgreement { layout: name, returns, differing, summary });
        }
    }
    for shuffle in [false, true] {
        let c = compare_bin(scene, rig, seed, method, shuffle, PathChoice::Auto);
        let differing = ((1.0 - c.same_decision) * c.points as f64).round() as usize;
        out.push(LayoutAgreement {
            layout: if shuffle { "bin shuffled".into() } else { "bin scan order".into() },
            returns: c.points,
            differing,
            summary: c.report.summary(),
        });
    }
    out
}
