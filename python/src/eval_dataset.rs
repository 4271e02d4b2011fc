//! `eval_dataset()`: our methods scored on a labelled SemanticKITTI-layout recording, as
//! `groundtruth eval --dataset` scores them, returning the same numbers as its `--json` file (a
//! dict), with the GIL released while it runs.

use std::path::PathBuf;

use classifier::dataset::{DatasetError, DatasetLayout, EvalOptions, Protocol, evaluate, report};
use classifier::ordering::SensorSetup;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::{classify_error, value_error};

/// A dataset error as `FileNotFoundError` (missing files, folders and labels), `OSError` (reading)
/// or `ValueError` (bad options, counts, classes), naming the file or option.
fn dataset_error(e: DatasetError) -> PyErr {
    use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
    match e {
        DatasetError::NotADataset { .. }
        | DatasetError::NoLabels { .. }
        | DatasetError::MissingLabel { .. }
        | DatasetError::EmptySequence { .. } => PyFileNotFoundError::new_err(e.to_string()),
        DatasetError::Io { .. } => PyOSError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// Scores our methods on the labelled recording in `path` (a dataset root with
/// `sequences/NN/{velodyne,labels}`, or one sequence's folder), every frame read as
/// `groundtruth classify` reads a `.bin` (ordered with `rig`'s beam table and mount, or
/// `calibration`'s; a dataset written by `groundtruth dataset` without either: each sequence's own
/// rig), under `protocol` (`semantickitti`, `patchworkpp`, `patchwork`; `ground` replaces its ground
/// class ids, `ignore` leaves more classes out, e.g. `[110]`, WADS's falling snow). Returns a dict
/// `{"dataset", "protocol", "range_bands", "methods": {name: {"pooled": {"precision", "recall", "f1", "iou", "accuracy", "tp", "fp", "tn", "fn", "points"},
/// "frame_mean", "by_range", "worst_frame", "mean_classify_ms", "frames": [...]}}}`, the document of
/// `groundtruth eval --dataset --json`. A folder of nuScenes sweeps with their lidarseg labels
/// (`lidar/NAME.pcd.bin`, `lidarseg/NAME_lidarseg.bin`) is scored too; `layout` (`"kitti"`,
/// `"nuscenes"`) names the records of the `.bin` files (default: by name and content).
#[pyfunction]
#[pyo3(signature = (path, methods=vec!["nitsch".to_string(), "learned".to_string()], *, rig=None, calibration=None, protocol="semantickitti", ground=None, ignore=None, sensor_height_m=1.73, sequences=None, max_frames=None, model=None, layout=None))]
#[allow(clippy::too_many_arguments)]
pub fn eval_dataset<'py>(
    py: Python<'py>,
    path: PathBuf,
    methods: Vec<String>,
    rig: Option<String>,
    calibration: Option<PathBuf>,
    protocol: &str,
    ground: Option<Vec<u32>>,
    ignore: Option<Vec<u32>>,
    sensor_height_m: f32,
    sequences: Option<Vec<String>>,
    max_frames: Option<usize>,
    model: Option<PathBuf>,
    layout: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let layout_choice =
        layout.map(classifier::recording::LayoutChoice::named).transpose().map_err(|e| value_error("layout", e))?;
    if methods.is_empty() {
        return Err(value_error("methods", format!("empty; known: {}", classifier::METHODS.join(", "))));
    }
    if max_frames == Some(0) {
        return Err(value_error("max_frames", "0: allowed 1 or more"));
    }
    let mut proto = Protocol::named(protocol, sensor_height_m).map_err(dataset_error)?;
    if let Some(g) = &ground {
        proto = proto.with_ground(g).map_err(dataset_error)?;
    }
    if let Some(i) = &ignore {
        proto = proto.with_ignored(i).map_err(dataset_error)?;
    }
    // Unknown methods and bad models are refused before any frame is read; each model file is
    // read once, every instance (one per sequence) built from it.
    let resolved: Vec<classifier::registry::ResolvedMethod> = methods
        .iter()
        .map(|m| {
            let model = model.as_deref().filter(|_| classifier::takes_model(m));
            classifier::registry::resolve(m, &classifier::MethodOptions { seed: 0, model })
        })
        .collect::<Result<_, _>>()
        .map_err(crate::classify::method_error)?;
    let rig_value = match &rig {
        Some(r) => Some(sim::Rig::load(r).map_err(|e| value_error("rig", e))?),
        None => None,
    };
    let setup = SensorSetup::new(rig_value.as_ref(), calibration.as_deref()).map_err(classify_error)?;
    let layout = DatasetLayout::open(&path, sequences.as_deref()).map_err(dataset_error)?;
    let sequence_setups = if rig.is_none() && calibration.is_none() {
        classifier::dataset::ours::sequence_setups(&path).map_err(dataset_error)?
    } else {
        None
    };
    let doc = py.detach(|| -> Result<serde_json::Value, DatasetError> {
        let options = EvalOptions {
            setup: &setup,
            sequence_setups: sequence_setups.as_ref(),
            protocol: &proto,
            max_frames_per_sequence: max_frames,
            layout: layout_choice,
        };
        let make = |name: &str| -> classifier::Result<Box<dyn classifier::GroundClassifier + Send>> {
            match resolved.iter().find(|r| r.name() == name) {
                Some(r) => r.build(),
                None => classifier::method_by_name(name, 0),
            }
        };
        let scores = evaluate(&layout, &methods, &make, &options, |_| Ok(()))?;
        let mut doc = report(&path, &proto, rig.as_deref(), calibration.as_deref(), &scores);
        if layout.format != classifier::dataset::FrameFormat::SemanticKitti {
            doc["format"] = serde_json::json!(layout.format);
        }
        Ok(doc)
    });
    let doc = doc.map_err(dataset_error)?;
    // Through Python's json module: plain dicts, lists, floats and None.
    let text = serde_json::to_string(&doc).map_err(|e| value_error("result", e))?;
    let json = py.import("json")?;
    let out = json.call_method1("loads", (text,))?;
    let _: &Bound<'py, PyDict> = out.cast()?;
    Ok(out)
}
