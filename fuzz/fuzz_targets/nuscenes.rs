//! Fuzz target: the nuScenes `.pcd.bin` reader, the test that tells its layout from KITTI's and the
//! lidarseg label reader; the first byte picks where the input splits into the sweep and its labels.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&k, rest)) = data.split_first() else { return };
    let split = (rest.len() * usize::from(k) / 255).min(rest.len());
    let (bin, labels) = rest.split_at(split);
    let path = std::path::Path::new("fuzz.pcd.bin");
    let _ = sim::io::nuscenes::content_layout(path, bin);
    let mut points = sim::io::nuscenes::NuscenesPoints::default();
    if sim::io::nuscenes::points_from_bytes_into(path, bin, &mut points).is_ok() {
        let n = points.points.len();
        assert_eq!((points.intensity.len(), points.rings.len()), (n, n));
        let _ = sim::io::nuscenes::lidarseg_from_bytes(std::path::Path::new("fuzz_lidarseg.bin"), labels, path, n);
    }
    let _ = sim::io::nuscenes::cloud_from_bytes(path, rest);
});
