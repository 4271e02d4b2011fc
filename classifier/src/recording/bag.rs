//! ROS 2 bags as recordings: which PointCloud2 topic to read (the one there is, or the one named),
//! and the warning of a bag cut short.

use sim::io::ros2::{Bag, Truncation};

use super::RecordingError;

/// The bag's PointCloud2 topics as `NAME (N messages)`.
fn listed(bag: &Bag) -> Result<Vec<String>, RecordingError> {
    Ok(bag.pointcloud_topics()?.iter().map(|t| format!("{} ({} messages)", t.name, t.count)).collect())
}

/// The topic to read: `topic` where given (checked when its messages are read), else the bag's one
/// PointCloud2 topic. Refused, listing the bag's PointCloud2 topics: no topic given and none or
/// several of them.
pub fn resolve_topic(bag: &Bag, topic: Option<&str>) -> Result<String, RecordingError> {
    if let Some(t) = topic {
        return Ok(t.to_string());
    }
    let topics = bag.pointcloud_topics()?;
    match topics.as_slice() {
        [one] => Ok(one.name.clone()),
        [] => Err(RecordingError::Topic(format!(
            "`{}` holds no sensor_msgs/msg/PointCloud2 topic in cdr",
            bag.path.display()
        ))),
        _ => Err(RecordingError::Topic(format!(
            "give --topic; the PointCloud2 topics of `{}`: {}",
            bag.path.display(),
            listed(bag)?.join(", ")
        ))),
    }
}

/// The warning of a bag file cut short, as the reports print it.
pub fn truncation_warning(topic: &str, cut: &Truncation) -> String {
    format!("warning: {cut} of `{topic}`, as `mcap recover` would read it")
}
