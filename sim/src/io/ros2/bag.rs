//! rosbag2 directories with one MCAP file, written as `ros2 bag record -s mcap
//! --storage-preset-profile zstd_fast` writes them and read from theirs and anyone else's: `metadata.yaml` beside `NAME_0.mcap`, messages in ROS 2
//! `cdr`, schemas as `ros2msg` text, the MCAP chunked (768 KiB) and compressed with zstd level -5
//! (rosbag2's `zstd_fast` preset, libmcap's `Fastest`; or uncompressed, [`BagCompression::None`]),
//! topics with their QoS profiles (`/tf_static` transient local).
//!
//! The container is the `mcap` crate (Foxglove's maintained Rust implementation); messages are
//! encoded by `cdr-encoding` ([`super::messages`]). The MCAP writer runs on a thread of its own
//! (the caller encodes the next frame while it compresses this one) and compresses in that one
//! thread, in the caller's order, so the same scan gives the same bytes on any machine. A bag is written into a temporary directory
//! beside its final one and renamed into place when complete: a failed run leaves no half-written
//! bag.

use std::collections::BTreeMap;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::messages::{
    POINTCLOUD2, PointCloud2, TF_MESSAGE, TfMessage, from_cdr, pointcloud2_definition, tf_message_definition, to_cdr,
};
use super::stream::Messages;
use crate::error::{Result, SimError};

/// QoS of an ordinary topic (reliable, volatile), as rosbag2 records it.
const QOS_VOLATILE: &str = "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 9223372036\n    nsec: 854775807\n  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n  avoid_ros_namespace_conventions: false";
/// QoS of `/tf_static` (reliable, transient local: late joiners get the transforms).
const QOS_TRANSIENT_LOCAL: &str = "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 1\n  deadline:\n    sec: 9223372036\n    nsec: 854775807\n  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n  avoid_ros_namespace_conventions: false";

/// Channel metadata key of our own layout's `# groundtruth` PCD line (so our clouds read back as
/// ours); other tools ignore it.
pub const GROUNDTRUTH_KEY: &str = "groundtruth_pcd_comment";

fn bag_error(path: &Path, e: impl std::fmt::Display) -> SimError {
    SimError::bad_file(path, e.to_string())
}

/// Per topic: type, message count, and the channel id.
#[derive(Clone, Debug)]
struct TopicCount {
    ty: &'static str,
    qos: &'static str,
    count: u64,
    channel: u16,
}

/// libmcap's `CompressionLevel::Fastest` for zstd, the level of rosbag2's `zstd_fast` preset.
pub const ZSTD_FASTEST: i32 = -5;

/// Why a build without the cargo feature `bag-compression` reads and writes only uncompressed bag
/// chunks, and how to get zstd and LZ4 (the C libraries are ~60 s of CPU in a first build).
pub const COMPRESSION_NOT_BUILT: &str = "not in this build (cargo feature `bag-compression`: `cargo install --path . --features full`, or `--features bag-compression`)";

/// How a bag's chunks are compressed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BagCompression {
    /// zstd at libmcap's `Fastest` level ([`ZSTD_FASTEST`], zstd level -5), as `ros2 bag record
    /// -s mcap --storage-preset-profile zstd_fast` writes.
    #[default]
    Zstd,
    /// Chunks stored uncompressed (rosbag2's `fastwrite` spirit): larger files, no compression
    /// work.
    None,
}

impl BagCompression {
    /// The names `--bag-compression` takes.
    pub const NAMES: [&'static str; 2] = ["zstd", "none"];

    /// Parses `zstd` or `none`.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "zstd" => Ok(Self::Zstd),
            "none" => Ok(Self::None),
            other => Err(SimError::invalid("bag compression", other, "zstd or none")),
        }
    }

    /// `self`, or an error naming the cargo feature where this build cannot write it (zstd
    /// without `bag-compression`).
    pub fn check_built(self) -> Result<Self> {
        match self {
            #[cfg(not(feature = "bag-compression"))]
            Self::Zstd => {
                Err(SimError::invalid("bag compression", "zstd", format!("none: zstd is {COMPRESSION_NOT_BUILT}")))
            }
            other => Ok(other),
        }
    }
}

/// What the writer thread is asked to do; ids are the caller's (0, 1, ... in order of
/// registration), mapped to the MCAP writer's on the thread.
enum Command {
    Schema { name: &'static str, text: String },
    Channel { schema: usize, topic: String, metadata: BTreeMap<String, String> },
    Message { channel: usize, sequence: u32, time_ns: u64, data: Vec<u8> },
}

type McapWriter = mcap::Writer<BufWriter<std::fs::File>>;

/// Runs the MCAP writer (chunking, compression, the file's writes) on its own thread, so that a
/// scan casts the next frame while this one is compressed; the order of the commands, and so the
/// bytes, are the caller's.
struct Worker {
    sender: Option<std::sync::mpsc::SyncSender<Command>>,
    handle: Option<std::thread::JoinHandle<std::result::Result<McapWriter, String>>>,
}

impl Worker {
    fn spawn(mut writer: McapWriter) -> Self {
        // Two frames in flight at most: memory stays bounded on long bags.
        let (sender, receiver) = std::sync::mpsc::sync_channel::<Command>(4);
        let handle = std::thread::spawn(move || {
            let (mut schemas, mut channels) = (Vec::new(), Vec::new());
            for command in receiver {
                match command {
                    Command::Schema { name, text } => {
                        schemas.push(writer.add_schema(name, "ros2msg", text.as_bytes()).map_err(|e| e.to_string())?)
                    }
                    Command::Channel { schema, topic, metadata } => channels.push(
                        writer.add_channel(schemas[schema], &topic, "cdr", &metadata).map_err(|e| e.to_string())?,
                    ),
                    Command::Message { channel, sequence, time_ns, data } => {
                        let header = mcap::records::MessageHeader {
                            channel_id: channels[channel],
                            sequence,
                            log_time: time_ns,
                            publish_time: time_ns,
                        };
                        writer.write_to_known_channel(&header, &data).map_err(|e| e.to_string())?;
                    }
                }
            }
            Ok(writer)
        });
        Self { sender: Some(sender), handle: Some(handle) }
    }

    /// Sends a command; if the thread has stopped on an error, that error.
    fn send(&mut self, command: Command) -> std::result::Result<(), String> {
        let failed = self.sender.as_ref().is_none_or(|s| s.send(command).is_err());
        if failed {
            return Err(self.join().err().unwrap_or_else(|| "the bag writer stopped".to_string()));
        }
        Ok(())
    }

    /// Closes the queue and waits for the thread: the writer, or the thread's error.
    fn join(&mut self) -> std::result::Result<McapWriter, String> {
        self.sender = None;
        match self.handle.take() {
            Some(h) => h.join().map_err(|_| "the bag writer thread panicked".to_string())?,
            None => Err("the bag writer stopped".to_string()),
        }
    }
}

/// Writes a rosbag2 directory (see the module docs).
pub struct BagWriter {
    dir: PathBuf,
    staging: PathBuf,
    file_name: String,
    worker: Worker,
    schemas: BTreeMap<&'static str, usize>,
    topics: BTreeMap<String, TopicCount>,
    channels: usize,
    times_ns: Option<(u64, u64)>,
    sequence: u32,
}

impl BagWriter {
    /// Starts a bag that will be the directory `dir` (replaced if it exists) once
    /// [`BagWriter::finish`] succeeds, compressed with zstd as `ros2 bag record -s mcap` does.
    pub fn create(dir: &Path) -> Result<Self> {
        Self::create_with(dir, BagCompression::Zstd)
    }

    /// [`BagWriter::create`] with a choice of chunk compression.
    pub fn create_with(dir: &Path, compression: BagCompression) -> Result<Self> {
        let compression = compression.check_built()?;
        let name = dir.file_name().and_then(|n| n.to_str()).filter(|n| !n.is_empty()).unwrap_or("bag").to_string();
        let parent = dir.parent().map(Path::to_path_buf).unwrap_or_default();
        std::fs::create_dir_all(if parent.as_os_str().is_empty() { Path::new(".") } else { &parent })
            .map_err(|e| bag_error(dir, e))?;
        let staging = parent.join(format!(".{name}.partial-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&staging);
        std::fs::create_dir_all(&staging).map_err(|e| bag_error(&staging, e))?;
        let file_name = format!("{name}_0.mcap");
        let file = std::fs::File::create(staging.join(&file_name)).map_err(|e| bag_error(&staging, e))?;
        let options = mcap::WriteOptions::new()
            .profile("ros2")
            .library("groundtruth")
            .compression(match compression {
                #[cfg(feature = "bag-compression")]
                BagCompression::Zstd => Some(mcap::Compression::Zstd),
                #[cfg(not(feature = "bag-compression"))]
                BagCompression::Zstd => None,
                BagCompression::None => None,
            })
            .chunk_size(Some(768 * 1024))
            // libmcap's default (`enableDataCRC = false`), which rosbag2 keeps: no CRC over the
            // whole data section (the crate's default computes one).
            .calculate_data_section_crc(false);
        // rosbag2's `zstd_fast` preset (`ros2 bag record -s mcap --storage-preset-profile
        // zstd_fast`): zstd at libmcap's `Fastest` level, zstd level -5 (the mcap crate
        // takes the level as a u32 and casts it back to i32, so -5 travels as its two's
        // complement), and no chunk CRCs (`noChunkCRC = true`; a zero CRC tells readers not
        // to check). Measured on 100 city frames (docs/ros2.md): half the compression
        // work of level 1 for files 1.42x larger, still smaller than the KITTI files of the
        // same scan. Chunks of 768 KiB (libmcap's default). One compression thread: the bytes
        // do not depend on the machine.
        #[cfg(feature = "bag-compression")]
        let options = match compression {
            BagCompression::Zstd => {
                options.compression_level(ZSTD_FASTEST as u32).compression_threads(0).calculate_chunk_crcs(false)
            }
            BagCompression::None => options.compression_threads(0),
        };
        let writer = options.create(BufWriter::with_capacity(1 << 20, file)).map_err(|e| bag_error(dir, e))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            staging,
            file_name,
            worker: Worker::spawn(writer),
            schemas: BTreeMap::new(),
            topics: BTreeMap::new(),
            channels: 0,
            times_ns: None,
            sequence: 0,
        })
    }

    fn send(&mut self, command: Command) -> Result<()> {
        let dir = self.dir.clone();
        self.worker.send(command).map_err(|e| bag_error(&dir, e))
    }

    fn channel(&mut self, topic: &str, ty: &'static str, extra: &BTreeMap<String, String>) -> Result<usize> {
        if let Some(t) = self.topics.get(topic) {
            return Ok(t.channel as usize);
        }
        let schema = match self.schemas.get(ty) {
            Some(&id) => id,
            None => {
                let text = if ty == POINTCLOUD2 { pointcloud2_definition() } else { tf_message_definition() };
                let id = self.schemas.len();
                self.send(Command::Schema { name: ty, text: text.to_string() })?;
                self.schemas.insert(ty, id);
                id
            }
        };
        let qos = if topic == "/tf_static" { QOS_TRANSIENT_LOCAL } else { QOS_VOLATILE };
        let mut metadata = extra.clone();
        metadata.insert("offered_qos_profiles".to_string(), qos.to_string());
        let channel = self.channels;
        self.send(Command::Channel { schema, topic: topic.to_string(), metadata })?;
        self.channels += 1;
        let id = u16::try_from(channel).map_err(|_| bag_error(&self.dir, "more than 65535 topics"))?;
        self.topics.insert(topic.to_string(), TopicCount { ty, qos, count: 0, channel: id });
        Ok(channel)
    }

    fn write(&mut self, channel: usize, topic: &str, time_ns: u64, data: Vec<u8>) -> Result<()> {
        let sequence = self.sequence;
        self.sequence += 1;
        self.send(Command::Message { channel, sequence, time_ns, data })?;
        if let Some(t) = self.topics.get_mut(topic) {
            t.count += 1;
        }
        self.times_ns = Some(match self.times_ns {
            None => (time_ns, time_ns),
            Some((a, b)) => (a.min(time_ns), b.max(time_ns)),
        });
        Ok(())
    }

    /// Writes a point cloud on `topic` at `time_ns` (the log time; the message's own stamp is its
    /// header's). `metadata`: extra channel metadata (e.g. [`GROUNDTRUTH_KEY`]), used when the
    /// topic's channel is made.
    pub fn write_pointcloud(
        &mut self,
        topic: &str,
        cloud: &PointCloud2<'_>,
        time_ns: u64,
        metadata: &BTreeMap<String, String>,
    ) -> Result<()> {
        let channel = self.channel(topic, POINTCLOUD2, metadata)?;
        let bytes = to_cdr(cloud, cloud.data.len()).map_err(|e| bag_error(&self.dir, e))?;
        self.write(channel, topic, time_ns, bytes)
    }

    /// Writes transforms on `/tf` (or `/tf_static` when `static_`) at `time_ns`.
    pub fn write_tf(&mut self, transforms: &TfMessage, static_: bool, time_ns: u64) -> Result<()> {
        let topic = if static_ { "/tf_static" } else { "/tf" };
        let channel = self.channel(topic, TF_MESSAGE, &BTreeMap::new())?;
        let bytes = to_cdr(transforms, 256).map_err(|e| bag_error(&self.dir, e))?;
        self.write(channel, topic, time_ns, bytes)
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.topics.values().map(|t| t.count).sum()
    }

    /// Finishes the MCAP file, writes `metadata.yaml` and moves the bag into place. Returns the
    /// bag's directory.
    pub fn finish(mut self) -> Result<PathBuf> {
        let dir = self.dir.clone();
        let mut writer = self.worker.join().map_err(|e| bag_error(&dir, e))?;
        writer.finish().map_err(|e| bag_error(&dir, e))?;
        let mut inner = writer.into_inner();
        inner.flush().map_err(|e| bag_error(&dir, e))?;
        inner.get_ref().sync_all().map_err(|e| bag_error(&dir, e))?;
        drop(inner);
        std::fs::write(self.staging.join("metadata.yaml"), self.metadata_yaml()).map_err(|e| bag_error(&dir, e))?;
        if dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(|e| bag_error(&dir, e))?;
        }
        std::fs::rename(&self.staging, &dir).map_err(|e| bag_error(&dir, e))?;
        Ok(dir)
    }

    /// `metadata.yaml` as rosbag2 (version 5, as Humble writes it) lays it out.
    fn metadata_yaml(&self) -> String {
        let (start, end) = self.times_ns.unwrap_or((0, 0));
        let count = self.messages();
        let mut y = format!(
            "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  duration:\n    nanoseconds: {}\n  starting_time:\n    nanoseconds_since_epoch: {start}\n  message_count: {count}\n  topics_with_message_count:\n",
            end - start
        );
        for (name, t) in &self.topics {
            let qos = t.qos.replace('\n', "\\n");
            y += &format!(
                "    - topic_metadata:\n        name: {name}\n        type: {}\n        serialization_format: cdr\n        offered_qos_profiles: \"{qos}\"\n      message_count: {}\n",
                t.ty, t.count
            );
        }
        y += &format!(
            "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - {f}\n  files:\n    - path: {f}\n      starting_time:\n        nanoseconds_since_epoch: {start}\n      duration:\n        nanoseconds: {}\n      message_count: {count}\n",
            end - start,
            f = self.file_name
        );
        y
    }
}

impl Drop for BagWriter {
    fn drop(&mut self) {
        // Not finished (or finish failed): stop the thread and leave nothing behind.
        // (After a successful finish the staging directory is the bag, renamed away.)
        let _ = self.worker.join();
        let _ = std::fs::remove_dir_all(&self.staging);
    }
}

/// A topic of a bag.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopicInfo {
    /// Name.
    pub name: String,
    /// Message type (schema name).
    pub ty: String,
    /// Message encoding.
    pub encoding: String,
    /// Messages.
    pub count: u64,
}

/// A bag to read: one `.mcap` file, or a rosbag2 directory's files (from its `metadata.yaml`,
/// else every `.mcap` in it, sorted).
#[derive(Clone, Debug)]
pub struct Bag {
    /// The path given.
    pub path: PathBuf,
    /// The MCAP files, in order.
    pub files: Vec<PathBuf>,
}

/// Whether `path` is a bag ([`Bag::open`] reads it): an `.mcap` file or a directory holding one.
pub fn is_bag(path: &Path) -> bool {
    if path.is_file() {
        return path.extension().is_some_and(|e| e == "mcap");
    }
    path.is_dir()
        && std::fs::read_dir(path)
            .map(|d| d.filter_map(|e| e.ok()).any(|e| e.path().extension().is_some_and(|x| x == "mcap")))
            .unwrap_or(false)
}

/// One PointCloud2 message read from a bag.
pub struct BagCloud {
    /// Its index among the topic's messages (0 on).
    pub index: usize,
    /// Its log time, nanoseconds.
    pub log_time_ns: u64,
    /// Its CDR bytes.
    pub cdr: Vec<u8>,
    /// Our layout's `# groundtruth` line, where the channel carries it.
    pub groundtruth_comment: Option<String>,
}

impl BagCloud {
    /// The decoded message (borrowing its data from [`BagCloud::cdr`]).
    pub fn decode(&self) -> std::result::Result<PointCloud2<'_>, String> {
        from_cdr(&self.cdr)
    }
}

impl Bag {
    /// Opens a bag (no message is read yet). Refused: a path that is neither an `.mcap` file nor a
    /// directory holding one.
    pub fn open(path: &Path) -> Result<Self> {
        let bad = |m: &str| bag_error(path, m);
        if path.is_file() {
            if path.extension().is_none_or(|e| e != "mcap") {
                return Err(bad("not an .mcap file"));
            }
            return Ok(Self { path: path.to_path_buf(), files: vec![path.to_path_buf()] });
        }
        if !path.is_dir() {
            return Err(bad("no such file or directory"));
        }
        let mut files: Vec<PathBuf> = Vec::new();
        if let Ok(text) = std::fs::read_to_string(path.join("metadata.yaml")) {
            let meta: serde_norway::Value = serde_norway::from_str(&text)
                .map_err(|e| bag_error(&path.join("metadata.yaml"), format!("not YAML: {e}")))?;
            let info = &meta["rosbag2_bagfile_information"];
            let storage = info["storage_identifier"].as_str().unwrap_or("mcap");
            if storage != "mcap" {
                return Err(bad(&format!(
                    "storage `{storage}`: only MCAP bags are read (convert with `ros2 bag convert` to storage mcap)"
                )));
            }
            if let Some(list) = info["relative_file_paths"].as_sequence() {
                files.extend(list.iter().filter_map(|f| f.as_str()).map(|f| path.join(f)));
            }
            if let Some(missing) = files.iter().find(|f| !f.is_file()) {
                return Err(bag_error(missing, "listed in metadata.yaml but missing"));
            }
        }
        if files.is_empty() {
            files = std::fs::read_dir(path)
                .map_err(|e| bag_error(path, e))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
                .collect();
            files.sort();
        }
        if files.is_empty() {
            return Err(bad("a directory without .mcap files: not a rosbag2 bag"));
        }
        Ok(Self { path: path.to_path_buf(), files })
    }

    /// The file's bytes, mapped: a bag of many gigabytes is not read into memory.
    fn read(file: &Path) -> Result<memmap2::Mmap> {
        let f = std::fs::File::open(file).map_err(|e| bag_error(file, e))?;
        // SAFETY: the mapping is read-only and private to this call's borrowers; as with every
        // reader of a file, a bag that another process truncates while it is read is undefined
        // (the MCAP readers of the mcap crate's own examples map files the same way).
        #[allow(unsafe_code)]
        let map = unsafe { memmap2::Mmap::map(&f) }.map_err(|e| bag_error(file, e))?;
        Ok(map)
    }

    /// The bag's topics with their types and message counts (from the summary, else every message
    /// is read; a file cut short counts its messages up to the cut).
    pub fn topics(&self) -> Result<Vec<TopicInfo>> {
        // The summary sections list channels and counts without reading the messages; files
        // without one (a writer that skipped it) are read through.
        if let Some(topics) = self.summary_topics() {
            return Ok(topics);
        }
        let mut topics: BTreeMap<String, TopicInfo> = BTreeMap::new();
        for file in &self.files {
            let bytes = Self::read(file)?;
            for m in Messages::new(&bytes) {
                let m = match m {
                    Ok(m) => m,
                    // A file cut short: its topics as far as it goes (the reading says where).
                    Err(e) if e.truncated => break,
                    Err(e) => return Err(bag_error(file, format!("corrupt MCAP: {e}"))),
                };
                let ty = m.channel.schema.clone();
                topics
                    .entry(m.channel.topic.clone())
                    .or_insert_with(|| TopicInfo {
                        name: m.channel.topic.clone(),
                        ty,
                        encoding: m.channel.message_encoding.clone(),
                        count: 0,
                    })
                    .count += 1;
            }
        }
        Ok(topics.into_values().collect())
    }

    /// The PointCloud2 topics (type `sensor_msgs/msg/PointCloud2`, encoding `cdr`).
    pub fn pointcloud_topics(&self) -> Result<Vec<TopicInfo>> {
        Ok(self.topics()?.into_iter().filter(|t| t.ty == POINTCLOUD2 && t.encoding == "cdr").collect())
    }

    /// The topics from the files' summary sections, without reading a message; `None` where a
    /// file has none (or a damaged one).
    fn summary_topics(&self) -> Option<Vec<TopicInfo>> {
        let mut topics: BTreeMap<String, TopicInfo> = BTreeMap::new();
        for file in &self.files {
            let bytes = Self::read(file).ok()?;
            if !super::stream::summary_is_safe_to_read(&bytes) {
                return None;
            }
            let summary = mcap::Summary::read(&bytes).ok().flatten()?;
            let counts = summary.stats.as_ref()?.channel_message_counts.clone();
            for (id, channel) in &summary.channels {
                topics
                    .entry(channel.topic.clone())
                    .or_insert_with(|| TopicInfo {
                        name: channel.topic.clone(),
                        ty: channel.schema.as_ref().map_or(String::new(), |s| s.name.clone()),
                        encoding: channel.message_encoding.clone(),
                        count: 0,
                    })
                    .count += counts.get(id).copied().unwrap_or(0);
            }
        }
        Some(topics.into_values().collect())
    }

    fn no_such_topic(&self, topic: &str) -> SimError {
        let names: Vec<String> = self
            .pointcloud_topics()
            .map(|t| t.into_iter().map(|t| format!("{} ({} messages)", t.name, t.count)).collect())
            .unwrap_or_default();
        bag_error(
            &self.path,
            format!(
                "no PointCloud2 topic `{topic}`; the bag's PointCloud2 topics: {}",
                if names.is_empty() { "none".to_string() } else { names.join(", ") }
            ),
        )
    }

    fn wrong_type(file: &Path, topic: &str, ty: &str, encoding: &str) -> SimError {
        bag_error(
            file,
            format!("topic `{topic}` holds `{ty}` in `{encoding}`, not sensor_msgs/msg/PointCloud2 in cdr (ROS 2)"),
        )
    }

    /// The messages of `topic`, in the order they were written (file by file), read and their
    /// chunks decompressed on a thread of their own, a message or two ahead of the caller.
    /// Refused, naming the topics there are: a topic that is not in the bag, or not PointCloud2
    /// in `cdr` (ROS 1, JSON, ...). A file that is corrupt stops the reading with an error naming
    /// the file and the message index reached; a file cut short (a recorder killed mid-write) is
    /// read up to its last whole message and the cut is reported by [`BagClouds::truncations`],
    /// as `mcap recover` would read it.
    pub fn clouds(&self, topic: &str) -> Result<BagClouds> {
        if let Some(topics) = self.summary_topics() {
            match topics.iter().find(|t| t.name == topic) {
                None => return Err(self.no_such_topic(topic)),
                Some(t) if t.ty != POINTCLOUD2 || t.encoding != "cdr" => {
                    return Err(Self::wrong_type(&self.path, topic, &t.ty, &t.encoding));
                }
                Some(_) => {}
            }
        }
        let (sender, receiver) = std::sync::mpsc::sync_channel::<Event>(2);
        let (files, wanted) = (self.files.clone(), topic.to_string());
        let handle = std::thread::spawn(move || {
            let mut index = 0usize;
            for file in &files {
                let bytes = match Self::read(file) {
                    Ok(b) => b,
                    Err(e) => {
                        let _ = sender.send(Event::Failed(e));
                        return;
                    }
                };
                let mut last_log_time_ns = None;
                for m in Messages::new(&bytes) {
                    let m = match m {
                        Ok(m) => m,
                        Err(e) if e.truncated => {
                            let cut =
                                Truncation { file: file.clone(), messages: index, last_log_time_ns, reason: e.message };
                            if sender.send(Event::Truncated(cut)).is_err() {
                                return;
                            }
                            break;
                        }
                        Err(e) => {
                            let message = format!("corrupt MCAP after message {index} of `{wanted}`: {e}");
                            let _ = sender.send(Event::Failed(bag_error(file, message)));
                            return;
                        }
                    };
                    if m.channel.topic != wanted {
                        continue;
                    }
                    let ty = m.channel.schema.as_str();
                    if ty != POINTCLOUD2 || m.channel.message_encoding != "cdr" {
                        let _ = sender.send(Event::Failed(Self::wrong_type(
                            file,
                            &wanted,
                            ty,
                            &m.channel.message_encoding,
                        )));
                        return;
                    }
                    last_log_time_ns = Some(m.log_time_ns);
                    let cloud = BagCloud {
                        index,
                        log_time_ns: m.log_time_ns,
                        cdr: m.data.into_owned(),
                        groundtruth_comment: m.channel.metadata.get(GROUNDTRUTH_KEY).cloned(),
                    };
                    if sender.send(Event::Cloud(cloud)).is_err() {
                        return; // the reader stopped
                    }
                    index += 1;
                }
            }
        });
        Ok(BagClouds {
            bag: Bag { path: self.path.clone(), files: self.files.clone() },
            topic: topic.to_string(),
            receiver: Some(receiver),
            handle: Some(handle),
            truncations: Vec::new(),
            read: 0,
            done: false,
        })
    }
}

/// What the reading thread of [`Bag::clouds`] sends.
enum Event {
    Cloud(BagCloud),
    Truncated(Truncation),
    Failed(SimError),
}

/// A bag file cut short: where its reading stopped.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Truncation {
    /// The file.
    pub file: PathBuf,
    /// Messages of the topic read before the cut (over the bag's files so far): the last one read
    /// is `messages - 1`.
    pub messages: usize,
    /// Log time of the last message of the topic read in this file, nanoseconds.
    pub last_log_time_ns: Option<u64>,
    /// What the MCAP reader said at the cut.
    pub reason: String,
}

impl std::fmt::Display for Truncation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.messages.checked_sub(1) {
            Some(last) => write!(
                f,
                "`{}` is cut short ({}): read up to its last whole message, message {last}{} ({} read)",
                self.file.display(),
                self.reason,
                self.last_log_time_ns.map_or(String::new(), |t| format!(" (log time {t} ns)")),
                self.messages
            ),
            None => {
                write!(f, "`{}` is cut short ({}) before any message of the topic", self.file.display(), self.reason)
            }
        }
    }
}

/// The messages of one topic of a bag ([`Bag::clouds`]), each `Ok` or the error that ended the
/// reading; a topic with no message at all (or none before a cut) ends in an error naming the
/// bag's PointCloud2 topics.
pub struct BagClouds {
    bag: Bag,
    topic: String,
    receiver: Option<std::sync::mpsc::Receiver<Event>>,
    handle: Option<std::thread::JoinHandle<()>>,
    truncations: Vec<Truncation>,
    read: usize,
    done: bool,
}

impl BagClouds {
    /// The files found cut short so far (each read up to its last whole message).
    pub fn truncations(&self) -> &[Truncation] {
        &self.truncations
    }

    /// The topic read.
    pub fn topic(&self) -> &str {
        &self.topic
    }
}

impl Iterator for BagClouds {
    type Item = Result<BagCloud>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        loop {
            let event = self.receiver.as_ref().and_then(|r| r.recv().ok());
            match event {
                Some(Event::Cloud(c)) => {
                    self.read += 1;
                    return Some(Ok(c));
                }
                Some(Event::Truncated(t)) => self.truncations.push(t),
                Some(Event::Failed(e)) => {
                    self.done = true;
                    return Some(Err(e));
                }
                None => {
                    self.done = true;
                    if self.read > 0 {
                        return None;
                    }
                    let error = self.bag.no_such_topic(&self.topic);
                    return Some(Err(match self.truncations.first() {
                        None => error,
                        Some(cut) => {
                            bag_error(&self.bag.path, format!("no whole message of `{}`: {cut}; {error}", self.topic))
                        }
                    }));
                }
            }
        }
    }
}

impl Drop for BagClouds {
    fn drop(&mut self) {
        // Closing the channel stops the reading thread at its next message.
        self.receiver = None;
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::ros2::messages::{Header, PointField, Time, datatype};

    fn cloud(k: u8) -> PointCloud2<'static> {
        let mut data = Vec::new();
        for v in [1.0f32, 2.0, 3.0 + f32::from(k)] {
            data.extend_from_slice(&v.to_le_bytes());
        }
        let f = |n: &str, o| PointField { name: n.into(), offset: o, datatype: datatype::FLOAT32, count: 1 };
        PointCloud2 {
            header: Header { stamp: Time::from_seconds(f64::from(k) * 0.1), frame_id: "lidar".into() },
            height: 1,
            width: 1,
            fields: vec![f("x", 0), f("y", 4), f("z", 8)],
            is_bigendian: false,
            point_step: 12,
            row_step: 12,
            data: std::borrow::Cow::Owned(data),
            is_dense: true,
        }
    }

    #[test]
    #[cfg_attr(not(feature = "bag-compression"), ignore = "zstd bags need the `bag-compression` feature")]
    fn a_bag_round_trips_and_lists_its_topics() {
        let dir = tempfile::tempdir().unwrap();
        let bag = dir.path().join("scan");
        let mut w = BagWriter::create(&bag).unwrap();
        for k in 0..3 {
            w.write_pointcloud("/lidar/points", &cloud(k), u64::from(k) * 100_000_000, &BTreeMap::new()).unwrap();
        }
        w.write_tf(&TfMessage { transforms: vec![] }, true, 0).unwrap();
        assert_eq!(w.finish().unwrap(), bag);
        assert!(bag.join("scan_0.mcap").is_file() && bag.join("metadata.yaml").is_file());
        let yaml = std::fs::read_to_string(bag.join("metadata.yaml")).unwrap();
        assert!(yaml.contains("message_count: 4") && yaml.contains("durability: 1"), "{yaml}");
        let b = Bag::open(&bag).unwrap();
        let topics = b.topics().unwrap();
        assert_eq!(topics.len(), 2);
        assert_eq!(b.pointcloud_topics().unwrap()[0].count, 3);
        let z: Vec<f32> = b
            .clouds("/lidar/points")
            .unwrap()
            .map(|c| {
                let c = c.unwrap();
                let pc = c.decode().unwrap();
                f32::from_le_bytes(pc.data[8..12].try_into().unwrap())
            })
            .collect();
        assert_eq!(z, vec![3.0, 4.0, 5.0]);
        let e = b.clouds("/nope").err().unwrap().to_string();
        assert!(e.contains("/lidar/points (3 messages)"), "{e}");
        let e = b.clouds("/tf_static").err().unwrap().to_string();
        assert!(e.contains("tf2_msgs/msg/TFMessage"), "{e}");
        // A file cut short is read up to its last whole message, the cut reported naming the file
        // and the last message read.
        let file = bag.join("scan_0.mcap");
        let bytes = std::fs::read(&file).unwrap();
        std::fs::write(&file, &bytes[..bytes.len() - 30]).unwrap();
        let b = Bag::open(&bag).unwrap();
        let mut clouds = b.clouds("/lidar/points").unwrap();
        assert_eq!(clouds.by_ref().map(|c| c.unwrap().index).collect::<Vec<_>>(), [0, 1, 2]);
        let cut = clouds.truncations().to_vec();
        assert_eq!(cut.len(), 1);
        let text = cut[0].to_string();
        assert!(text.contains("scan_0.mcap") && text.contains("message 2"), "{text}");
        // Cut before any message: an error naming the file and the cut.
        std::fs::write(&file, &bytes[..40]).unwrap();
        let e = Bag::open(&bag).unwrap().clouds("/lidar/points").unwrap().find_map(|c| c.err()).unwrap().to_string();
        assert!(e.contains("scan_0.mcap") && e.contains("cut short"), "{e}");
        // An unfinished bag leaves nothing.
        let w = BagWriter::create(&dir.path().join("never")).unwrap();
        drop(w);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// A bag from another writer: lz4 chunks (Foxglove's tools and some converters write them),
    /// no summary section, no `metadata.yaml`, two messages per chunk; and a sqlite3 rosbag2
    /// directory, refused by name.
    #[cfg(feature = "bag-compression")]
    #[test]
    fn lz4_chunks_without_a_summary_and_sqlite3_bags() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("other.mcap");
        let file = BufWriter::new(std::fs::File::create(&path).unwrap());
        let options = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Lz4))
            .chunk_size(Some(64))
            .emit_summary_records(false)
            .emit_summary_offsets(false);
        let mut w = options.create(file).unwrap();
        let schema = w.add_schema(POINTCLOUD2, "ros2msg", pointcloud2_definition().as_bytes()).unwrap();
        let channel = w.add_channel(schema, "/points", "cdr", &BTreeMap::new()).unwrap();
        for k in 0..4u8 {
            let header =
                mcap::records::MessageHeader { channel_id: channel, sequence: 0, log_time: 0, publish_time: 0 };
            w.write_to_known_channel(&header, &to_cdr(&cloud(k), 12).unwrap()).unwrap();
        }
        w.finish().unwrap();
        drop(w);
        let b = Bag::open(&path).unwrap();
        assert_eq!(b.pointcloud_topics().unwrap()[0].count, 4);
        let z: Vec<f32> = b
            .clouds("/points")
            .unwrap()
            .map(|c| f32::from_le_bytes(c.unwrap().decode().unwrap().data[8..12].try_into().unwrap()))
            .collect();
        assert_eq!(z, [3.0, 4.0, 5.0, 6.0]);
        let sqlite = dir.path().join("sqlite");
        std::fs::create_dir(&sqlite).unwrap();
        std::fs::write(
            sqlite.join("metadata.yaml"),
            "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n  relative_file_paths:\n    - sqlite_0.db3\n",
        )
        .unwrap();
        let e = Bag::open(&sqlite).unwrap_err().to_string();
        assert!(e.contains("sqlite3") && e.contains("ros2 bag convert"), "{e}");
    }
}
