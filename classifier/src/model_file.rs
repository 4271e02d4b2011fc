//! What the methods' model files share: reading the file, parsing its JSON and checking its
//! `format` and `version` before the typed parse (so that another method's model is named as
//! such), saving atomically, and the errors of each, naming the file.

use std::path::Path;

use serde::de::DeserializeOwned;

/// A kind of model file: the `format` it holds, the version this build reads and writes, and the
/// method it belongs to.
pub(crate) struct ModelKind {
    /// The `format` field.
    pub(crate) format: &'static str,
    /// The `version` field.
    pub(crate) version: u32,
    /// The method whose model it is (`mcdaniel`, `learned`).
    pub(crate) method: &'static str,
}

/// Why a model file could not be read, parsed or written, whatever its method; `path` names the
/// file (`<built-in>` for a bundled model).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ModelFileError {
    /// The file could not be read (missing, permissions).
    #[error("model file {path}: cannot read: {message}")]
    Read {
        /// The file.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// The file could not be written.
    #[error("model file {path}: cannot write: {message}")]
    Write {
        /// The file.
        path: String,
        /// The message.
        message: String,
    },
    /// Not valid JSON (e.g. truncated), not an object, or a field of the wrong type, missing or
    /// unknown.
    #[error("model file {path}: invalid model JSON: {message}")]
    Json {
        /// The file.
        path: String,
        /// The parser's message (line and column).
        message: String,
    },
    /// Another `format` (e.g. a McDaniel model given to the learned method).
    #[error("model file {path}: format `{found}`, expected `{expected}` (a model of the `{method}` method)")]
    Format {
        /// The file.
        path: String,
        /// The format found.
        found: String,
        /// The format expected.
        expected: &'static str,
        /// The method that reads the expected format.
        method: &'static str,
    },
    /// Another `version`.
    #[error("model file {path}: version {found}, this build reads version {expected}")]
    Version {
        /// The file.
        path: String,
        /// The version found.
        found: String,
        /// The version this build reads.
        expected: u32,
    },
}

/// The text of the model file `path`, and the name that errors give it.
pub(crate) fn read(path: &Path) -> Result<(String, String), ModelFileError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| ModelFileError::Read { path: name.clone(), message: e.to_string() })?;
    Ok((name, text))
}

/// Parses `text` (named `path` in errors) as a JSON object whose `format` and `version` are those
/// of `kind`; returns the object for the method's own checks and typed parse ([`typed`]).
pub(crate) fn parse(
    text: &str,
    path: &str,
    kind: &ModelKind,
) -> Result<serde_json::Map<String, serde_json::Value>, ModelFileError> {
    let json = |message: String| ModelFileError::Json { path: path.to_string(), message };
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| json(e.to_string()))?;
    let serde_json::Value::Object(obj) = value else {
        return Err(json("the top level is not a JSON object".into()));
    };
    match obj.get("format") {
        Some(serde_json::Value::String(f)) if f == kind.format => {}
        Some(other) => {
            return Err(ModelFileError::Format {
                path: path.to_string(),
                found: other.as_str().map_or_else(|| other.to_string(), str::to_string),
                expected: kind.format,
                method: kind.method,
            });
        }
        None => return Err(json("missing field `format`".into())),
    }
    match obj.get("version") {
        Some(v) if v.as_u64() == Some(u64::from(kind.version)) => {}
        Some(v) => {
            return Err(ModelFileError::Version {
                path: path.to_string(),
                found: v.to_string(),
                expected: kind.version,
            });
        }
        None => return Err(json("missing field `version`".into())),
    }
    Ok(obj)
}

/// The typed model of a checked object ([`parse`]).
pub(crate) fn typed<T: DeserializeOwned>(
    obj: serde_json::Map<String, serde_json::Value>,
    path: &str,
) -> Result<T, ModelFileError> {
    serde_json::from_value(serde_json::Value::Object(obj))
        .map_err(|e| ModelFileError::Json { path: path.to_string(), message: e.to_string() })
}

/// Writes `text` to the model file `path` atomically (a temporary file, then a rename).
pub(crate) fn write(path: &Path, text: &str) -> Result<(), ModelFileError> {
    sim::io::atomic::write_bytes_atomic(path, text.as_bytes())
        .map_err(|e| ModelFileError::Write { path: path.display().to_string(), message: e.to_string() })
}
