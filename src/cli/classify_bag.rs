//! `groundtruth classify --input BAG --topic TOPIC`: the point clouds of a ROS 2 bag (an `.mcap`
//! file or a rosbag2 directory, ours or anyone's) classified message by message.
//!
//! Every `sensor_msgs/msg/PointCloud2` message of the topic takes the path a PCD file takes
//! ([`super::classify::FrameReader::read_pcd_bytes`]): organized or not, the drivers' layouts, `ring`
//! and `time` fields, `--rig` / `--calibration`. Out come `frame_NNNNNN.ground` per message (one
//! byte per point in the message's order, NNNNNN its index on the topic) and `ground_bag/`, a
//! rosbag2 directory with the same messages, each with a `ground` field (`uint8`, 1 = ground)
//! appended to its points. A field rather than Patchwork++'s two topics (ground, non-ground):
//! the cloud stays organized, one message per input message, every point with its decision where
//! it was, and a consumer that wants two clouds splits them on the field. A message that cannot be
//! read (fields that disagree with its data, no `x y z`, ...) is reported with its index and
//! skipped; the others are classified, and the count of skipped ones printed.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, bail};
use classifier::FrameInput;
use classifier::ordering::{SensorSetup, decisions_per_point};
use sim::io::ros2::pointcloud2::{to_pcd, with_ground_field};
use sim::io::ros2::{Bag, BagWriter};

/// Lists the bag's PointCloud2 topics, for a missing `--topic`.
pub fn topics_message(bag: &Bag) -> anyhow::Result<String> {
    let topics = bag.pointcloud_topics()?;
    if topics.is_empty() {
        return Ok(format!("`{}` holds no sensor_msgs/msg/PointCloud2 topic in cdr", bag.path.display()));
    }
    let list: Vec<String> = topics.iter().map(|t| format!("{} ({} messages)", t.name, t.count)).collect();
    Ok(format!("give --topic; the PointCloud2 topics of `{}`: {}", bag.path.display(), list.join(", ")))
}

/// Runs `classify` on a bag.
pub fn run(
    input: &Path,
    topic: Option<&str>,
    out: &Path,
    setup: &SensorSetup,
    method: &mut dyn classifier::GroundClassifier,
) -> anyhow::Result<()> {
    let bag = Bag::open(input)?;
    let Some(topic) = topic else { bail!("{}", topics_message(&bag)?) };
    std::fs::create_dir_all(out).with_context(|| format!("creating `{}`", out.display()))?;
    let mut reader = super::classify::FrameReader::default();
    let mut writer = BagWriter::create(&out.join("ground_bag"))?;
    // The `.ground` files are staged and moved in at the end: a failed run leaves none of them.
    let stage = Staging::create(out)?;
    let (mut good, mut skipped) = (0usize, 0usize);
    let mut fatal: Option<anyhow::Error> = None;
    let messages = bag.for_each_cloud(topic, |m| {
        let name = std::path::PathBuf::from(format!("{}#{topic}[{}]", input.display(), m.index));
        let result = (|| -> anyhow::Result<Option<()>> {
            let pc = match m.decode() {
                Ok(pc) => pc,
                Err(e) => {
                    eprintln!("`{}` {topic} message {}: {e}; skipped", input.display(), m.index);
                    return Ok(None);
                }
            };
            let pcd = match to_pcd(&pc, m.groundtruth_comment.as_deref()) {
                Ok(b) => b,
                Err(e) => {
                    eprintln!("`{}` {topic} message {}: {e}; skipped", input.display(), m.index);
                    return Ok(None);
                }
            };
            if let Err(e) = reader.read_pcd_bytes(&name, &pcd, setup) {
                eprintln!("`{}` {topic} message {}: {e:#}; skipped", input.display(), m.index);
                return Ok(None);
            }
            let (cloud, report) = (reader.cloud(), reader.report());
            let ground = method
                .classify(&FrameInput { index: m.index, cloud, world_from_vehicle: None })
                .with_context(|| format!("classifying {topic} message {}", m.index))?;
            let bytes: Vec<u8> = match report {
                None => ground.iter().map(|&g| u8::from(g)).collect(),
                Some(r) => decisions_per_point(r, &ground),
            };
            let stem = format!("frame_{:06}", m.index);
            stage.write(&format!("{stem}.ground"), &bytes)?;
            let with =
                with_ground_field(&pc, &bytes).map_err(|e| anyhow::anyhow!("{topic} message {}: {e}", m.index))?;
            let metadata: BTreeMap<String, String> = m
                .groundtruth_comment
                .iter()
                .map(|c| (sim::io::ros2::bag::GROUNDTRUTH_KEY.to_string(), c.clone()))
                .collect();
            writer.write_pointcloud(topic, &with, m.log_time_ns, &metadata)?;
            let count = bytes.iter().filter(|&&b| b == 1).count();
            println!("{stem}: {} points, {count} ground", bytes.len());
            Ok(Some(()))
        })();
        match result {
            Ok(Some(())) => good += 1,
            Ok(None) => skipped += 1,
            Err(e) => {
                fatal = Some(e);
                return Err(sim::SimError::invalid("message", m.index, "a message that classifies"));
            }
        }
        Ok(())
    });
    if let Some(e) = fatal {
        return Err(e);
    }
    messages?;
    if good == 0 {
        bail!("no message of `{topic}` in `{}` could be read ({skipped} skipped)", input.display());
    }
    let dir = writer.finish()?;
    stage.commit()?;
    println!("{good} messages of {topic} classified, {skipped} skipped; decisions in {}", dir.display());
    Ok(())
}

/// A hidden directory beside the outputs whose files move into place only on success; dropped
/// before [`Staging::commit`], it is removed with what it holds.
struct Staging {
    dir: std::path::PathBuf,
    out: std::path::PathBuf,
    names: std::cell::RefCell<Vec<String>>,
    committed: bool,
}

impl Staging {
    fn create(out: &Path) -> anyhow::Result<Self> {
        let dir = out.join(format!(".classify.partial-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating `{}`", dir.display()))?;
        Ok(Self { dir, out: out.to_path_buf(), names: Default::default(), committed: false })
    }

    fn write(&self, name: &str, bytes: &[u8]) -> anyhow::Result<()> {
        let path = self.dir.join(name);
        std::fs::write(&path, bytes).with_context(|| format!("writing `{}`", path.display()))?;
        self.names.borrow_mut().push(name.to_string());
        Ok(())
    }

    fn commit(mut self) -> anyhow::Result<()> {
        for name in self.names.borrow().iter() {
            let to = self.out.join(name);
            std::fs::rename(self.dir.join(name), &to).with_context(|| format!("moving into `{}`", to.display()))?;
        }
        self.committed = true;
        std::fs::remove_dir_all(&self.dir).with_context(|| format!("removing `{}`", self.dir.display()))
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}
