//! ROS 2 without ROS: scans and decisions as rosbag2 directories (one MCAP file, `cdr` messages),
//! and the point clouds of anyone's bag read back ([`bag`]); `sensor_msgs/msg/PointCloud2`,
//! `tf2_msgs/msg/TFMessage` and their CDR encoding ([`messages`]); clouds between our PCD layouts
//! and PointCloud2 ([`pointcloud2`]).

pub mod bag;
pub mod messages;
pub mod pointcloud2;
pub mod scan;
pub mod stream;

pub use bag::{Bag, BagCloud, BagClouds, BagCompression, BagWriter, TopicInfo, Truncation, is_bag};
pub use messages::PointCloud2;
