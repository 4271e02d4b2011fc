//! Where a frame came from: its file, and for a bag's message its topic, index and log time, for a
//! labelled dataset's frame its sequence; the layout its points were read in. With the ordering report ([`crate::ordering::OrderingReport`])
//! it says how a frame was read.

use std::path::PathBuf;

use serde::Serialize;

use super::{InputLayout, LayoutBasis};

/// Where a frame came from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Provenance {
    /// The file (for a bag: the bag given, an `.mcap` file or a rosbag2 directory).
    pub file: PathBuf,
    /// How its points were laid out.
    pub layout: InputLayout,
    /// What decided the layout (name, content or `--layout`).
    pub layout_by: LayoutBasis,
    /// The bag's topic, for a message.
    pub topic: Option<String>,
    /// The message's index among the topic's messages (0 on), for a message.
    pub message: Option<usize>,
    /// The message's log time, nanoseconds, for a message.
    pub log_time_ns: Option<u64>,
    /// The sequence (its folder name, e.g. `08`), for a labelled dataset's frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sequence: Option<String>,
}

impl Provenance {
    /// A file's.
    pub fn file(file: PathBuf, layout: InputLayout, layout_by: LayoutBasis) -> Self {
        Self { file, layout, layout_by, topic: None, message: None, log_time_ns: None, sequence: None }
    }

    /// A labelled dataset's frame's: its cloud file `file` in sequence `sequence`.
    pub fn sequence_file(file: PathBuf, sequence: &str, layout: InputLayout, layout_by: LayoutBasis) -> Self {
        Self { sequence: Some(sequence.to_string()), ..Self::file(file, layout, layout_by) }
    }

    /// A bag message's.
    pub fn message(bag: PathBuf, topic: &str, index: usize, log_time_ns: u64) -> Self {
        Self {
            file: bag,
            layout: InputLayout::PointCloud2,
            layout_by: LayoutBasis::Name,
            topic: Some(topic.to_string()),
            message: Some(index),
            log_time_ns: Some(log_time_ns),
            sequence: None,
        }
    }

    /// The name the frame goes by in messages: the file, or `BAG#TOPIC[INDEX]` for a message.
    pub fn name(&self) -> PathBuf {
        match (&self.topic, self.message) {
            (Some(topic), Some(index)) => PathBuf::from(format!("{}#{topic}[{index}]", self.file.display())),
            _ => self.file.clone(),
        }
    }
}

impl std::fmt::Display for Provenance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.name().display())
    }
}
