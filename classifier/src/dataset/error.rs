//! Errors of reading and scoring labelled datasets: each names the file, folder or flag at fault.

use std::path::PathBuf;

/// What is wrong with a dataset directory, a frame or an evaluation's options.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    /// The directory is not in the SemanticKITTI layout.
    #[error(
        "`{dir}`: not a SemanticKITTI-layout dataset (expected `sequences/NN/velodyne/*.bin` or `velodyne/*.bin` in it) nor a nuScenes-lidarseg folder (`lidar/*.pcd.bin` and `lidarseg/*_lidarseg.bin`)"
    )]
    NotADataset {
        /// The directory given.
        dir: PathBuf,
    },
    /// A sequence without a `labels/` folder.
    #[error("`{dir}`: no `labels/` folder beside `velodyne/`: scoring needs labels")]
    NoLabels {
        /// The sequence folder.
        dir: PathBuf,
    },
    /// A cloud without its label file.
    #[error("`{bin}`: no label file `{label}`")]
    MissingLabel {
        /// The cloud.
        bin: PathBuf,
        /// The label file it needs.
        label: PathBuf,
    },
    /// A sequence without frames.
    #[error("`{dir}`: the sequence holds no `.bin` frames (`.pcd.bin` in a nuScenes-lidarseg folder's `lidar/`)")]
    EmptySequence {
        /// The `velodyne/` folder.
        dir: PathBuf,
    },
    /// `--sequences` names a sequence the dataset does not hold.
    #[error("--sequences: no sequence `{id}` in `{dir}` (it holds: {known})")]
    UnknownSequence {
        /// The id asked for.
        id: String,
        /// The dataset root.
        dir: PathBuf,
        /// The sequences it holds.
        known: String,
    },
    /// A `.bin` whose length is not a whole number of 16-byte records.
    #[error("`{path}`: {bytes} bytes is not a whole number of 16-byte x y z intensity records (truncated?)")]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Its length.
        bytes: u64,
    },
    /// A `.label` whose entry count differs from its cloud's point count.
    #[error("`{label}` holds {labels} labels but `{bin}` {points} points")]
    LabelCount {
        /// The label file.
        label: PathBuf,
        /// Its entries.
        labels: usize,
        /// The cloud.
        bin: PathBuf,
        /// Its points.
        points: usize,
    },
    /// A class id that SemanticKITTI does not define, given as ground or ignored.
    #[error(
        "{flag}: class id {id} is not a SemanticKITTI label id (known: 0, 1, 10, ..., 99, 252-259; see `groundtruth list`) nor WADS's 110 (falling snow) or 111 (accumulated snow)"
    )]
    UnknownClass {
        /// The flag or field.
        flag: &'static str,
        /// The id.
        id: u32,
    },
    /// A bad option value.
    #[error("{flag} = {value}: {allowed}")]
    Invalid {
        /// The flag or field.
        flag: &'static str,
        /// The value given.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// A file its reader refused (the error names it and what is wrong).
    #[error(transparent)]
    File(#[from] sim::SimError),
    /// Reading a file failed.
    #[error("`{path}`: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A recording that could not be read (the error names it).
    #[error(transparent)]
    Recording(Box<crate::recording::RecordingError>),
    /// Ordering or classifying a frame failed.
    #[error("`{path}`: {source}")]
    Classify {
        /// The frame's cloud.
        path: PathBuf,
        /// The error.
        source: crate::ClassifyError,
    },
}

impl From<crate::recording::RecordingError> for DatasetError {
    /// A labelled dataset's error as it was (the reader of labelled frames gives its errors as
    /// [`crate::recording::RecordingError::Dataset`]), any other wrapped.
    fn from(e: crate::recording::RecordingError) -> Self {
        match e {
            crate::recording::RecordingError::Dataset(e) => *e,
            e => DatasetError::Recording(Box::new(e)),
        }
    }
}
