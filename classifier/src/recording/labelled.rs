//! A labelled dataset read as a recording: a SemanticKITTI-layout directory (`sequences/NN/` with
//! `velodyne/` and `labels/`, or one sequence's folder) or a nuScenes-lidarseg folder (`lidar/` with
//! `lidarseg/`), listed by [`DatasetLayout`], its frames read sequence by sequence, each with its
//! points and classes in file order ([`LabelledPoints`]); the reading and ordering of a labelled
//! frame is [`super::FrameReader::read_labelled`].
//!
//! ```
//! use classifier::recording::{Ordering, Recording};
//! let dir = tempfile::tempdir()?;
//! let seq = dir.path().join("sequences/04");
//! std::fs::create_dir_all(seq.join("velodyne"))?;
//! std::fs::create_dir_all(seq.join("labels"))?;
//! let point: Vec<u8> = [10.0f32, 0.0, -1.7, 0.5].iter().flat_map(|v| v.to_le_bytes()).collect();
//! std::fs::write(seq.join("velodyne/000000.bin"), &point)?;
//! std::fs::write(seq.join("labels/000000.label"), 40u32.to_le_bytes())?;
//! let recording = Recording::open(dir.path(), None)?;
//! let mut frames = recording.frames(Ordering::AsStored)?;
//! let frame = frames.next_frame().expect("one frame")?;
//! let labelled = frame.labelled.expect("a labelled frame");
//! assert_eq!(labelled.points.classes, [sim::SemanticClass(40)]);
//! assert_eq!(frame.provenance.sequence.as_deref(), Some("04"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::{Frames, InputFile, Ordering, Provenance, RecordingError};
use crate::dataset::{DatasetLayout, FramePoints, LabelledFrame};

/// A labelled dataset's frame, as [`super::Frame::labelled`] gives it.
#[derive(Clone, Copy, Debug)]
pub struct LabelledPoints<'a> {
    /// The frame's files (its `.bin` and its labels), its sequence and its stem.
    pub frame: &'a LabelledFrame,
    /// Its place in its sequence (0 on).
    pub index_in_sequence: usize,
    /// Its points in file order (`x y z intensity`, sensor frame) with their classes
    /// (SemanticKITTI ids) and, for nuScenes records, their rings; the layout the `.bin` was read in.
    pub points: &'a FramePoints,
}

/// A labelled dataset as a recording's source: the listing, each frame's cloud file (the
/// recording's files, indexed by place in the recording) and where each frame sits in it.
#[derive(Debug)]
pub(super) struct DatasetSource {
    /// The listing.
    pub(super) layout: DatasetLayout,
    /// Each frame's cloud file, sequence by sequence.
    pub(super) files: Vec<InputFile>,
    /// Each frame's sequence (by place) and place in it.
    places: Vec<(usize, usize)>,
}

impl DatasetSource {
    /// The source of `layout`'s frames.
    pub(super) fn new(layout: DatasetLayout) -> Self {
        let mut places = Vec::new();
        for (s, sequence) in layout.sequences.iter().enumerate() {
            places.extend((0..sequence.frames.len()).map(|k| (s, k)));
        }
        let files = layout
            .frames()
            .enumerate()
            .map(|(index, f)| InputFile { index, path: f.bin.clone(), world_from_vehicle: None })
            .collect();
        Self { layout, files, places }
    }

    /// The frame at place `ordinal` of the recording, with its place in its sequence.
    pub(super) fn frame(&self, ordinal: usize) -> Option<(usize, &LabelledFrame)> {
        let &(s, k) = self.places.get(ordinal)?;
        Some((k, self.layout.sequences.get(s)?.frames.get(k)?))
    }
}

impl<'r> Frames<'r> {
    /// Reads and orders (or keeps as stored) the frame at place `ordinal` of the labelled dataset
    /// `dataset`, its provenance naming its sequence and `.bin`; returns the milliseconds of the
    /// read, `None` past the last frame.
    pub(super) fn read_labelled(
        &mut self,
        dataset: &'r DatasetSource,
        ordinal: usize,
    ) -> Option<Result<f64, RecordingError>> {
        let (_, frame) = dataset.frame(ordinal)?;
        let setup = match self.ordering {
            Ordering::Ordered(setup) => Some(setup),
            Ordering::AsStored => None,
        };
        Some(self.reader.read_labelled(frame, setup).inspect(|_| {
            let (layout, basis) = self.reader.layout();
            self.provenance = Provenance::sequence_file(frame.bin.clone(), &frame.sequence, layout, basis);
        }))
    }

    /// The last frame read of the labelled dataset `dataset`, with its points and classes.
    pub(super) fn labelled(&self, dataset: &'r DatasetSource) -> Option<LabelledPoints<'_>> {
        let (index_in_sequence, frame) = dataset.frame(self.next_file.checked_sub(1)?)?;
        let points = self.reader.labelled_points()?;
        Some(LabelledPoints { frame, index_in_sequence, points })
    }
}
