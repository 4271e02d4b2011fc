//! The messages of one MCAP file in the order they were written, from the `mcap` crate's sans-io
//! reader with a bound on every record's length.
//!
//! `mcap::MessageStream` (0.26) reads chunk records without such a bound: a corrupted length in a
//! damaged file makes it reserve exabytes and abort the process. Here every record (and so every
//! allocation) is limited to [`MAX_RECORD_BYTES`], and a larger one is refused as corrupt.
//!
//! The reader is linear (no summary or footer needed), so a file cut short (a recorder killed
//! mid-write) yields every message that was written whole, then a [`StreamError`] that says it
//! was cut short ([`StreamError::truncated`]), as `mcap recover` reads such a file.

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Arc;

use mcap::records::{Record, op};
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};

/// The largest record read (1 GiB): far above any point cloud (an OS1-128 at 2048 columns with
/// every driver field is 12.6 MB), far below what a corrupted length asks for.
pub const MAX_RECORD_BYTES: usize = 1 << 30;

/// A channel as the stream knows it.
#[derive(Debug)]
pub struct ChannelInfo {
    /// Its topic.
    pub topic: String,
    /// Its schema's name (empty where it has none).
    pub schema: String,
    /// Its message encoding (`cdr` for ROS 2).
    pub message_encoding: String,
    /// Its metadata.
    pub metadata: std::collections::BTreeMap<String, String>,
}

/// Why the stream stopped before its end.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StreamError {
    /// The file ends inside a record (cut short), rather than holding bytes that are not MCAP.
    pub truncated: bool,
    /// What the reader said.
    pub message: String,
}

impl StreamError {
    fn corrupt(message: impl Into<String>) -> Self {
        Self { truncated: false, message: message.into() }
    }
}

impl From<mcap::McapError> for StreamError {
    fn from(e: mcap::McapError) -> Self {
        let message = match &e {
            // A build without zstd and LZ4 names what it lacks and how to get it.
            mcap::McapError::UnsupportedCompression(name) if !cfg!(feature = "bag-compression") => {
                format!("chunks compressed with `{name}`: decompression is {}", super::bag::COMPRESSION_NOT_BUILT)
            }
            _ => e.to_string(),
        };
        Self { truncated: matches!(e, mcap::McapError::UnexpectedEof), message }
    }
}

impl std::fmt::Display for StreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// A message of the stream.
pub struct StreamMessage<'a> {
    /// Its channel.
    pub channel: Arc<ChannelInfo>,
    /// Its log time, nanoseconds.
    pub log_time_ns: u64,
    /// Its bytes (borrowed from the file where its chunk was stored uncompressed).
    pub data: Cow<'a, [u8]>,
}

/// Iterates the messages of an MCAP file's bytes (see the module docs).
pub struct Messages<'a> {
    buf: &'a [u8],
    reader: LinearReader,
    schemas: HashMap<u16, String>,
    channels: HashMap<u16, Arc<ChannelInfo>>,
    done: bool,
}

impl<'a> Messages<'a> {
    /// Starts reading `buf`, a whole MCAP file.
    pub fn new(buf: &'a [u8]) -> Self {
        let options = LinearReaderOptions::default().with_record_length_limit(MAX_RECORD_BYTES);
        Self {
            buf,
            reader: LinearReader::new_with_options(options),
            schemas: HashMap::new(),
            channels: HashMap::new(),
            done: false,
        }
    }

    fn next_record(&mut self) -> Option<Result<Record<'a>, StreamError>> {
        while let Some(event) = self.reader.next_event() {
            match event {
                Ok(LinearReadEvent::ReadRequest(need)) => {
                    let n = need.min(self.buf.len());
                    self.reader.insert(n).copy_from_slice(&self.buf[..n]);
                    self.reader.notify_read(n);
                    self.buf = &self.buf[n..];
                }
                Ok(LinearReadEvent::Record { data, opcode }) => {
                    if opcode == op::ATTACHMENT && attachment_is_short(data) {
                        return Some(Err(StreamError::corrupt("an attachment record shorter than its header and CRC")));
                    }
                    return Some(mcap::parse_record(opcode, data).map(Record::into_owned).map_err(StreamError::from));
                }
                Err(e) => return Some(Err(e.into())),
            }
        }
        None
    }
}

/// Whether an Attachment record's `body` ends before its header (log and create times, name,
/// media type, data length) and CRC: mcap 0.26's `parse_record` slices such a body past its end, a
/// panic (found by the `mcap_bag` fuzz target). A body too short for the header's string lengths
/// counts as short too (the crate would refuse it).
fn attachment_is_short(body: &[u8]) -> bool {
    let length_at = |at: usize| Some(u32::from_le_bytes(body.get(at..at.checked_add(4)?)?.try_into().ok()?) as usize);
    let header_and_crc = (|| {
        let media_type_at = 20usize.checked_add(length_at(16)?)?;
        media_type_at.checked_add(4)?.checked_add(length_at(media_type_at)?)?.checked_add(8 + 4)
    })();
    header_and_crc.is_none_or(|n| body.len() < n)
}

/// Bytes of the footer record (opcode, length, 20-byte body) and the end magic.
const FOOTER_AND_MAGIC_BYTES: usize = 1 + 8 + 20 + 8;

/// Whether the summary section of the MCAP file `buf` (from the footer's summary start to the
/// footer) can be handed to `mcap::Summary::read`: no Attachment record shorter than its header
/// (see [`attachment_is_short`]) and no Chunk (whose records the crate would parse too); the spec
/// allows neither there. A file without a footer or summary is left to the crate.
pub(crate) fn summary_is_safe_to_read(buf: &[u8]) -> bool {
    let Some(footer) = buf.len().checked_sub(FOOTER_AND_MAGIC_BYTES) else { return true };
    let summary_start = u64::from_le_bytes(buf[footer + 9..footer + 17].try_into().unwrap_or_default());
    if summary_start == 0 {
        return true;
    }
    let mut at = usize::try_from(summary_start).unwrap_or(usize::MAX);
    while let Some(head) = buf.get(at..at.saturating_add(9)) {
        let length =
            usize::try_from(u64::from_le_bytes(head[1..9].try_into().unwrap_or_default())).unwrap_or(usize::MAX);
        let body = buf.get(at + 9..).unwrap_or_default();
        match head[0] {
            op::FOOTER => break,
            op::CHUNK => return false,
            op::ATTACHMENT if attachment_is_short(&body[..length.min(body.len())]) => return false,
            _ => {}
        }
        at = at.saturating_add(9).saturating_add(length);
    }
    true
}

impl<'a> Iterator for Messages<'a> {
    type Item = Result<StreamMessage<'a>, StreamError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        loop {
            let record = match self.next_record() {
                None => {
                    self.done = true;
                    return None;
                }
                Some(Err(e)) => {
                    self.done = true;
                    return Some(Err(e));
                }
                Some(Ok(r)) => r,
            };
            match record {
                Record::Schema { header, .. } => {
                    self.schemas.insert(header.id, header.name);
                }
                Record::Channel(c) => {
                    let schema = if c.schema_id == 0 {
                        String::new()
                    } else {
                        match self.schemas.get(&c.schema_id) {
                            Some(name) => name.clone(),
                            None => {
                                self.done = true;
                                return Some(Err(StreamError::corrupt(format!(
                                    "channel {} names schema {}, which is not there",
                                    c.id, c.schema_id
                                ))));
                            }
                        }
                    };
                    let info = ChannelInfo {
                        topic: c.topic,
                        schema,
                        message_encoding: c.message_encoding,
                        metadata: c.metadata,
                    };
                    self.channels.insert(c.id, Arc::new(info));
                }
                Record::Message { header, data } => {
                    let Some(channel) = self.channels.get(&header.channel_id) else {
                        self.done = true;
                        return Some(Err(StreamError::corrupt(format!(
                            "a message on channel {}, which is not there",
                            header.channel_id
                        ))));
                    };
                    return Some(Ok(StreamMessage { channel: channel.clone(), log_time_ns: header.log_time, data }));
                }
                // The summary after it repeats schemas and channels: the messages end here.
                Record::DataEnd(_) => {
                    // Read on to the end so that a truncated summary or end magic is reported.
                    while let Some(r) = self.next_record() {
                        if let Err(e) = r {
                            self.done = true;
                            return Some(Err(e));
                        }
                    }
                    self.done = true;
                    return None;
                }
                _ => {}
            }
        }
    }
}
