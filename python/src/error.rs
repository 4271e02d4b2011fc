//! Rust errors as Python exceptions: every failure on user input becomes `ValueError`, `TypeError`
//! or `OSError` carrying the Rust message (which names the field), never a panic.

use groundtruth_scenario::ScenarioError;
use pyo3::PyErr;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyTypeError, PyValueError};

/// A `ValueError` naming `field`.
pub fn value_error(field: &str, message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{field}: {message}"))
}

/// A `TypeError` naming `field`.
pub fn type_error(field: &str, message: impl std::fmt::Display) -> PyErr {
    PyTypeError::new_err(format!("{field}: {message}"))
}

fn io_error(e: &std::io::Error, message: String) -> PyErr {
    if e.kind() == std::io::ErrorKind::NotFound {
        PyFileNotFoundError::new_err(message)
    } else {
        PyOSError::new_err(message)
    }
}

/// A simulator error: I/O errors become `OSError` (`FileNotFoundError` for a missing file),
/// everything else `ValueError`.
pub fn sim_error(e: sim::SimError) -> PyErr {
    match &e {
        sim::SimError::Io { source, .. } => io_error(source, e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// A scenario error: I/O errors become `OSError`, everything else `ValueError`.
pub fn scenario_error(e: ScenarioError) -> PyErr {
    match e {
        ScenarioError::Io { ref source, .. } => io_error(source, e.to_string()),
        ScenarioError::Sim(s) => sim_error(s),
        ScenarioError::Scene(scenes::SceneError::Sim(sim::SimError::Io { ref source, .. })) => {
            io_error(source, e.to_string())
        }
        e => PyValueError::new_err(e.to_string()),
    }
}

/// A classifier error (unknown method, unreadable model, ...) as `ValueError` (or `OSError` for a
/// model file that cannot be read).
pub fn classify_error(e: classifier::ClassifyError) -> PyErr {
    scenario_error(ScenarioError::Classify(e))
}
