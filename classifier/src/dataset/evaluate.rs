//! Scoring methods on a labelled dataset: every frame is read and ordered once, through the
//! recordings' reader as a user's recording is ([`Recording::from_dataset`],
//! [`crate::recording::FrameReader::read_labelled`]: [`SensorSetup::order_kitti`]; a nuScenes sweep
//! from its rings, [`SensorSetup::order_flat`]), every method classifies it, and each decision is
//! scored per input point in the file's own order ([`crate::ordering::decisions_per_point`]),
//! under a [`Protocol`], by range from the sensor (the file's own coordinates).

use std::time::Instant;

use sim::OrderedCloud;

use super::DatasetError;
use super::layout::{DatasetLayout, LabelledFrame};
use super::protocol::Protocol;
use super::score::{FrameScore, MethodScore};
use crate::methods::{FrameInput, GroundClassifier};
use crate::ordering::{OrderingReport, SensorSetup};
use crate::recording::{Ordering, Provenance, Recording};

/// How to evaluate.
#[derive(Clone, Debug)]
pub struct EvalOptions<'a> {
    /// Orders the frames (rig, calibration).
    pub setup: &'a SensorSetup,
    /// Sequences ordered with a setup of their own (a dataset of ours: each sequence's rig and
    /// mount from its manifest), by sequence id.
    pub sequence_setups: Option<&'a std::collections::BTreeMap<String, SensorSetup>>,
    /// What counts as ground and what is left out.
    pub protocol: &'a Protocol,
    /// Score only the first frames of each sequence (`None`: all).
    pub max_frames_per_sequence: Option<usize>,
    /// The layout of SemanticKITTI-layout `.bin` files (`--layout`; `None`: by name and content,
    /// [`crate::recording::InputLayout::decide`]).
    pub layout: Option<crate::recording::LayoutChoice>,
}

/// One classified frame, handed to the caller (pictures, progress).
pub struct FrameView<'a> {
    /// The frame's files.
    pub frame: &'a LabelledFrame,
    /// The ordered cloud the methods ran on (labels from the `.label`).
    pub cloud: &'a OrderedCloud,
    /// What ordering did.
    pub report: &'a OrderingReport,
    /// The cloud file's layout and what decided it.
    pub layout: (crate::recording::InputLayout, crate::recording::LayoutBasis),
    /// Where the frame came from (its sequence and `.bin`, the layout it was read in).
    pub provenance: &'a Provenance,
    /// The method.
    pub method: &'a str,
    /// Its decisions per cell of `cloud`.
    pub ground: &'a [bool],
    /// Its scores on the frame.
    pub score: &'a FrameScore,
}

/// Scores `methods` on every frame of `layout`, each sequence's first frames read as a recording
/// of their own ([`DatasetLayout::part`], [`Recording::from_dataset`]). `make` builds a method by
/// name, afresh for each sequence (methods that keep state across frames, such as the grid map,
/// start over); `on_frame` sees each classified frame. Returns one [`MethodScore`] per method, in
/// the order given.
///
/// ```
/// use classifier::dataset::{evaluate, DatasetLayout, EvalOptions, Protocol};
/// use classifier::ordering::SensorSetup;
/// // A labelled frame of a flat floor 1.7 m below a VLP-16: its eight downward beams (-15 to
/// // -1 deg), in scan order.
/// let dir = tempfile::tempdir()?;
/// let seq = dir.path().join("sequences/00");
/// std::fs::create_dir_all(seq.join("velodyne"))?;
/// std::fs::create_dir_all(seq.join("labels"))?;
/// let (mut bin, mut label) = (Vec::new(), Vec::new());
/// for ring in 0..8 {
///     let el = (-15.0f32 + 2.0 * ring as f32).to_radians();
///     for col in 0..900 {
///         let az = -(col as f32) * std::f32::consts::TAU / 900.0;
///         let t = 1.7 / -el.sin();
///         for v in [t * el.cos() * az.cos(), t * el.cos() * az.sin(), -1.7, 0.5] {
///             bin.extend_from_slice(&f32::to_le_bytes(v));
///         }
///         label.extend_from_slice(&40u32.to_le_bytes());
///     }
/// }
/// std::fs::write(seq.join("velodyne/000000.bin"), bin)?;
/// std::fs::write(seq.join("labels/000000.label"), label)?;
/// let layout = DatasetLayout::open(dir.path(), None)?;
/// let setup = SensorSetup::new(Some(&sim::Rig::load("vlp16-roof")?), None)?;
/// let protocol = Protocol::named("semantickitti", 1.73)?;
/// let options = EvalOptions { setup: &setup, sequence_setups: None, protocol: &protocol, max_frames_per_sequence: None, layout: None };
/// let scores = evaluate(&layout, &["nitsch".to_string()], &|n| classifier::method_by_name(n, 0), &options, |_| Ok(()))?;
/// assert_eq!(scores[0].pooled().tp + scores[0].pooled().fn_, 8 * 900);
/// assert!(scores[0].pooled().recall() > 0.95);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn evaluate(
    layout: &DatasetLayout,
    methods: &[String],
    make: &dyn Fn(&str) -> crate::Result<Box<dyn GroundClassifier + Send>>,
    options: &EvalOptions<'_>,
    mut on_frame: impl FnMut(&FrameView<'_>) -> Result<(), DatasetError>,
) -> Result<Vec<MethodScore>, DatasetError> {
    let mut scores: Vec<MethodScore> =
        methods.iter().map(|m| MethodScore { method: m.clone(), frames: Vec::new() }).collect();
    let classify_error = |frame: &LabelledFrame| {
        let path = frame.bin.clone();
        move |source| DatasetError::Classify { path, source }
    };
    for (k, sequence) in layout.sequences.iter().enumerate() {
        let mut built = Vec::with_capacity(methods.len());
        for m in methods {
            built.push(make(m).map_err(|source| DatasetError::Classify { path: sequence.dir.clone(), source })?);
        }
        let take = options.max_frames_per_sequence.unwrap_or(usize::MAX);
        let setup = options.sequence_setups.and_then(|m| m.get(&sequence.id)).unwrap_or(options.setup);
        let recording = Recording::from_dataset(layout.part(k, 0..take)).with_layout(options.layout)?;
        let mut frames = recording.frames(Ordering::Ordered(setup))?;
        while let Some(read) = frames.next_frame() {
            let read = read?;
            let (Some(labelled), Some(report)) = (read.labelled, read.report) else {
                return Err(DatasetError::Invalid {
                    flag: "--input",
                    value: read.provenance.to_string(),
                    allowed: "a labelled dataset's frame, ordered".to_string(),
                });
            };
            let (frame, index) = (labelled.frame, labelled.index_in_sequence);
            let (records, classes) = (&labelled.points.records, &labelled.points.classes);
            let cloud = read.cloud;
            for (method, score) in built.iter_mut().zip(scores.iter_mut()) {
                let t = Instant::now();
                let ground = method
                    .classify(&FrameInput { index, cloud, world_from_vehicle: None })
                    .map_err(classify_error(frame))?;
                let classify_ms = t.elapsed().as_secs_f64() * 1e3;
                let per_point = read.decisions_per_point(&ground);
                let mut fs = FrameScore {
                    sequence: frame.sequence.clone(),
                    frame: frame.stem.clone(),
                    classify_ms,
                    ..FrameScore::default()
                };
                for ((rec, &class), &decision) in records.iter().zip(classes).zip(&per_point) {
                    let p = glam::Vec3::new(rec[0], rec[1], rec[2]);
                    if p == glam::Vec3::ZERO || !p.is_finite() {
                        fs.no_returns += 1;
                        continue;
                    }
                    fs.add(options.protocol.truth(class.0, p.z), decision == 1, p.length());
                }
                on_frame(&FrameView {
                    frame,
                    cloud,
                    report,
                    layout: labelled.points.layout,
                    provenance: read.provenance,
                    method: &score.method,
                    ground: &ground,
                    score: &fs,
                })?;
                score.frames.push(fs);
            }
        }
    }
    Ok(scores)
}

/// The document of an evaluation, as `groundtruth eval --dataset --json` writes it and the Python
/// package returns it: `{"dataset", "protocol", "rig", "calibration", "range_bands", "methods":
/// {NAME: {"pooled": {"precision", "recall", "f1", "iou", "accuracy", "tp", "fp", "tn", "fn",
/// "points"}, "frame_mean", "by_range", "worst_frame", "mean_classify_ms", "frames": [...]}}}`.
pub fn report(
    dataset: &std::path::Path,
    protocol: &Protocol,
    rig: Option<&str>,
    calibration: Option<&std::path::Path>,
    scores: &[MethodScore],
) -> serde_json::Value {
    use super::score::{RANGE_BANDS, band_name};
    let methods: std::collections::BTreeMap<&str, &MethodScore> =
        scores.iter().map(|s| (s.method.as_str(), s)).collect();
    serde_json::json!({
        "dataset": dataset.display().to_string(),
        "protocol": protocol,
        "rig": rig,
        "calibration": calibration.map(|p| p.display().to_string()),
        "range_bands": (0..RANGE_BANDS).map(band_name).collect::<Vec<_>>(),
        "methods": methods,
    })
}
