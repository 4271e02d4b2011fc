//! Methods by name, with their models resolved once: [`method`] builds a ready classifier,
//! [`resolve`] loads a method's model file once so that many instances can be built from it (one
//! per sequence of a dataset, say) without reading the file again. The one place that decides
//! which methods take a model ([`takes_model`]) and how a model file is loaded; a model that fails
//! to load is a [`MethodError`] naming the file.
//!
//! ```
//! use classifier::registry::{MethodOptions, method, takes_model};
//! let mut nitsch = method("nitsch", &MethodOptions::default())?;
//! assert_eq!(nitsch.name(), "nitsch");
//! assert!(takes_model("learned") && !takes_model("ransac"));
//! let e = method("learned", &MethodOptions { seed: 0, model: Some("no/such/model.json".as_ref()) }).err().unwrap();
//! assert!(e.to_string().contains("no/such/model.json"));
//! # Ok::<(), classifier::registry::MethodError>(())
//! ```

use std::path::{Path, PathBuf};

use crate::error::ClassifyError;
use crate::learned::{LearnedModel, LearnedModelError};
use crate::mcdaniel::{McDanielModel, McDanielParams, ModelError};
use crate::methods::{GroundClassifier, METHODS, learned_with_model, mcdaniel_with_model, method_by_name};

/// The methods that take a trained model file (`--model`, `model=`).
pub const MODEL_METHODS: &[&str] = &["mcdaniel", "learned"];

/// Whether the method `name` takes a trained model file.
pub fn takes_model(name: &str) -> bool {
    MODEL_METHODS.contains(&name)
}

/// How to build a method.
#[derive(Clone, Copy, Debug, Default)]
pub struct MethodOptions<'a> {
    /// Seeds randomized methods (RANSAC).
    pub seed: u64,
    /// A trained model file for a method that takes one ([`takes_model`]); `None`: the bundled
    /// model.
    pub model: Option<&'a Path>,
}

/// Why a method could not be resolved.
#[derive(Debug, thiserror::Error)]
pub enum MethodError {
    /// A name that is not in [`METHODS`].
    #[error("unknown method `{name}`; known: {known}")]
    Unknown {
        /// The name given.
        name: String,
        /// Comma-separated known names.
        known: String,
    },
    /// A model file given to a method that takes none.
    #[error("the model `{}` applies to {}, not to `{method}`", .path.display(), MODEL_METHODS.iter().map(|m| format!("`{m}`")).collect::<Vec<_>>().join(" and "))]
    TakesNoModel {
        /// The method.
        method: String,
        /// The model file.
        path: PathBuf,
    },
    /// A model file that does not exist.
    #[error("model file `{}`: no such file", .path.display())]
    ModelMissing {
        /// The model file.
        path: PathBuf,
    },
    /// A `mcdaniel` model file that could not be loaded (the error names the file).
    #[error(transparent)]
    McDanielModel(#[from] ModelError),
    /// A `learned` model file that could not be loaded (the error names the file).
    #[error(transparent)]
    LearnedModel(#[from] LearnedModelError),
    /// The method could not be built from its model and parameters.
    #[error("method `{method}`: {error}")]
    Build {
        /// The method.
        method: String,
        /// What went wrong.
        error: ClassifyError,
    },
}

/// A method's model, loaded.
#[derive(Clone, Debug)]
enum Model {
    /// The method's bundled model (or it takes none).
    Bundled,
    /// A `mcdaniel` model from a file.
    McDaniel(McDanielModel),
    /// A `learned` model from a file.
    Learned(LearnedModel),
}

/// A method with its model loaded: [`ResolvedMethod::build`] makes instances of it without reading
/// the model file again.
#[derive(Clone, Debug)]
pub struct ResolvedMethod {
    name: String,
    seed: u64,
    model: Model,
}

impl ResolvedMethod {
    /// The method's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// A fresh instance (methods that keep state across frames start over).
    pub fn build(&self) -> crate::Result<Box<dyn GroundClassifier + Send>> {
        match &self.model {
            Model::Bundled => method_by_name(&self.name, self.seed),
            Model::McDaniel(m) => mcdaniel_with_model(m.clone(), McDanielParams::default()),
            Model::Learned(m) => learned_with_model(m.clone()),
        }
    }
}

/// Resolves the method `name` with `options`: checks the name, loads the model file (once) where
/// one is given. Refused: an unknown name, a model given to a method that takes none, a model
/// file that is missing or cannot be loaded (naming the file).
pub fn resolve(name: &str, options: &MethodOptions<'_>) -> Result<ResolvedMethod, MethodError> {
    if !METHODS.contains(&name) {
        return Err(MethodError::Unknown { name: name.to_string(), known: METHODS.join(", ") });
    }
    let model = match options.model {
        None => Model::Bundled,
        Some(path) if !takes_model(name) => {
            return Err(MethodError::TakesNoModel { method: name.to_string(), path: path.to_path_buf() });
        }
        Some(path) if !path.is_file() => return Err(MethodError::ModelMissing { path: path.to_path_buf() }),
        Some(path) if name == "mcdaniel" => Model::McDaniel(McDanielModel::load(path)?),
        Some(path) => Model::Learned(LearnedModel::load(path)?),
    };
    Ok(ResolvedMethod { name: name.to_string(), seed: options.seed, model })
}

/// The method `name`, built with `options` (see [`resolve`]).
pub fn method(name: &str, options: &MethodOptions<'_>) -> Result<Box<dyn GroundClassifier + Send>, MethodError> {
    let resolved = resolve(name, options)?;
    resolved.build().map_err(|error| MethodError::Build { method: name.to_string(), error })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn models_are_resolved_once_and_bad_files_named() {
        let dir = tempfile::tempdir().unwrap();
        let bad = dir.path().join("broken-model.json");
        std::fs::write(&bad, "{ not json").unwrap();
        for name in MODEL_METHODS {
            let e = method(name, &MethodOptions { seed: 0, model: Some(&bad) }).err().expect("refused");
            assert!(e.to_string().contains("broken-model.json"), "{name}: {e}");
            assert!(!e.to_string().contains("ordering"), "{name}: {e}");
            assert!(matches!(e, MethodError::McDanielModel(_) | MethodError::LearnedModel(_)), "{name}: {e:?}");
        }
        let missing = dir.path().join("missing.json");
        let e = resolve("learned", &MethodOptions { seed: 0, model: Some(&missing) }).unwrap_err();
        assert!(matches!(e, MethodError::ModelMissing { .. }) && e.to_string().contains("missing.json"), "{e}");
        let e = resolve("nitsch", &MethodOptions { seed: 0, model: Some(&bad) }).unwrap_err();
        assert!(e.to_string().contains("`mcdaniel` and `learned`, not to `nitsch`"), "{e}");
        let e = resolve("nope", &MethodOptions::default()).unwrap_err();
        assert!(e.to_string().contains("unknown method `nope`"), "{e}");
        // A model saved and resolved once builds instances that decide alike.
        let saved = dir.path().join("learned.json");
        crate::learned::default_model().unwrap().save(&saved).unwrap();
        let resolved = resolve("learned", &MethodOptions { seed: 0, model: Some(&saved) }).unwrap();
        std::fs::remove_file(&saved).unwrap();
        let sensor = crate::synthetic::SyntheticSensor::spinning(16, 360, -15.0, -1.0, 1.8);
        let cloud = sensor.scan(&[crate::synthetic::flat_ground()]);
        let frame = crate::FrameInput { index: 0, cloud: &cloud, world_from_vehicle: None };
        let a = resolved.build().unwrap().classify(&frame).unwrap();
        let b = resolved.build().unwrap().classify(&frame).unwrap();
        assert_eq!(a, b);
        assert!(a.iter().filter(|&&g| g).count() * 10 > a.len() * 9);
    }
}
