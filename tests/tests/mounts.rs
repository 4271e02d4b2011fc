//! Property tests on mount changes: wherever a sensor sits on the vehicle, ideal returns from flat
//! ground lie on z = 0 in the vehicle frame, ranges agree with the geometry, and the classifier keeps
//! finding the ground.

use glam::Vec3;
use gt_tests::{LoadedScene, ScanSpec, scan_on};
use proptest::prelude::*;
use sim::rig::{Mount, Rig};
use sim::scene::builtin;

fn vlp16_at(mount: Mount) -> Rig {
    let mut rig = Rig::preset("vlp16-roof").unwrap();
    rig.sensors[0].mount = mount;
    rig
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    #[test]
    fn ground_stays_at_z0_and_is_classified_at_any_mount(
        height in 0.8f32..2.5,
        x in -1.0f32..3.0,
        pitch in -4.0f32..4.0,
        roll in -3.0f32..3.0,
        yaw in -180.0f32..180.0,
    ) {
        let mount = Mount { x_m: x, y_m: 0.0, z_m: height, roll_deg: roll, pitch_deg: pitch, yaw_deg: yaw };
        let rig = vlp16_at(mount);
        let mesh = builtin::flat_objects();
        let frames = scan_on(&LoadedScene::from_mesh(mesh, "flat-objects"), &rig, &ScanSpec { ideal: true, ..ScanSpec::default() });
        let c = &frames[0].cloud;
        let vehicle_from_sensor = mount.vehicle_from_sensor();
        let origin = vehicle_from_sensor.transform_point3(Vec3::ZERO);
        let mut ground = 0;
        for i in 0..c.len() {
            if c.has_return(i) && c.ground[i] {
                ground += 1;
                prop_assert!(c.point_in_vehicle[i].z.abs() < 2e-4, "ground z {}", c.point_in_vehicle[i].z);
                // Range = distance from the beam origin (VLP-16 beams start at the optical centre).
                let d = (c.point_in_vehicle[i] - origin).length();
                prop_assert!((d - c.range_m[i]).abs() < 1e-3, "range {} vs {}", c.range_m[i], d);
            }
        }
        prop_assert!(ground > 5000, "ground returns {ground}");
        let s = gt_tests::classify(frames, "nitsch").eval.pooled.scores();
        prop_assert!(s.f1 >= 0.95, "F1 {} at {mount:?}", s.f1);
    }
}
