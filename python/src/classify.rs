//! `classify()`: our ground classification methods by name (the registry of `classifier`), with
//! the GIL released.

use std::path::PathBuf;

use classifier::{FrameInput, GroundClassifier};
use pyo3::prelude::*;

use crate::error::{classify_error, value_error};
use crate::frame::{Frame, grid_array};

/// The method `name` with its default parameters, as the command line builds it: `model` is a
/// trained model file for `mcdaniel` (default: the bundled forest model); RANSAC is seeded with
/// the frame index.
fn method(name: &str, model: Option<&PathBuf>) -> PyResult<Box<dyn GroundClassifier + Send>> {
    match model {
        None => classifier::method_by_name(name, 0).map_err(classify_error),
        Some(path) if name == "mcdaniel" => {
            if !path.is_file() {
                return Err(pyo3::exceptions::PyFileNotFoundError::new_err(format!(
                    "model: {}: no such file",
                    path.display()
                )));
            }
            let model = classifier::McDanielModel::load(path)
                .map_err(|e| classify_error(classifier::ClassifyError::Model(e)))?;
            classifier::mcdaniel_with_model(model, classifier::McDanielParams::default()).map_err(classify_error)
        }
        Some(path) => {
            Err(value_error("model", format!("`{}` applies to `mcdaniel` only, not to `{name}`", path.display())))
        }
    }
}

/// Classifies `frame` with our method `method` (`groundtruth.METHODS`: `nitsch`, `ransac`, `grid`,
/// `mcdaniel`, ...); returns the decisions as a bool `(H, W)` array, True = ground (False where no
/// return). `model`: a trained `mcdaniel` model file. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (frame, method="nitsch", model=None))]
pub fn classify<'py>(
    py: Python<'py>,
    frame: &Frame,
    method: &str,
    model: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut m = self::method(method, model.as_ref())?;
    let scan = frame.scan.clone();
    let k = frame.k;
    let decisions = py
        .detach(move || {
            let f = &scan.frames()[k];
            let input = FrameInput { index: f.index, cloud: &f.cloud, world_from_vehicle: Some(f.world_from_vehicle) };
            m.classify(&input)
        })
        .map_err(classify_error)?;
    grid_array(py, decisions, frame.grid(), None)
}
