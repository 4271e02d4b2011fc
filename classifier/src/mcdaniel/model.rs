//! The trained model and its JSON file: a linear SVM on standardised features f1-f8.
//!
//! ```json
//! { "format": "groundtruth-mcdaniel-linear-svm", "version": 1,
//!   "features": ["f1_occupied_columns", ..., "f8_ray_trace_score"],
//!   "feature_params": { "cell_m": 0.5, "pyramid_layers": 4, "max_extent_m": 200.0 },
//!   "mean": [8 numbers], "std": [8 numbers], "weights": [8 numbers], "bias": b, "c": 100.0,
//!   "trained_on": { free-form } }
//! ```
//!
//! The decision value of a feature vector `f` is `sum_k weights[k] * (f[k] - mean[k]) / std[k] + bias`;
//! ground where it is above the decision threshold (0 by default). Loading refuses, with a
//! [`ModelError`] naming the file and the problem, a missing or unreadable file, invalid or
//! truncated JSON, another format or version, a feature list or array of the wrong length,
//! non-finite numbers (JSON `null`, as NaN is written), a std <= 0 and feature parameters out of
//! range. Saving is atomic (temporary file, then rename).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{FEATURE_COUNT, FEATURE_NAMES, FeatureParams};
use crate::model_file::{self, ModelFileError, ModelKind};

/// The `format` of a model file.
pub const MODEL_FORMAT: &str = "groundtruth-mcdaniel-linear-svm";
/// The model file version this build reads and writes.
pub const MODEL_VERSION: u32 = 1;
/// The McDaniel method's model files.
const KIND: ModelKind = ModelKind { format: MODEL_FORMAT, version: MODEL_VERSION, method: "mcdaniel" };

/// Why a model file was refused; `path` names the file (`<built-in>` for the bundled model).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ModelError {
    /// The file could not be read, parsed or written, or holds another format or version.
    #[error(transparent)]
    File(#[from] ModelFileError),
    /// An array with the wrong number of entries, or the wrong feature names.
    #[error("model file {path}: `{field}` has {found} entries, expected {FEATURE_COUNT} ({names})", names = FEATURE_NAMES.join(", "))]
    FeatureCount {
        /// The file.
        path: String,
        /// The field.
        field: &'static str,
        /// Entries found.
        found: usize,
    },
    /// A feature name that is not the expected one.
    #[error("model file {path}: features[{index}] is `{found}`, expected `{expected}`")]
    FeatureName {
        /// The file.
        path: String,
        /// Position in `features`.
        index: usize,
        /// Name found.
        found: String,
        /// Name expected.
        expected: &'static str,
    },
    /// A number that is not finite (NaN and infinities are written as `null` in JSON).
    #[error("model file {path}: `{field}` is not a finite number")]
    NonFinite {
        /// The file.
        path: String,
        /// The field, e.g. `weights[3]`.
        field: String,
    },
    /// A value outside its allowed range.
    #[error("model file {path}: `{field}` = {value} (allowed: {allowed})")]
    Invalid {
        /// The file.
        path: String,
        /// The field.
        field: String,
        /// The value.
        value: String,
        /// The allowed range.
        allowed: String,
    },
}

/// A trained McDaniel model (see the module docs for the file).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct McDanielModel {
    /// Always [`MODEL_FORMAT`].
    pub format: String,
    /// Always [`MODEL_VERSION`].
    pub version: u32,
    /// The feature names, [`FEATURE_NAMES`].
    pub features: Vec<String>,
    /// How the features were computed (must match at classification time).
    pub feature_params: FeatureParams,
    /// Per feature, the training set's mean.
    pub mean: Vec<f64>,
    /// Per feature, the training set's standard deviation (1 where it was 0).
    pub std: Vec<f64>,
    /// Per standardised feature, the SVM weight.
    pub weights: Vec<f64>,
    /// The SVM bias.
    pub bias: f64,
    /// The SVM cost `C` it was trained with.
    pub c: f64,
    /// What it was trained on (free-form).
    #[serde(default)]
    pub trained_on: serde_json::Value,
}

impl McDanielModel {
    /// The decision value of one feature vector: `w . standardised(f) + b`.
    pub fn decision_value(&self, f: &[f32; FEATURE_COUNT]) -> f64 {
        let mut v = self.bias;
        for (k, &fk) in f.iter().enumerate() {
            v += self.weights[k] * ((f64::from(fk) - self.mean[k]) / self.std[k]);
        }
        v
    }

    /// Parses and checks a model from JSON text; `path` names the source in errors.
    pub fn from_json_str(text: &str, path: &str) -> Result<Self, ModelError> {
        let p = || path.to_string();
        let obj = model_file::parse(text, path, &KIND)?;
        // Non-finite numbers are written as `null`: name them before the typed parse.
        for field in ["mean", "std", "weights"] {
            if let Some(serde_json::Value::Array(a)) = obj.get(field)
                && let Some(k) = a.iter().position(serde_json::Value::is_null)
            {
                return Err(ModelError::NonFinite { path: p(), field: format!("{field}[{k}]") });
            }
        }
        for field in ["bias", "c"] {
            if obj.get(field).is_some_and(serde_json::Value::is_null) {
                return Err(ModelError::NonFinite { path: p(), field: field.into() });
            }
        }
        let model: McDanielModel = model_file::typed(obj, path)?;
        model.check(path)?;
        Ok(model)
    }

    /// Checks counts, names, finiteness and ranges; `path` names the source in errors.
    pub fn check(&self, path: &str) -> Result<(), ModelError> {
        let p = || path.to_string();
        if self.features.len() != FEATURE_COUNT {
            return Err(ModelError::FeatureCount { path: p(), field: "features", found: self.features.len() });
        }
        for (index, (found, expected)) in self.features.iter().zip(FEATURE_NAMES).enumerate() {
            if found != expected {
                return Err(ModelError::FeatureName { path: p(), index, found: found.clone(), expected });
            }
        }
        for (field, v) in [("mean", &self.mean), ("std", &self.std), ("weights", &self.weights)] {
            if v.len() != FEATURE_COUNT {
                return Err(ModelError::FeatureCount { path: p(), field, found: v.len() });
            }
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                return Err(ModelError::NonFinite { path: p(), field: format!("{field}[{k}]") });
            }
        }
        for (field, v) in [("bias", self.bias), ("c", self.c)] {
            if !v.is_finite() {
                return Err(ModelError::NonFinite { path: p(), field: field.into() });
            }
        }
        if let Some(k) = self.std.iter().position(|&s| s <= 0.0) {
            return Err(ModelError::Invalid {
                path: p(),
                field: format!("std[{k}]"),
                value: self.std[k].to_string(),
                allowed: "> 0".into(),
            });
        }
        if self.c <= 0.0 {
            return Err(ModelError::Invalid {
                path: p(),
                field: "c".into(),
                value: self.c.to_string(),
                allowed: "> 0".into(),
            });
        }
        self.feature_params.validate().map_err(|e| match e {
            crate::ClassifyError::InvalidParameter { field, value, allowed } => ModelError::Invalid {
                path: p(),
                field: format!("feature_params.{field}"),
                value,
                allowed: allowed.into(),
            },
            other => ModelError::Invalid {
                path: p(),
                field: "feature_params".into(),
                value: other.to_string(),
                allowed: String::new(),
            },
        })
    }

    /// Loads and checks a model file.
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        let (name, text) = model_file::read(path)?;
        Self::from_json_str(&text, &name)
    }

    /// The model as pretty JSON.
    pub fn to_json_string(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).unwrap_or_default();
        s.push('\n');
        s
    }

    /// Checks the model and writes it atomically to `path`.
    pub fn save(&self, path: &Path) -> Result<(), ModelError> {
        let name = path.display().to_string();
        self.check(&name)?;
        Ok(model_file::write(path, &self.to_json_string())?)
    }
}
