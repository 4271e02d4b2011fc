//! The learned method's model and its JSON file: gradient-boosted **oblivious** (symmetric) trees
//! on the features of [`super::features`], trained by hessboost ([`super::train`]).
//!
//! ```json
//! { "format": "groundtruth-learned-oblivious-trees", "version": 1,
//!   "features": ["normal_z", ..., "row_step_m"],
//!   "base_margin": -0.12, "threshold": 0.5,
//!   "trees": [ { "features": [6, 2, 9], "thresholds": [0.21, 0.55, 0.08], "leaves": [8 numbers] }, ... ],
//!   "trained_on": { free-form }, "training": { free-form } }
//! ```
//!
//! A tree of depth `d` asks one question per level (level 0 first): is feature `features[l]` at
//! least `thresholds[l]`? The answers, level 0 the most significant bit, index its `2^d` leaves.
//! The margin of a feature vector is `base_margin` plus one leaf of every tree; its ground
//! probability the logistic of the margin; it is ground where the probability is above
//! `threshold`. Loading refuses, with a [`LearnedModelError`] naming the file, a missing or
//! unreadable file, invalid or truncated JSON, another format or version, another feature list, a
//! tree whose arrays disagree or whose depth is over [`MAX_DEPTH`], a feature index out of range,
//! and any non-finite number (JSON `null`, as NaN is written). Saving is atomic.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::features::{FEATURE_COUNT, FEATURE_NAMES};
use crate::model_file::{self, ModelFileError, ModelKind};

/// The `format` of a model file.
pub const MODEL_FORMAT: &str = "groundtruth-learned-oblivious-trees";
/// The model file version this build reads and writes.
pub const MODEL_VERSION: u32 = 1;
/// The learned method's model files.
const KIND: ModelKind = ModelKind { format: MODEL_FORMAT, version: MODEL_VERSION, method: "learned" };
/// The deepest tree a model may hold.
pub const MAX_DEPTH: usize = 10;
/// The most trees a model may hold.
pub const MAX_TREES: usize = 100_000;

/// Why a model file was refused; `path` names the file (`<built-in>` for the bundled model).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LearnedModelError {
    /// The file could not be read, parsed or written, or holds another format or version.
    #[error(transparent)]
    File(#[from] ModelFileError),
    /// Another feature list.
    #[error("model file {path}: features {found:?}, this build computes {expected:?}")]
    Features {
        /// The file.
        path: String,
        /// The list found.
        found: Vec<String>,
        /// The list expected.
        expected: Vec<&'static str>,
    },
    /// A tree or number that cannot be used.
    #[error("model file {path}: {message}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
}

/// One oblivious tree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObliviousTree {
    /// The feature asked about at each level, level 0 first.
    pub features: Vec<u8>,
    /// The threshold of each level: the answer is 1 where the feature is at least this.
    pub thresholds: Vec<f32>,
    /// `2^depth` leaf values, indexed by the answers (level 0 the most significant bit).
    pub leaves: Vec<f32>,
}

impl ObliviousTree {
    /// The tree's depth.
    pub fn depth(&self) -> usize {
        self.features.len()
    }

    /// The leaf of feature vector `x`.
    ///
    /// ```
    /// use classifier::learned::model::ObliviousTree;
    /// let t = ObliviousTree { features: vec![0, 1], thresholds: vec![0.5, 2.0], leaves: vec![1.0, 2.0, 3.0, 4.0] };
    /// let mut x = [0.0f32; classifier::learned::features::FEATURE_COUNT];
    /// assert_eq!(t.leaf(&x), 1.0);
    /// x[0] = 0.5; // at the threshold: 1
    /// assert_eq!(t.leaf(&x), 3.0);
    /// x[1] = 7.0;
    /// assert_eq!(t.leaf(&x), 4.0);
    /// ```
    pub fn leaf(&self, x: &[f32; FEATURE_COUNT]) -> f32 {
        let mut idx = 0usize;
        for (&f, &t) in self.features.iter().zip(&self.thresholds) {
            idx = 2 * idx + usize::from(x[f as usize] >= t);
        }
        self.leaves[idx]
    }
}

/// The model: the trees, their base margin and the decision threshold.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnedModel {
    /// Always [`MODEL_FORMAT`].
    pub format: String,
    /// Always [`MODEL_VERSION`].
    pub version: u32,
    /// The feature names, [`FEATURE_NAMES`].
    pub features: Vec<String>,
    /// The margin before any tree (logit of the prior).
    pub base_margin: f32,
    /// Ground where the ground probability is above this (0 < threshold < 1).
    pub threshold: f32,
    /// The trees.
    pub trees: Vec<ObliviousTree>,
    /// What the model was trained on (free-form, for people).
    #[serde(default)]
    pub trained_on: serde_json::Value,
    /// How it was trained: library, parameters, time (free-form, for people).
    #[serde(default)]
    pub training: serde_json::Value,
}

impl LearnedModel {
    /// A model of `trees` with the current format, version and features.
    pub fn new(base_margin: f32, threshold: f32, trees: Vec<ObliviousTree>) -> Self {
        Self {
            format: MODEL_FORMAT.to_string(),
            version: MODEL_VERSION,
            features: FEATURE_NAMES.iter().map(|s| s.to_string()).collect(),
            base_margin,
            threshold,
            trees,
            trained_on: serde_json::Value::Null,
            training: serde_json::Value::Null,
        }
    }

    /// The margin of feature vector `x` (the logit of its ground probability).
    pub fn margin(&self, x: &[f32; FEATURE_COUNT]) -> f32 {
        self.trees.iter().fold(self.base_margin, |m, t| m + t.leaf(x))
    }

    /// The margin above which a cell is ground: the logit of `threshold`.
    pub fn margin_threshold(&self) -> f32 {
        (self.threshold / (1.0 - self.threshold)).ln()
    }

    /// Parses and checks a model; `path` names it in errors.
    pub fn from_json_str(text: &str, path: &str) -> Result<Self, LearnedModelError> {
        let model: LearnedModel = model_file::typed(model_file::parse(text, path, &KIND)?, path)?;
        model.check(path)?;
        Ok(model)
    }

    /// Checks features, trees and numbers.
    pub fn check(&self, path: &str) -> Result<(), LearnedModelError> {
        let invalid = |message: String| LearnedModelError::Invalid { path: path.to_string(), message };
        if self.features.iter().map(String::as_str).ne(FEATURE_NAMES.iter().copied()) {
            return Err(LearnedModelError::Features {
                path: path.to_string(),
                found: self.features.clone(),
                expected: FEATURE_NAMES.to_vec(),
            });
        }
        if !self.base_margin.is_finite() {
            return Err(invalid("`base_margin` is not a finite number".to_string()));
        }
        if !(self.threshold.is_finite() && self.threshold > 0.0 && self.threshold < 1.0) {
            return Err(invalid(format!("`threshold` = {}: allowed 0 < threshold < 1", self.threshold)));
        }
        if self.trees.is_empty() || self.trees.len() > MAX_TREES {
            return Err(invalid(format!("{} trees: allowed 1 ..= {MAX_TREES}", self.trees.len())));
        }
        for (k, t) in self.trees.iter().enumerate() {
            let d = t.depth();
            if d == 0 || d > MAX_DEPTH {
                return Err(invalid(format!("tree {k}: depth {d}, allowed 1 ..= {MAX_DEPTH}")));
            }
            if t.thresholds.len() != d || t.leaves.len() != 1 << d {
                return Err(invalid(format!(
                    "tree {k}: {} features, {} thresholds and {} leaves (a depth-{d} tree has {d}, {d} and {})",
                    d,
                    t.thresholds.len(),
                    t.leaves.len(),
                    1usize << d
                )));
            }
            if let Some(f) = t.features.iter().find(|&&f| f as usize >= FEATURE_COUNT) {
                return Err(invalid(format!("tree {k}: feature {f} out of range 0 ..< {FEATURE_COUNT}")));
            }
            if t.thresholds.iter().chain(&t.leaves).any(|x| !x.is_finite()) {
                return Err(invalid(format!("tree {k}: a threshold or leaf is not a finite number")));
            }
        }
        Ok(())
    }

    /// Reads a model file.
    pub fn load(path: &Path) -> Result<Self, LearnedModelError> {
        let (name, text) = model_file::read(path)?;
        Self::from_json_str(&text, &name)
    }

    /// The model as JSON text.
    pub fn to_json_string(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// Writes the model atomically (a temporary file, then a rename).
    pub fn save(&self, path: &Path) -> Result<(), LearnedModelError> {
        Ok(model_file::write(path, &self.to_json_string())?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> LearnedModel {
        LearnedModel::new(
            -0.5,
            0.5,
            vec![
                ObliviousTree { features: vec![6], thresholds: vec![0.3], leaves: vec![2.0, -2.0] },
                ObliviousTree { features: vec![3, 0], thresholds: vec![0.5, 0.9], leaves: vec![-1.0, -0.5, 0.5, 1.0] },
            ],
        )
    }

    #[test]
    fn margins_add_one_leaf_per_tree() {
        let m = model();
        let mut x = [0.0f32; FEATURE_COUNT];
        x[3] = 1.0;
        x[0] = 0.95;
        assert_eq!(m.margin(&x), -0.5 + 2.0 + 1.0);
        x[6] = 0.4;
        assert_eq!(m.margin(&x), -0.5 - 2.0 + 1.0);
        assert_eq!(m.margin_threshold(), 0.0);
    }

    #[test]
    fn bad_files_are_refused_naming_the_file_and_the_problem() {
        let m = model();
        let text = m.to_json_string();
        assert_eq!(LearnedModel::from_json_str(&text, "m.json").unwrap(), m);
        let cases = [
            (text[..text.len() / 2].to_string(), "invalid model JSON"),
            (text.replace(MODEL_FORMAT, "groundtruth-mcdaniel-linear-svm"), "a model of the `learned` method"),
            (text.replace("\"version\":1", "\"version\":2"), "version 2"),
            (text.replace("\"normal_z\"", "\"z\""), "features"),
            (text.replace("\"base_margin\":-0.5", "\"base_margin\":null"), "invalid model JSON"),
            (text.replace("\"threshold\":0.5", "\"threshold\":1.5"), "threshold"),
            (text.replace("[2.0,-2.0]", "[2.0]"), "tree 0"),
            (text.replace("\"features\":[6]", "\"features\":[60]"), "out of range"),
            (text.replace("\"trees\":[", "\"extra\":1,\"trees\":["), "unknown field"),
        ];
        for (bad, needle) in cases {
            let e = LearnedModel::from_json_str(&bad, "m.json").unwrap_err().to_string();
            assert!(e.contains("m.json") && e.contains(needle), "{e} (expected `{needle}`)");
        }
        let e = LearnedModel::load(Path::new("/no/such/model.json")).unwrap_err().to_string();
        assert!(e.contains("/no/such/model.json") && e.contains("cannot read"), "{e}");
    }

    #[test]
    fn saving_and_loading_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.json");
        model().save(&path).unwrap();
        assert_eq!(LearnedModel::load(&path).unwrap(), model());
    }
}
