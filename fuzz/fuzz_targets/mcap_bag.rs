//! Fuzz target: a ROS 2 bag (an `.mcap` file) opened, its topics listed and every PointCloud2
//! message of each topic decoded (the reader reads from a path: the input is written to a file of
//! this process first).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("groundtruth-fuzz-{}.mcap", std::process::id()));
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
