//! Labelled recordings in the SemanticKITTI layout, real or ours, or nuScenes sweeps with their
//! lidarseg labels, and the scores of ground
//! classification methods on them under a named protocol.
//!
//! - [`layout`]: which sequences and frames a directory holds (`DIR/sequences/NN/{velodyne,labels}`
//!   or one sequence's `velodyne/` and `labels/`, or a nuScenes-lidarseg folder), and decoding a
//!   frame's `.bin` and `.label` in file order;
//! - [`protocol`]: what counts as ground, what is ignored (`semantickitti`, `patchworkpp`,
//!   `patchwork`);
//! - [`score`]: per-point confusion counts per frame and pooled, with range bands;
//! - [`evaluate`]: every frame read and ordered once through [`crate::recording::Recording`] (the
//!   one reader of recordings: a dataset is a recording, [`crate::recording::Recording::open`]
//!   recognises its folders, [`crate::recording::FrameReader::read_labelled`] reads and orders a
//!   labelled frame), each method run on it, each decision scored in the file's own point order;
//! - [`ours`]: a dataset `groundtruth dataset` wrote orders each sequence with its own rig.
//!
//! Frames are read as a user's recording is ([`crate::ordering::SensorSetup::order_kitti`]): scan
//! unfolding, the beam table, or an organized sensor image, with `--rig` / `--calibration`.

mod error;
pub mod evaluate;
pub mod layout;
pub mod ours;
pub mod protocol;
pub mod score;

pub use error::DatasetError;
pub use evaluate::{EvalOptions, FrameView, evaluate, report};
pub use layout::{DatasetLayout, FrameFormat, FramePoints, LabelledFrame, Sequence};
pub use protocol::Protocol;
pub use score::{FrameScore, MethodScore, RANGE_BAND_EDGES_M};
