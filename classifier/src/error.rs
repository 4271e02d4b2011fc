//! Typed errors of the classifier: bad clouds are refused with a message that says what is wrong.

/// Errors the classifier returns for clouds or parameters it cannot work with.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ClassifyError {
    /// A field's length disagrees with the grid size `planes * rows * cols`.
    #[error("inconsistent cloud: {0}")]
    Inconsistent(String),
    /// A grid too small for 8-neighbourhoods (fewer than two rows or columns, or no planes).
    #[error("grid {rows} x {cols} x {planes} is too small: the features need at least 2 rows and 2 columns")]
    TooSmall {
        /// Rows of the grid.
        rows: usize,
        /// Columns of the grid.
        cols: usize,
        /// Echo planes of the grid.
        planes: usize,
    },
    /// A parameter outside its allowed range.
    #[error("invalid value for `{field}`: {value} (allowed: {allowed})")]
    InvalidParameter {
        /// Name of the parameter.
        field: &'static str,
        /// The offending value, formatted.
        value: String,
        /// The allowed range.
        allowed: &'static str,
    },
    /// A method name that is not in [`crate::METHODS`].
    #[error("unknown method `{name}`; known: {known}")]
    UnknownMethod {
        /// The name given.
        name: String,
        /// Comma-separated known names.
        known: String,
    },
    /// A method that needs something the frame does not carry (e.g. a vehicle pose).
    #[error("method `{method}` needs {what}")]
    Missing {
        /// Method name.
        method: &'static str,
        /// What is missing.
        what: &'static str,
    },
    /// A training (or ROC) set without ground or without non-ground points.
    #[error("training set has {ground} ground and {non_ground} non-ground candidates: both classes are needed")]
    TrainingSet {
        /// Ground (positive) points.
        ground: usize,
        /// Non-ground (negative) points.
        non_ground: usize,
    },
    /// A model file (or model) that cannot be used.
    #[error(transparent)]
    Model(#[from] crate::mcdaniel::ModelError),
    /// A learned-method model file (or model) that cannot be used.
    #[error(transparent)]
    LearnedModel(#[from] crate::learned::LearnedModelError),
    /// Training failed in the learning library.
    #[error("training: {0}")]
    Training(String),
    /// A flat cloud whose rings cannot be recovered without its sensor (no ring field, neither scan
    /// order nor firing order).
    #[error(transparent)]
    NoOrder(#[from] crate::ordering::RecoveryError),
    /// A beam table or unordered cloud that ordering recovery cannot use.
    #[error("ordering recovery: {0}")]
    Ordering(String),
}

impl ClassifyError {
    /// Shorthand for [`ClassifyError::InvalidParameter`].
    pub fn invalid(field: &'static str, value: impl std::fmt::Display, allowed: &'static str) -> Self {
        ClassifyError::InvalidParameter { field, value: value.to_string(), allowed }
    }
}

/// Result alias of the classifier.
pub type Result<T, E = ClassifyError> = std::result::Result<T, E>;

/// Checks that a cloud's grid agrees with its data and is large enough for the features.
/// Clouds with no returns at all pass (every point is then simply non-ground).
pub fn check_cloud(cloud: &sim::OrderedCloud) -> Result<()> {
    cloud.check_consistent().map_err(ClassifyError::Inconsistent)?;
    if cloud.rows < 2 || cloud.cols < 2 || cloud.planes == 0 {
        return Err(ClassifyError::TooSmall { rows: cloud.rows, cols: cloud.cols, planes: cloud.planes });
    }
    Ok(())
}

/// [`check_cloud`], and that `out` holds one decision per cell of `cloud` (all planes).
pub fn check_cloud_and_output(cloud: &sim::OrderedCloud, out: &[bool]) -> Result<()> {
    check_cloud(cloud)?;
    if out.len() != cloud.len() {
        return Err(ClassifyError::Inconsistent(format!("output has {} entries, cloud {}", out.len(), cloud.len())));
    }
    Ok(())
}

/// Whether cell `i` holds a usable return: a point with three finite coordinates. Cells whose range
/// is finite but whose coordinates are NaN (corrupt input) are treated as no return.
#[inline]
pub fn is_valid(point: glam::Vec3) -> bool {
    point.is_finite()
}
