//! Why `nitsch` misses ground in a labelled KITTI-layout frame (a diagnostic):
//! `cargo run --release -p groundtruth-classifier --example misses -- FRAME.bin [RIG] [MAX_RANGE_M]`
//! (the `.label` beside it in `../labels/`, or in the same folder). Every missed ground return
//! within MAX_RANGE_M (default 10 m) of the sensor is put in one of three groups: not a candidate
//! (`g_rho` under the threshold; split by the normal's tilt and the normal quality `n_rho`), a
//! candidate in a cluster the rules rejected (with the clusters' sizes and heights), a candidate
//! in a ground cluster (an echo or ordering effect). It prints the counts and the rows of the grid
//! that hold the misses, and draws the outcome near the sensor (`$TMPDIR/misses_STEM.png`).

#![allow(clippy::needless_range_loop)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use classifier::ordering::{CloudBuffer, OrderingReport, SensorSetup};
use classifier::{Nitsch, NitschParams};
use sim::SemanticClass;

fn main() {
    let bin = PathBuf::from(std::env::args().nth(1).expect("usage: misses FRAME.bin [RIG] [MAX_RANGE_M]"));
    let rig = std::env::args().nth(2).filter(|r| r != "-");
    let max_range: f32 = std::env::args().nth(3).map_or(10.0, |s| s.parse().expect("a range in metres"));
    let stem = bin.file_stem().unwrap().to_str().unwrap().to_string();
    let beside = bin.with_extension("label");
    let label =
        if beside.is_file() { beside } else { bin.parent().unwrap().join("../labels").join(format!("{stem}.label")) };
    let records: Vec<[f32; 4]> = std::fs::read(&bin)
        .unwrap()
        .chunks_exact(16)
        .map(|c| std::array::from_fn(|k| f32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap())))
        .collect();
    let labels: Vec<SemanticClass> = std::fs::read(&label)
        .unwrap()
        .chunks_exact(4)
        .map(|c| SemanticClass((u32::from_le_bytes(c.try_into().unwrap()) & 0xFFFF) as u16))
        .collect();
    let rig = rig.map(|r| sim::Rig::load(&r).unwrap());
    let setup = SensorSetup::new(rig.as_ref(), None).unwrap();
    let (mut buffer, mut report) = (CloudBuffer::default(), OrderingReport::default());
    setup.order_kitti(&records, Some(&labels), &mut buffer, &mut report).unwrap();
    let cloud = buffer.cloud();
    let params = NitschParams::default();
    let mut m = Nitsch::new(params).unwrap();
    let g = m.classify(cloud).unwrap();
    println!("{}: {} x {} x {}, {}", Path::new(&bin).display(), cloud.rows, cloud.cols, cloud.planes, report.summary());
    let sensor_from_vehicle = setup.vehicle_from_sensor.inverse();
    let n = cloud.rows * cloud.cols;
    let (mut total, mut not_candidate, mut rejected, mut in_ground) = (0, 0, 0, 0);
    let mut tilt = BTreeMap::<String, usize>::new();
    let mut clusters = BTreeMap::<usize, usize>::new();
    let mut rows = BTreeMap::<usize, (usize, usize)>::new();
    for i in 0..n {
        let p = cloud.point_in_vehicle[i];
        if !p.is_finite() || !cloud.ground[i] {
            continue;
        }
        let r = sensor_from_vehicle.transform_point3(p).length();
        if r > max_range {
            continue;
        }
        let e = rows.entry(i / cloud.cols).or_default();
        e.0 += 1;
        if g[i] {
            continue;
        }
        e.1 += 1;
        total += 1;
        let (gr, nr, nz) = (m.features.g_rho[i], m.features.n_rho[i], m.features.normal[i].z);
        if gr < params.threshold || gr <= 0.0 {
            not_candidate += 1;
            let bucket = format!(
                "n_z {} n_rho {}",
                if nz > 0.97 {
                    ">0.97"
                } else if nz > 0.9 {
                    "0.9-0.97"
                } else if nz > 0.0 {
                    "0-0.9"
                } else {
                    "none"
                },
                if nr > 0.9 {
                    ">0.9"
                } else if nr > 0.6 {
                    "0.6-0.9"
                } else {
                    "<0.6"
                }
            );
            *tilt.entry(bucket).or_default() += 1;
        } else if let Some(root) = m.workspace.cluster_of(i) {
            let (.., ground) = m.workspace.cluster_summary(root);
            if ground {
                in_ground += 1;
            } else {
                rejected += 1;
                *clusters.entry(root).or_default() += 1;
            }
        }
    }
    println!(
        "missed ground within {max_range} m: {total}: not candidates {not_candidate}, in rejected clusters {rejected}, in ground clusters {in_ground}"
    );
    for (k, v) in &tilt {
        println!("  not candidate, {k}: {v}");
    }
    let mut by_size: Vec<_> = clusters.iter().collect();
    by_size.sort_by_key(|(_, v)| std::cmp::Reverse(**v));
    for (root, missed) in by_size.iter().take(8) {
        let (size, inside, h, _) = m.workspace.cluster_summary(**root);
        let p = cloud.point_in_vehicle[**root];
        println!(
            "  rejected cluster {root}: {missed} missed, size {size}, inside the ground area {inside}, mean height above it {h:.2} m, at ({:.1}, {:.1}, {:.2})",
            p.x, p.y, p.z
        );
    }
    let picture = std::env::temp_dir().join(format!("misses_{stem}.png"));
    let opts = sim::picture::BevOptions { size_px: 900, half_extent_m: Some(max_range * 1.2), point_px: 2 };
    let img =
        sim::picture::render_bev(cloud, &sim::picture::Coloring::Outcome { predicted_ground: &g }, &opts).unwrap();
    sim::picture::save_png(&picture, &img).unwrap();
    println!("outcome within {:.0} m: {}", max_range * 1.2, picture.display());
    for (row, (ground, missed)) in &rows {
        if *missed > 0 {
            println!("  row {row}: {ground} ground within range, {missed} missed");
        }
    }
}
