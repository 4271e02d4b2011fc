//! A scan as ROS 2 messages: per frame and sensor one `sensor_msgs/msg/PointCloud2` on
//! `/SENSOR/points` (in a driver's layout, points in the sensor's frame `SENSOR`; or our layout with
//! every field, points in the vehicle frame `base_link`), `/tf_static` with every
//! `vehicle_from_sensor` (`base_link` -> `SENSOR`) and `/tf` with the vehicle's pose at each
//! frame's start (`map` -> `base_link`). Stamps are the scan's own times (seconds from its start).

use std::collections::BTreeMap;

use glam::{Affine3A, DAffine3};

use super::bag::{BagWriter, GROUNDTRUTH_KEY};
use super::messages::{Header, TfMessage, Time, Transform, TransformStamped};
use super::pointcloud2::{from_pcd, groundtruth_comment};
use crate::OrderedCloud;
use crate::error::{Result, SimError};
use crate::io::pcd::{PcdLayout, encode_layout};

/// The frame id of the vehicle.
pub const VEHICLE_FRAME: &str = "base_link";
/// The frame id of the world.
pub const WORLD_FRAME: &str = "map";

/// A sensor of the rig as the bag names it.
#[derive(Clone, Debug)]
pub struct SensorTopic {
    /// The sensor's name (its frame id).
    pub name: String,
    /// Its cloud topic, `/NAME/points`.
    pub topic: String,
    /// Its mount.
    pub vehicle_from_sensor: Affine3A,
}

/// The sensors of a rig as topics.
pub fn sensor_topics(rig: &crate::Rig) -> Vec<SensorTopic> {
    rig.sensors
        .iter()
        .map(|s| SensorTopic {
            name: s.name.clone(),
            topic: format!("/{}/points", s.name),
            vehicle_from_sensor: s.mount.vehicle_from_sensor(),
        })
        .collect()
}

fn daffine(t: &Affine3A) -> DAffine3 {
    DAffine3::from_mat4(glam::Mat4::from(*t).as_dmat4())
}

/// The rows of `cloud` that belong to sensor `sensor` (a row is one sensor's ring, every plane
/// kept), as a cloud of their own; the whole cloud where one sensor covers every row.
fn sensor_rows(cloud: &OrderedCloud, sensor: u8) -> std::borrow::Cow<'_, OrderedCloud> {
    let (rows, cols) = (cloud.rows, cloud.cols);
    let owner = |r: usize| cloud.sensor[r * cols..(r + 1) * cols].iter().copied().find(|&s| s != u8::MAX);
    let mine: Vec<usize> = (0..rows).filter(|&r| owner(r) == Some(sensor)).collect();
    if mine.len() == rows {
        return std::borrow::Cow::Borrowed(cloud);
    }
    let mut out = OrderedCloud::empty(mine.len(), cols, cloud.planes);
    for plane in 0..cloud.planes {
        for (k, &r) in mine.iter().enumerate() {
            for c in 0..cols {
                let (from, to) = (cloud.index(plane, r, c), out.index(plane, k, c));
                out.point_in_vehicle[to] = cloud.point_in_vehicle[from];
                out.range_m[to] = cloud.range_m[from];
                out.intensity[to] = cloud.intensity[from];
                out.ring[to] = cloud.ring[from];
                out.column[to] = cloud.column[from];
                out.sensor[to] = cloud.sensor[from];
                out.time_s[to] = cloud.time_s[from];
                out.echo[to] = cloud.echo[from];
                out.label[to] = cloud.label[from];
                out.instance[to] = cloud.instance[from];
                out.ground[to] = cloud.ground[from];
                out.normal[to] = cloud.normal[from];
            }
        }
    }
    std::borrow::Cow::Owned(out)
}

/// Writes one frame: every sensor's cloud in `layout` stamped `start_s` (the frame's start, seconds),
/// and the vehicle's pose on `/tf`. Returns per sensor its topic and point count (width x height).
pub fn write_frame(
    bag: &mut BagWriter,
    cloud: &OrderedCloud,
    sensors: &[SensorTopic],
    layout: PcdLayout,
    start_s: f64,
    world_from_vehicle: &Affine3A,
) -> Result<Vec<(String, usize)>> {
    let stamp = Time::from_seconds(start_s);
    let mut out = Vec::with_capacity(sensors.len());
    for (s, sensor) in sensors.iter().enumerate() {
        let rows = sensor_rows(cloud, s as u8);
        let (sensor_from_vehicle, frame_id) = match layout {
            PcdLayout::Groundtruth => (None, VEHICLE_FRAME.to_string()),
            _ => (Some(sensor.vehicle_from_sensor.inverse()), sensor.name.clone()),
        };
        let pcd = encode_layout(&rows, layout, false, sensor_from_vehicle.as_ref())?;
        let header = Header { stamp, frame_id };
        let msg = from_pcd(&pcd, header).map_err(|e| SimError::invalid("cloud", e, "an organized cloud"))?;
        let metadata: BTreeMap<String, String> =
            groundtruth_comment(&pcd).map(|c| (GROUNDTRUTH_KEY.to_string(), c)).into_iter().collect();
        bag.write_pointcloud(&sensor.topic, &msg, stamp.nanoseconds(), &metadata)?;
        out.push((sensor.topic.clone(), (msg.width * msg.height) as usize));
    }
    let pose = TfMessage {
        transforms: vec![TransformStamped {
            header: Header { stamp, frame_id: WORLD_FRAME.to_string() },
            child_frame_id: VEHICLE_FRAME.to_string(),
            transform: Transform::of(&daffine(world_from_vehicle)),
        }],
    };
    bag.write_tf(&pose, false, stamp.nanoseconds())?;
    Ok(out)
}

/// Writes `/tf_static`: every sensor's mount, stamped at 0.
pub fn write_static(bag: &mut BagWriter, sensors: &[SensorTopic]) -> Result<()> {
    let transforms = sensors
        .iter()
        .map(|s| TransformStamped {
            header: Header { stamp: Time::default(), frame_id: VEHICLE_FRAME.to_string() },
            child_frame_id: s.name.clone(),
            transform: Transform::of(&daffine(&s.vehicle_from_sensor)),
        })
        .collect();
    bag.write_tf(&TfMessage { transforms }, true, 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::ros2::Bag;

    /// Two ideal frames of the four-sensor LUX rig on `flat`, at 5 m/s.
    fn two_lux_frames() -> (crate::Rig, Vec<crate::scan::Frame>) {
        let mesh = crate::scene::builtin::flat();
        let rig = crate::Rig::load("lux-roof-4").unwrap();
        let config = crate::scan::ScanConfig { frames: 2, ideal: true, speed_m_per_s: 5.0, ..Default::default() };
        let frames = crate::scan::scan(&mesh, &rig, &config).unwrap();
        (rig, frames)
    }

    #[test]
    #[cfg_attr(not(feature = "bag-compression"), ignore = "zstd bags need the `bag-compression` feature")]
    fn a_scan_becomes_a_bag_with_one_cloud_per_frame_and_sensor() {
        let (rig, frames) = two_lux_frames();
        let dir = tempfile::tempdir().unwrap();
        let sensors = sensor_topics(&rig);
        for layout in [PcdLayout::Groundtruth, PcdLayout::Velodyne] {
            let path = dir.path().join(layout.name());
            let mut bag = BagWriter::create(&path).unwrap();
            write_static(&mut bag, &sensors).unwrap();
            let mut points = 0;
            for f in &frames {
                let written =
                    write_frame(&mut bag, &f.cloud, &sensors, layout, f.start_time_s, &f.world_from_vehicle).unwrap();
                assert_eq!(written.len(), 4);
                // The four sensors' rows make the whole grid.
                points += written.iter().map(|w| w.1).sum::<usize>();
            }
            bag.finish().unwrap();
            let b = Bag::open(&path).unwrap();
            let topics = b.topics().unwrap();
            assert_eq!(topics.len(), 6, "4 clouds, /tf, /tf_static");
            let clouds: u64 = b.pointcloud_topics().unwrap().iter().map(|t| t.count).sum();
            assert_eq!(clouds, 8);
            let planes = if layout == PcdLayout::Groundtruth { frames[0].cloud.planes } else { 1 };
            assert_eq!(points, 2 * frames[0].cloud.rows * frames[0].cloud.cols * planes);
        }
    }

    /// The default compression (zstd level -5) and none give the same messages: the same CDR
    /// bytes at the same times, what an uncompressed scan writes; the zstd file is the smaller.
    #[test]
    #[cfg_attr(not(feature = "bag-compression"), ignore = "zstd bags need the `bag-compression` feature")]
    fn compressed_and_uncompressed_bags_hold_the_same_messages() {
        let (rig, frames) = two_lux_frames();
        let dir = tempfile::tempdir().unwrap();
        let sensors = sensor_topics(&rig);
        let write = |name: &str, compression| {
            let path = dir.path().join(name);
            let mut bag = BagWriter::create_with(&path, compression).unwrap();
            write_static(&mut bag, &sensors).unwrap();
            for f in &frames {
                write_frame(&mut bag, &f.cloud, &sensors, PcdLayout::Velodyne, f.start_time_s, &f.world_from_vehicle)
                    .unwrap();
            }
            bag.finish().unwrap();
            let b = Bag::open(&path).unwrap();
            let messages: Vec<(String, u64, Vec<u8>)> = sensors
                .iter()
                .flat_map(|s| {
                    b.clouds(&s.topic).unwrap().map(|c| {
                        let c = c.unwrap();
                        (s.topic.clone(), c.log_time_ns, c.cdr)
                    })
                })
                .collect();
            (messages, std::fs::metadata(path.join(format!("{name}_0.mcap"))).unwrap().len())
        };
        let (zstd, zstd_bytes) = write("zstd", crate::io::ros2::BagCompression::Zstd);
        let (none, none_bytes) = write("none", crate::io::ros2::BagCompression::None);
        assert_eq!(zstd.len(), 8, "2 frames x 4 sensors");
        assert!(zstd == none, "the decoded messages differ between zstd and uncompressed bags");
        assert!(zstd_bytes < none_bytes, "zstd {zstd_bytes} bytes, uncompressed {none_bytes}");
        // Each message is the cloud's PCD body behind its PointCloud2 header, as written.
        let rows = super::sensor_rows(&frames[0].cloud, 0);
        let from = sensors[0].vehicle_from_sensor.inverse();
        let pcd = encode_layout(&rows, PcdLayout::Velodyne, false, Some(&from)).unwrap();
        let header = Header { stamp: Time::from_seconds(frames[0].start_time_s), frame_id: sensors[0].name.clone() };
        let msg = from_pcd(&pcd, header).unwrap();
        let expected = crate::io::ros2::messages::to_cdr(&msg, msg.data.len()).unwrap();
        assert!(zstd[0].2 == expected, "the first cloud's CDR bytes differ from its PCD's");
    }
}
