//! `groundtruth classify --input BAG [--topic TOPIC]`: the point clouds of a ROS 2 bag (an `.mcap`
//! file or a rosbag2 directory, ours or anyone's) classified message by message; without
//! `--topic`, the bag's one PointCloud2 topic.
//!
//! Every `sensor_msgs/msg/PointCloud2` message of the topic takes the path a PCD file takes
//! ([`classifier::recording`]): organized or not, the drivers' layouts, `ring` and `time` fields,
//! `--rig` / `--calibration`. A bag cut short (a recorder killed mid-write) is read up to its last
//! whole message, with a warning naming the last message read (on stderr and after the summary). Out come `frame_NNNNNN.ground` per message (one
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
use classifier::ordering::SensorSetup;
use classifier::recording::{Ordering, Recording};
use sim::io::ros2::BagWriter;
use sim::io::ros2::pointcloud2::with_ground_field;

/// Runs `classify` on a bag's topic (`recording` is a bag).
pub fn run(
    recording: &Recording,
    out: &Path,
    setup: &SensorSetup,
    method: &mut dyn classifier::GroundClassifier,
) -> anyhow::Result<()> {
    let topic = recording.topic().unwrap_or_default();
    // The ground bag is zstd-compressed: a build without the compression says so before reading.
    sim::io::ros2::BagCompression::default().check_built()?;
    // The topic is checked (and its messages start coming) before anything is written.
    let mut frames = recording.frames(Ordering::Ordered(setup))?;
    std::fs::create_dir_all(out).with_context(|| format!("creating `{}`", out.display()))?;
    let mut writer = BagWriter::create(&out.join("ground_bag"))?;
    // The `.ground` files are staged and moved in at the end: a failed run leaves none of them.
    let stage = Staging::create(out)?;
    let (mut good, mut skipped) = (0usize, 0usize);
    while let Some(frame) = frames.next_frame() {
        let frame = match frame {
            Ok(f) => f,
            Err(e) if e.is_message() => {
                eprintln!("{e}; skipped");
                skipped += 1;
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        let Some(m) = frame.message else { bail!("{}: a bag's frame without its message", frame.provenance) };
        let ground = method
            .classify(&FrameInput { index: m.index, cloud: frame.cloud, world_from_vehicle: None })
            .with_context(|| format!("classifying {topic} message {}", m.index))?;
        let bytes = frame.decisions_per_point(&ground);
        let stem = format!("frame_{:06}", m.index);
        stage.write(&format!("{stem}.ground"), &bytes)?;
        let pc = m.decode().map_err(|e| anyhow::anyhow!("{topic} message {}: {e}", m.index))?;
        let with = with_ground_field(&pc, &bytes).map_err(|e| anyhow::anyhow!("{topic} message {}: {e}", m.index))?;
        let metadata: BTreeMap<String, String> = m
            .groundtruth_comment
            .iter()
            .map(|c| (sim::io::ros2::bag::GROUNDTRUTH_KEY.to_string(), c.clone()))
            .collect();
        writer.write_pointcloud(topic, &with, m.log_time_ns, &metadata)?;
        let count = bytes.iter().filter(|&&b| b == 1).count();
        println!("{stem}: {} points, {count} ground", bytes.len());
        good += 1;
    }
    for w in frames.warnings() {
        eprintln!("{w}");
    }
    if good == 0 {
        bail!("no message of `{topic}` in `{}` could be read ({skipped} skipped)", recording.path().display());
    }
    let dir = writer.finish()?;
    stage.commit()?;
    println!("{good} messages of {topic} classified, {skipped} skipped; decisions in {}", dir.display());
    for w in frames.warnings() {
        println!("{w}");
    }
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
