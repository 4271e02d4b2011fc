//! Recordings read as ordered frames: any input the project reads (a KITTI-layout `.bin`, a PCD,
//! PLY or LAS file, a directory of them, a scan directory with its `manifest.json`, a ROS 2 bag's
//! PointCloud2 topic, a labelled SemanticKITTI-layout or nuScenes-lidarseg directory) becomes a
//! sequence of frames, each with its cloud (ordered into rings and columns by a [`SensorSetup`],
//! or as stored), what ordering did ([`OrderingReport`]) and where it came from ([`Provenance`]).
//! `classify`, `eval dataset` (datasets and bags, through [`crate::dataset::evaluate`]), `bench
//! classify`, `train --dataset` and the Python package read through here.
//!
//! A directory holding `sequences/` (a SemanticKITTI-layout root), `velodyne/` (one sequence's
//! folder, `labels/` beside it) or `lidar/` with `lidarseg/` (a nuScenes-lidarseg folder) is a
//! labelled dataset: listed by [`crate::dataset::DatasetLayout`], its frames read sequence by
//! sequence, each ordered by the same [`SensorSetup`] with its classes carried through ordering as
//! the cloud's labels, its points and classes in file order at [`Frame::labelled`], its provenance
//! naming the sequence and the `.bin`.
//!
//! - [`input`]: what a path holds (one file, a scan directory, a directory of files) and each
//!   file's layout ([`InputLayout`], decided once per file: the place a new layout goes);
//! - [`labelled`]: a labelled dataset as a recording ([`LabelledPoints`]);
//! - [`files`]: the one reader of the file formats and of labelled frames ([`FrameReader`]);
//! - [`bag`]: a bag's topic (the one there is, or the one named) and the warning of a bag cut short;
//!   its messages are read in [`Frames`], the one loop over a bag's messages;
//! - [`provenance`]: where a frame came from;
//! - [`bytes`]: the page-aligned buffer files are read into.
//!
//! ```
//! use classifier::recording::{Ordering, Recording};
//! let dir = tempfile::tempdir()?;
//! let mut cloud = sim::OrderedCloud::empty(2, 3, 1);
//! for (i, p) in cloud.point_in_vehicle.iter_mut().enumerate() {
//!     *p = glam::Vec3::new(10.0, i as f32, -1.0);
//! }
//! sim::io::pcd::write(&dir.path().join("frame_000007.pcd"), &cloud, false)?;
//! let recording = Recording::open(dir.path(), None)?;
//! let mut frames = recording.frames(Ordering::AsStored)?;
//! let frame = frames.next_frame().expect("one frame")?;
//! assert_eq!((frame.index, frame.cloud.rows, frame.cloud.cols), (7, 2, 3));
//! assert!(frame.provenance.file.ends_with("frame_000007.pcd"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod bag;
pub mod bytes;
pub mod files;
pub mod input;
pub mod labelled;
pub mod provenance;

use std::path::{Path, PathBuf};

use glam::Affine3A;
use sim::OrderedCloud;
use sim::io::ros2::{Bag, BagCloud, BagClouds};

pub use bag::resolve_topic;
pub use bytes::InputBytes;
pub use files::{FrameReader, read_as_stored, read_as_stored_as};
pub use input::{InputFile, InputLayout, LayoutBasis, LayoutChoice, list_files};
pub use labelled::LabelledPoints;
pub use provenance::Provenance;

use crate::dataset::{DatasetError, DatasetLayout};
use crate::error::ClassifyError;
use crate::ordering::{OrderingReport, SensorSetup, decisions_per_input_point};
use labelled::DatasetSource;

/// Why a recording, or one of its frames, could not be read.
#[derive(Debug, thiserror::Error)]
pub enum RecordingError {
    /// A file that could not be read (the error names it).
    #[error(transparent)]
    File(#[from] sim::SimError),
    /// A labelled dataset that could not be listed, or one of its frames read or ordered (the
    /// error names the folder or file).
    #[error(transparent)]
    Dataset(#[from] Box<DatasetError>),
    /// A path that is neither a file nor a directory.
    #[error("input `{}` is neither a file nor a directory", .path.display())]
    NotFound {
        /// The path.
        path: PathBuf,
    },
    /// A directory holding no file of a known layout.
    #[error("no {} files in `{}`", InputLayout::EXTENSIONS, .path.display())]
    Empty {
        /// The directory.
        path: PathBuf,
    },
    /// A directory that could not be listed.
    #[error("reading directory `{}`: {error}", .path.display())]
    Io {
        /// The directory.
        path: PathBuf,
        /// What the system said.
        error: std::io::Error,
    },
    /// A file of no layout the reader knows.
    #[error("`{}`: unsupported file type (expected {})", .path.display(), InputLayout::EXTENSIONS)]
    Unsupported {
        /// The file.
        path: PathBuf,
    },
    /// A `--layout` of no known name.
    #[error("--layout `{name}`: allowed {}", LayoutChoice::NAMES.join(", "))]
    UnknownLayout {
        /// The name given.
        name: String,
    },
    /// A `--layout` for a file that is not a headerless `.bin`.
    #[error(
        "`{}`: --layout {} applies to headerless .bin files (KITTI or nuScenes records); this is a {} file",
        .path.display(),
        .choice.name(),
        .named.description()
    )]
    LayoutOfNonRaw {
        /// The file.
        path: PathBuf,
        /// The layout asked for.
        choice: LayoutChoice,
        /// The file's layout by its name.
        named: InputLayout,
    },
    /// A rig that could not be loaded.
    #[error("loading rig `{name}`: {error}")]
    Rig {
        /// The rig's name or file.
        name: String,
        /// What is wrong.
        error: sim::SimError,
    },
    /// A rig or calibration that cannot order files (`what` names it).
    #[error("{what}: {error}")]
    Setup {
        /// The rig or calibration.
        what: String,
        /// What is wrong.
        error: ClassifyError,
    },
    /// A frame that ordering refused.
    #[error("ordering {what}: {error}")]
    Ordering {
        /// The frame (`` `FILE` ``, or the rows of one).
        what: String,
        /// What ordering said.
        error: ClassifyError,
    },
    /// An organized cloud whose rows disagree with the calibration file's lasers.
    #[error("`{name}` has {rows} rows but the calibration file {lasers} lasers")]
    CalibrationRows {
        /// The frame.
        name: String,
        /// Its rows.
        rows: usize,
        /// The calibration's lasers.
        lasers: usize,
    },
    /// No topic given and the bag does not hold exactly one PointCloud2 topic (the message lists
    /// them).
    #[error("{0}")]
    Topic(String),
    /// A topic given for an input that is not a bag.
    #[error("--topic applies to a bag (an .mcap file or a rosbag2 directory); `{}` is none", .path.display())]
    TopicWithoutBag {
        /// The input.
        path: PathBuf,
    },
    /// A bag's message that cannot be read (its fields disagree with its data, no `x y z`, a
    /// cloud ordering refuses): the other messages can still be read.
    #[error("`{}` {topic} message {index}: {reason}", .bag.display())]
    Message {
        /// The bag.
        bag: PathBuf,
        /// The topic.
        topic: String,
        /// The message's index on the topic.
        index: usize,
        /// What is wrong.
        reason: String,
    },
}

impl RecordingError {
    /// Whether the error is one message's (skip it, read on) rather than the recording's.
    pub fn is_message(&self) -> bool {
        self.message_index().is_some()
    }

    /// The index of the message, for one message's error.
    pub fn message_index(&self) -> Option<usize> {
        match self {
            RecordingError::Message { index, .. } => Some(*index),
            _ => None,
        }
    }
}

/// The sensor setup that orders files from other tools: a rig by preset name or TOML file (a
/// single-sensor rig: its beam table and mount) and the sensor's calibration file (see
/// [`SensorSetup::new`]).
pub fn sensor_setup(rig: Option<&str>, calibration: Option<&Path>) -> Result<SensorSetup, RecordingError> {
    let rig_value = match rig {
        Some(name) => {
            Some(sim::Rig::load(name).map_err(|error| RecordingError::Rig { name: name.to_string(), error })?)
        }
        None => None,
    };
    SensorSetup::new(rig_value.as_ref(), calibration).map_err(|error| RecordingError::Setup {
        what: match rig {
            Some(name) => format!("rig `{name}`"),
            None => "the sensor setup".to_string(),
        },
        error,
    })
}

/// How frames are read.
#[derive(Clone, Copy, Debug)]
pub enum Ordering<'a> {
    /// Ordered into rings and columns for classification with this setup (our own files are
    /// already).
    Ordered(&'a SensorSetup),
    /// As the file or message holds them (an organized cloud keeps its grid, anything else is
    /// `1 x N` in its own order).
    AsStored,
}

/// A recording: a file, a directory of files, a scan directory, a bag's topic, or a labelled
/// dataset.
#[derive(Debug)]
pub struct Recording {
    path: PathBuf,
    source: Source,
    layout: Option<LayoutChoice>,
}

#[derive(Debug)]
enum Source {
    Files(Vec<InputFile>),
    Bag { bag: Bag, topic: String },
    Dataset(DatasetSource),
}

impl Recording {
    /// Opens `path`: a bag (an `.mcap` file or a rosbag2 directory; `topic`, or its one PointCloud2
    /// topic); a labelled dataset, every sequence (a directory holding `sequences/`, `velodyne/`,
    /// or `lidar/` with `lidarseg/`: [`DatasetLayout::is_dataset`], listed by
    /// [`DatasetLayout::open`]); else the files of [`list_files`]. Refused: a topic for an input
    /// that is not a bag, and what [`list_files`], [`DatasetLayout::open`] and [`resolve_topic`]
    /// refuse.
    pub fn open(path: &Path, topic: Option<&str>) -> Result<Self, RecordingError> {
        if sim::io::ros2::is_bag(path) {
            let bag = Bag::open(path)?;
            let topic = resolve_topic(&bag, topic)?;
            return Ok(Self { path: path.to_path_buf(), source: Source::Bag { bag, topic }, layout: None });
        }
        if topic.is_some() {
            return Err(RecordingError::TopicWithoutBag { path: path.to_path_buf() });
        }
        if path.is_dir() && DatasetLayout::is_dataset(path) {
            return Ok(Self::from_dataset(DatasetLayout::open(path, None).map_err(Box::new)?));
        }
        Ok(Self { path: path.to_path_buf(), source: Source::Files(list_files(path)?), layout: None })
    }

    /// The recording of a labelled dataset as listed (its root the path; some sequences, or some
    /// frames of one, with [`DatasetLayout::open`]'s `only` and [`DatasetLayout::part`]).
    pub fn from_dataset(layout: DatasetLayout) -> Self {
        Self { path: layout.root.clone(), source: Source::Dataset(DatasetSource::new(layout)), layout: None }
    }

    /// The listing, for a labelled dataset.
    pub fn dataset(&self) -> Option<&DatasetLayout> {
        match &self.source {
            Source::Dataset(d) => Some(&d.layout),
            _ => None,
        }
    }

    /// The same recording with its headerless `.bin` files read in `layout` (`--layout`: KITTI or
    /// nuScenes records, whatever their names and contents say); `None` decides per file
    /// ([`InputLayout::decide`]). Refused: a layout for a bag, KITTI records for a
    /// nuScenes-lidarseg folder (its sweeps are nuScenes records), a layout for a file that is not a
    /// `.bin` (when its frame is read).
    pub fn with_layout(mut self, layout: Option<LayoutChoice>) -> Result<Self, RecordingError> {
        let named = match (layout, &self.source) {
            (Some(_), Source::Bag { .. }) => Some(InputLayout::PointCloud2),
            (Some(LayoutChoice::Kitti), Source::Dataset(d))
                if d.layout.format == crate::dataset::FrameFormat::NuscenesLidarseg =>
            {
                Some(InputLayout::NuscenesBin)
            }
            _ => None,
        };
        if let (Some(choice), Some(named)) = (layout, named) {
            return Err(RecordingError::LayoutOfNonRaw { path: self.path.clone(), choice, named });
        }
        self.layout = layout;
        Ok(self)
    }

    /// The layout `--layout` named for its `.bin` files, if any.
    pub fn layout_choice(&self) -> Option<LayoutChoice> {
        self.layout
    }

    /// The path given.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The bag's topic read, for a bag.
    pub fn topic(&self) -> Option<&str> {
        match &self.source {
            Source::Bag { topic, .. } => Some(topic),
            Source::Files(_) | Source::Dataset(_) => None,
        }
    }

    /// The files, for a recording of files (for a labelled dataset its frames' cloud files, in
    /// the order they are read, indexed by place; empty for a bag).
    pub fn files(&self) -> &[InputFile] {
        match &self.source {
            Source::Files(files) => files,
            Source::Dataset(d) => &d.files,
            Source::Bag { .. } => &[],
        }
    }

    /// Its frames, in order, read as `ordering` says (see [`Frames::next_frame`]).
    pub fn frames<'r>(&'r self, ordering: Ordering<'r>) -> Result<Frames<'r>, RecordingError> {
        let clouds = match &self.source {
            Source::Bag { bag, topic } => Some(bag.clouds(topic)?),
            Source::Files(_) | Source::Dataset(_) => None,
        };
        let mut reader = FrameReader::default();
        reader.set_layout_choice(self.layout);
        Ok(Frames {
            recording: self,
            ordering,
            reader,
            next_file: 0,
            clouds,
            message: None,
            provenance: Provenance::file(self.path.clone(), InputLayout::PointCloud2, LayoutBasis::Name),
            world_from_vehicle: None,
            warnings: Vec::new(),
            cuts_seen: 0,
            dense_with_nan: None,
        })
    }
}

/// One frame of a recording, borrowed from its [`Frames`] until the next is read.
pub struct Frame<'a> {
    /// Frame index: a file's (manifest, `frame_NNNNNN` name, place in the directory), a message's
    /// index on its topic, a labelled dataset's frame's place in the recording (sequence by
    /// sequence; its place in its sequence is [`LabelledPoints::index_in_sequence`]).
    pub index: usize,
    /// The cloud.
    pub cloud: &'a OrderedCloud,
    /// What ordering did, for input from other tools (the cell of every input point); `None` for
    /// our own files and frames read as stored.
    pub report: Option<&'a OrderingReport>,
    /// Where it came from.
    pub provenance: &'a Provenance,
    /// The vehicle's pose, where the recording gives it (a scan directory's manifest).
    pub world_from_vehicle: Option<Affine3A>,
    /// Milliseconds spent reading (the file's read, or the message's decode; the rest was
    /// ordering).
    pub read_ms: f64,
    /// The bag's message, for a message (to write it back with decisions, say).
    pub message: Option<&'a BagCloud>,
    /// A labelled dataset's frame: its files, its place in its sequence, its points and classes
    /// in file order (the classes are also the cloud's labels, carried through ordering); `None`
    /// for other recordings.
    pub labelled: Option<LabelledPoints<'a>>,
}

impl Frame<'_> {
    /// Decisions per cell of [`Frame::cloud`] as one byte per input point in the input's own order
    /// (1 = ground): through the ordering report where there is one, else cell by cell.
    pub fn decisions_per_point(&self, ground: &[bool]) -> Vec<u8> {
        decisions_per_input_point(self.report, ground)
    }
}

/// The frames of a [`Recording`], read one after another into buffers kept from frame to frame
/// (a lending iterator: each [`Frame`] borrows them until the next). For a bag this is the one
/// loop over its messages: each PointCloud2 message is decoded straight from its data and ordered
/// as a PCD file is; a message that cannot be read is an error of its own
/// ([`RecordingError::is_message`]: read on); a bag file cut short is read up to its last whole
/// message, with a warning ([`Frames::warnings`]).
pub struct Frames<'r> {
    recording: &'r Recording,
    ordering: Ordering<'r>,
    reader: FrameReader,
    next_file: usize,
    clouds: Option<BagClouds>,
    message: Option<BagCloud>,
    provenance: Provenance,
    world_from_vehicle: Option<Affine3A>,
    warnings: Vec<String>,
    cuts_seen: usize,
    /// Messages that declare `is_dense` but hold NaN points: the index of their warning, their
    /// count, the first one's index and NaN points.
    dense_with_nan: Option<(usize, usize, usize, usize)>,
}

impl Frames<'_> {
    /// The next frame, or the error that kept it from being read; `None` at the end.
    #[allow(clippy::should_implement_trait)]
    pub fn next_frame(&mut self) -> Option<Result<Frame<'_>, RecordingError>> {
        let read_ms = match self.clouds.as_mut() {
            Some(clouds) => {
                let next = clouds.next();
                let cuts = clouds.truncations();
                for cut in &cuts[self.cuts_seen..] {
                    self.warnings.push(bag::truncation_warning(clouds.topic(), cut));
                }
                self.cuts_seen = cuts.len();
                let message = match next? {
                    Ok(m) => m,
                    Err(e) => return Some(Err(e.into())),
                };
                let topic = clouds.topic().to_string();
                self.provenance =
                    Provenance::message(self.recording.path.clone(), &topic, message.index, message.log_time_ns);
                self.world_from_vehicle = None;
                let setup = match self.ordering {
                    Ordering::Ordered(setup) => Some(setup),
                    Ordering::AsStored => None,
                };
                let read = self.reader.read_message(&self.provenance, &message, setup);
                if read.is_ok() && self.reader.declared_dense() && self.reader.nan_no_returns() > 0 {
                    self.warn_dense_with_nan(&topic, message.index);
                }
                self.message = Some(message);
                read
            }
            None => {
                let recording = self.recording;
                let file = recording.files().get(self.next_file)?;
                self.next_file += 1;
                self.message = None;
                self.world_from_vehicle = file.world_from_vehicle;
                if let Source::Dataset(dataset) = &recording.source {
                    self.read_labelled(dataset, self.next_file - 1)?
                } else {
                    let read = match self.ordering {
                        Ordering::Ordered(setup) => {
                            self.reader.read(&file.path, setup).map(|ms| (ms, self.reader.layout()))
                        }
                        Ordering::AsStored => {
                            let t0 = std::time::Instant::now();
                            read_as_stored_as(&file.path, self.recording.layout).map(|(cloud, layout)| {
                                self.reader.set_cloud(cloud);
                                (t0.elapsed().as_secs_f64() * 1e3, layout)
                            })
                        }
                    };
                    if read.is_ok() && self.reader.trailing_bytes() > 0 {
                        self.warnings.push(format!(
                            "warning: `{}`: {} bytes after the points its header declares, left unread (as PCL's reader leaves them)",
                            file.path.display(),
                            self.reader.trailing_bytes()
                        ));
                    }
                    read.map(|(ms, (layout, basis))| {
                        self.provenance = Provenance::file(file.path.clone(), layout, basis);
                        ms
                    })
                }
            }
        };
        let read_ms = match read_ms {
            Ok(ms) => ms,
            Err(e) => return Some(Err(e)),
        };
        let index = match (&self.message, self.recording.files().get(self.next_file.wrapping_sub(1))) {
            (Some(m), _) => m.index,
            (None, Some(f)) => f.index,
            (None, None) => 0,
        };
        let labelled = match &self.recording.source {
            Source::Dataset(dataset) => self.labelled(dataset),
            _ => None,
        };
        Some(Ok(Frame {
            index,
            cloud: self.reader.cloud(),
            report: self.reader.report(),
            provenance: &self.provenance,
            world_from_vehicle: self.world_from_vehicle,
            read_ms,
            message: self.message.as_ref(),
            labelled,
        }))
    }

    /// The warnings so far: each bag file found cut short, naming the last message read; the
    /// messages that declare `is_dense = true` but hold NaN points (read as no-returns); each
    /// binary PCD file with bytes after the points its header declares (left unread).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Counts message `index` of `topic` among those that declare `is_dense` but hold NaN points,
    /// keeping one warning for them all.
    fn warn_dense_with_nan(&mut self, topic: &str, index: usize) {
        let nan = self.reader.nan_no_returns();
        let (at, count, first, first_nan) = match self.dense_with_nan {
            Some((at, count, first, first_nan)) => (at, count + 1, first, first_nan),
            None => {
                self.warnings.push(String::new());
                (self.warnings.len() - 1, 1, index, nan)
            }
        };
        self.dense_with_nan = Some((at, count, first, first_nan));
        self.warnings[at] = format!(
            "warning: {count} message(s) of `{topic}` declare is_dense = true but hold NaN points (first: message \
             {first}, {first_nan} points); read as no-returns (not ground, kept in place)"
        );
    }
}
