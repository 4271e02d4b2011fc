//! The target of ring recovery on our own scans: each spinning roof sensor's `rural` frames written
//! as ring-less KITTI `.bin` (sensor frame, ring-major order) and classified by `method` (default
//! `learned`) without a rig (the sensor recovered from the data) and with its rig (`--rig`): pooled
//! F1 of both, the sensor named, and the ordering's milliseconds per point.
//!
//! `cargo run --profile quick -p gt-tests --example rings_targets [-- SEED FRAMES METHOD RIG...]`

use std::time::Instant;

use classifier::ordering::{CloudBuffer, OrderingReport, SensorSetup};
use classifier::{Confusion, FrameInput, method_by_name};
use gt_tests::{ScanSpec, scan_spec};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seed: u64 = args.first().and_then(|s| s.parse().ok()).unwrap_or(31337);
    let frames: u64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2);
    let method = args.get(2).cloned().unwrap_or_else(|| "learned".into());
    let rigs: Vec<String> = if args.len() > 3 {
        args[3..].to_vec()
    } else {
        ["vlp16-roof", "os1-64-roof", "os1-128-roof", "hdl64e-roof", "hdl32e-roof", "vlp32c-roof", "pandar64-roof"]
            .map(String::from)
            .to_vec()
    };
    println!("rig points f1_without_rig f1_with_rig d_f1 sensor order_ms_per_kpoint_without order_ms_per_kpoint_with");
    for rig_name in &rigs {
        let spec = ScanSpec {
            scene: "rural".into(),
            rig: rig_name.clone(),
            seed,
            frames,
            speed_m_per_s: 5.0,
            ..ScanSpec::default()
        };
        let (scanned, rig) = scan_spec(&spec);
        let with_rig = SensorSetup::new(Some(&rig), None).expect("rig setup");
        let without = SensorSetup::default();
        let sensor_from_vehicle = rig.sensors[0].mount.vehicle_from_sensor().inverse();
        let (mut c_without, mut c_with) = (Confusion::default(), Confusion::default());
        let (mut ms_without, mut ms_with, mut points, mut named) = (0.0, 0.0, 0usize, String::new());
        for f in &scanned {
            let order = sim::io::kitti::scan_order(&f.cloud);
            let (bin, _, n) = sim::io::kitti::encode(&f.cloud, Some(&sensor_from_vehicle)).expect("encode");
            let pts = sim::io::kitti::points_from_bytes(std::path::Path::new("f.bin"), &bin, None).expect("read");
            let records: Vec<[f32; 4]> =
                pts.points.iter().zip(&pts.intensity).map(|(p, &i)| [p.x, p.y, p.z, i]).collect();
            points += n;
            for (setup, confusion, ms) in
                [(&without, &mut c_without, &mut ms_without), (&with_rig, &mut c_with, &mut ms_with)]
            {
                let (mut cloud, mut report) = (CloudBuffer::default(), OrderingReport::default());
                let t0 = Instant::now();
                setup.order_kitti(&records, None, &mut cloud, &mut report).expect("order");
                *ms += t0.elapsed().as_secs_f64() * 1e3;
                if let Some(s) = &report.sensor {
                    named = s.summary();
                }
                let mut m = method_by_name(&method, 0).expect("method");
                let ground = m
                    .classify(&FrameInput { index: 0, cloud: cloud.cloud(), world_from_vehicle: None })
                    .expect("classify");
                let per_point = classifier::ordering::decisions_per_point(&report, &ground);
                for (k, &cell) in order.iter().enumerate() {
                    confusion.add(f.cloud.ground[cell], per_point[k] == 1);
                }
            }
        }
        let (a, b) = (c_without.f1(), c_with.f1());
        println!(
            "{rig_name} {points} {a:.4} {b:.4} {:.4} [{named}] {:.4} {:.4}",
            (a - b).abs(),
            ms_without / points as f64 * 1e3,
            ms_with / points as f64 * 1e3
        );
    }
}
