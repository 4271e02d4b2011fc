//! Scanning on the GPU (skipped without an adapter unless `GROUNDTRUTH_REQUIRE_GPU=1`): moving
//! frames cast from beams and poses through the pipeline keep the agreement contract against the
//! CPU reference, and an adapter that disappears mid-run is reported (a fault naming the device)
//! instead of a panic or a silent fallback to the CPU.
#![cfg(feature = "gpu")]

use crate::common;

use common::gpu_caster;
use sim::cast::gpu::GpuOptions;
use sim::cast::{Backend, Caster};
use sim::scan::{Agreement, AgreementContract, ScanConfig, Scanner};

#[test]
fn pipelined_moving_frames_keep_the_contract() {
    let mesh = sim::scene::builtin::builtin("flat-objects").unwrap();
    if gpu_caster(&mesh, GpuOptions::default()).is_none() {
        return;
    }
    for (name, yaw) in [("lux-roof-4", 0.2), ("vlp16-roof", -0.3), ("os1-64-roof", 0.0)] {
        let rig = sim::Rig::preset(name).unwrap();
        let config =
            ScanConfig { seed: 4, frames: 5, speed_m_per_s: 9.0, yaw_rate_rad_per_s: yaw, ..Default::default() };
        let gpu = Scanner::new(&mesh, &rig, ScanConfig { backend: Backend::Gpu, ..config.clone() }).unwrap();
        let cpu = Scanner::new(&mesh, &rig, config).unwrap();
        let quantum = cpu.measurements().iter().map(|m| m.range_quantum_m).fold(0.0, f32::max);
        let mut indices = Vec::new();
        gpu.scan_frames(0..5, |frame| {
            let agreement = Agreement::of(&cpu.frame(frame.index).cloud, &frame.cloud, quantum).unwrap();
            assert!(agreement.both_hit > 500, "{name}: {agreement:?}");
            let checked = AgreementContract::GPU.check(&agreement);
            assert!(checked.is_ok(), "{name} frame {}: {checked:?}", frame.index);
            indices.push(frame.index);
            Ok::<(), ()>(())
        })
        .unwrap();
        assert_eq!(indices, [0, 1, 2, 3, 4]);
        let stats = gpu.caster().device_stats().unwrap();
        // Beams up once, then poses only (48 B per shot time): under half the 32 B per ray of
        // rays made on the host, even for the LUX whose 4 layers share a shot time.
        assert!(stats.upload_bytes < 16 * stats.rays, "{name}: {stats:?}");
        assert_eq!(gpu.caster().fault(), None);
    }
}

#[test]
fn a_lost_device_is_reported_not_replaced_by_the_cpu() {
    let mesh = sim::scene::builtin::builtin("flat-objects").unwrap();
    let Some(gpu) = gpu_caster(&mesh, GpuOptions::default()) else { return };
    let ray = sim::cast::Ray { origin: glam::Vec3::new(0.0, 0.0, 2.0), dir: -glam::Vec3::Z, t_max: 100.0 };
    let before = gpu.cast_all(&[ray; 64]);
    assert!(before.iter().all(|h| h.is_some_and(|h| (h.t - 2.0).abs() < 0.05)), "{:?}", before[0]);
    assert_eq!(gpu.fault(), None);
    gpu.destroy_device();
    let after = gpu.cast_all(&[ray; 64]);
    let fault = gpu.fault().expect("a fault after the device is gone");
    assert!(fault.contains(gpu.adapter().split(" (").next().unwrap()), "{fault}");
    eprintln!("{fault}");
    assert!(fault.contains("lost") || fault.contains("failed") || fault.contains("error"), "{fault}");
    // No silent CPU fallback: nothing was cast on the CPU in its place.
    assert_eq!(gpu.cpu_fallbacks(), 0);
    assert_eq!(after.len(), 64);
}
