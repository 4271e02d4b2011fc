//! Fuzz target: a ROS 2 bag (an `.mcap` file) opened, its topics listed and every PointCloud2
//! message of each topic decoded (the reader maps a file: the input is written to a file of this
//! process first, in `/dev/shm` where there is one: on a disk, ext4 writes back a truncated file on
//! every close, which held the target to about 2.6 k executions/s).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let shm = std::path::Path::new("/dev/shm");
    let dir = if shm.is_dir() { shm.to_path_buf() } else { std::env::temp_dir() };
    let path = dir.join(format!("groundtruth-fuzz-{}.mcap", std::process::id()));
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let Ok(bag) = sim::io::ros2::Bag::open(&path) else { return };
    let Ok(topics) = bag.topics() else { return };
    for t in topics {
        let Ok(clouds) = bag.clouds(&t.name) else { continue };
        for message in clouds.take(64) {
            if let Ok(m) = message
                && let Ok(cloud) = m.decode()
            {
                let _ = sim::io::ros2::pointcloud2::frame(&path, &cloud, m.groundtruth_comment.as_deref());
            }
        }
    }
});
