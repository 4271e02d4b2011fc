//! The one error type of the scenario API: every failure on user input is one of these, never a
//! panic. Messages name the field (or region) and the allowed values.

use std::path::PathBuf;

/// What went wrong while building, scanning or scoring a scenario.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The scene description was rejected (unknown family or name, bad TOML, a parameter out of
    /// range: the message names `params.<field>` and its range).
    #[error("scene: {0}")]
    Scene(#[from] scenes::SceneError),
    /// The simulator rejected the rig or the scan settings (unknown preset, bad rig file, frames or
    /// speed out of range).
    #[error("scan: {0}")]
    Sim(#[from] sim::SimError),
    /// A classification method failed or is unknown.
    #[error("method: {0}")]
    Classify(#[from] classifier::ClassifyError),
    /// A scene or rig file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A scan spec that does not parse (an unknown field, a value of the wrong type).
    #[error("{source_name}: {message}")]
    Spec {
        /// The file or front end it came from.
        source_name: String,
        /// What is wrong, as the parser says it (e.g. "unknown field `colour`, expected one of ...").
        message: String,
    },
    /// A builder setting outside its allowed range.
    #[error("invalid value for `{field}`: {value} (allowed: {allowed})")]
    Invalid {
        /// The setting, e.g. `mount.z_m` or `params.slope_deg`.
        field: String,
        /// The value given, formatted.
        value: String,
        /// The allowed values.
        allowed: String,
    },
    /// A region that only exists in some scene families was asked of another family.
    #[error("region `{region}` needs a `{needs}` scene, this scene's family is `{family}`")]
    RegionFamily {
        /// The region's name.
        region: String,
        /// The family it needs.
        needs: &'static str,
        /// The scene's family.
        family: String,
    },
    /// A region holding no return in any frame: nothing to score (check the rig sees it).
    #[error("region `{region}` holds no return in any of the {frames} frame(s)")]
    EmptyRegion {
        /// The region's name.
        region: String,
        /// Frames searched.
        frames: usize,
    },
    /// Decisions that do not match the scan's frames or cells.
    #[error("decisions: {what} (expected {expected}, got {got})")]
    Shape {
        /// What does not match, e.g. `frames` or `cells of frame 0`.
        what: String,
        /// The expected count.
        expected: usize,
        /// The count given.
        got: usize,
    },
}

impl ScenarioError {
    /// An [`ScenarioError::Invalid`] for `field` = `value`, allowed `allowed`.
    pub fn invalid(field: impl Into<String>, value: impl std::fmt::Display, allowed: impl Into<String>) -> Self {
        Self::Invalid { field: field.into(), value: value.to_string(), allowed: allowed.into() }
    }
}

/// Result with [`ScenarioError`].
pub type Result<T, E = ScenarioError> = std::result::Result<T, E>;
