//! `classify()`: our ground classification methods by name (the registry of `classifier`), with
//! the GIL released.

use std::path::PathBuf;
use std::sync::Arc;

use classifier::{FrameInput, GroundClassifier};
use groundtruth_scenario::Scan;
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::error::{classify_error, value_error};
use crate::frame::{frames_arg, grid_array};

/// A method that could not be resolved, as a Python exception naming what is wrong: `ValueError`
/// for an unknown name or a model given to a method that takes none, `FileNotFoundError` for a
/// missing model file, the model's own error (`ValueError`, `OSError`) for one that cannot be
/// loaded.
pub fn method_error(e: classifier::MethodError) -> PyErr {
    use classifier::MethodError;
    match e {
        MethodError::TakesNoModel { .. } => value_error("model", e),
        MethodError::ModelMissing { .. } => pyo3::exceptions::PyFileNotFoundError::new_err(format!("model: {e}")),
        MethodError::McDanielModel(m) => classify_error(classifier::ClassifyError::Model(m)),
        MethodError::LearnedModel(m) => classify_error(classifier::ClassifyError::LearnedModel(m)),
        MethodError::Build { error, .. } => classify_error(error),
        MethodError::Unknown { .. } => value_error("method", e),
    }
}

/// The method `name` with its default parameters, as the command line builds it
/// ([`classifier::method`]): `model` is a trained model file for `mcdaniel` (default: the bundled
/// forest model) or `learned` (default: the bundled model); RANSAC is seeded with the frame index.
pub fn method(name: &str, model: Option<&PathBuf>) -> PyResult<Box<dyn GroundClassifier + Send>> {
    classifier::method(name, &classifier::MethodOptions { seed: 0, model: model.map(PathBuf::as_path) })
        .map_err(method_error)
}

/// Classifies `frame` with our method `method` (`groundtruth.METHODS`: `nitsch`, `ransac`, `grid`,
/// `mcdaniel`, `learned`, ...); returns the decisions as a bool `(H, W)` array, True = ground (False
/// where no return). Given a list of frames, one method instance classifies them in order and a
/// list of arrays comes back (`grid` accumulates its map over the frames, as `groundtruth classify`
/// does on a directory). `model`: a trained `mcdaniel` or `learned` model file. The GIL is released
/// while it runs.
#[pyfunction]
#[pyo3(signature = (frame, method="nitsch", model=None))]
pub fn classify<'py>(
    py: Python<'py>,
    frame: &Bound<'py, PyAny>,
    method: &str,
    model: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut m = self::method(method, model.as_ref())?;
    let (frames, single) = frames_arg(frame, "a Frame or a list of Frames")?;
    let work: Vec<(Arc<Scan>, usize)> = frames.iter().map(|f| (f.get().scan.clone(), f.get().k)).collect();
    let decisions = py
        .detach(move || {
            work.iter()
                .map(|(scan, k)| {
                    let f = &scan.frames()[*k];
                    let input =
                        FrameInput { index: f.index, cloud: &f.cloud, world_from_vehicle: Some(f.world_from_vehicle) };
                    m.classify(&input)
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .map_err(classify_error)?;
    let arrays: Vec<Bound<'py, PyAny>> =
        frames.iter().zip(decisions).map(|(f, d)| grid_array(py, d, f.get().grid(), None)).collect::<PyResult<_>>()?;
    if single {
        if let Some(a) = arrays.into_iter().next() {
            return Ok(a);
        }
        return Err(value_error("frame", "no decisions came back"));
    }
    Ok(PyList::new(py, arrays)?.into_any())
}
