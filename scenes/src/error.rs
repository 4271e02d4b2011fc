//! Typed errors of the scene library: unknown names, TOML syntax and schema errors, parameters
//! out of range, and user mesh files that are missing or malformed.

use std::path::PathBuf;

/// Everything that can go wrong while loading or generating a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A name that is neither a bundled scene nor an existing `.toml` file.
    #[error("unknown scene `{name}`; bundled scenes: {known} (or give a path to a .toml file)")]
    UnknownScene {
        /// The name given.
        name: String,
        /// Comma-separated bundled scene names.
        known: String,
    },
    /// A `family` that is not one of the generator families.
    #[error("{source_name}: unknown family `{family}`; known families: {known}")]
    UnknownFamily {
        /// File (or bundled name) the description came from.
        source_name: String,
        /// The family given.
        family: String,
        /// Comma-separated family names.
        known: String,
    },
    /// The TOML parser or the schema rejected the file (the message names the field, line and column).
    #[error("{source_name}: {message}")]
    Toml {
        /// File (or bundled name) the description came from.
        source_name: String,
        /// The parser's message.
        message: String,
    },
    /// A schema version this build does not read.
    #[error("{source_name}: unsupported scene schema `version = {version}` (this build reads version = 1)")]
    Version {
        /// File (or bundled name) the description came from.
        source_name: String,
        /// The version given.
        version: i64,
    },
    /// A parameter outside its allowed range.
    #[error("invalid value for `{field}`: {value} (allowed: {allowed})")]
    InvalidParameter {
        /// Dotted name of the field, e.g. `params.slope_deg`.
        field: String,
        /// The offending value.
        value: String,
        /// The allowed range.
        allowed: String,
    },
    /// A user mesh file that does not exist or cannot be read.
    #[error("mesh file {path}: {message}")]
    MeshFile {
        /// Resolved path of the mesh file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The scene file itself could not be read ([`sim::SimError::Io`], naming the file).
    #[error(transparent)]
    Sim(#[from] sim::SimError),
}

impl SceneError {
    /// Shorthand for [`SceneError::InvalidParameter`].
    pub fn invalid(field: impl Into<String>, value: impl std::fmt::Display, allowed: impl Into<String>) -> Self {
        SceneError::InvalidParameter { field: field.into(), value: value.to_string(), allowed: allowed.into() }
    }
}

/// Checks that `value` is finite and within `lo ..= hi`; otherwise names `params.<field>` and the range.
pub fn check(field: &str, value: f32, lo: f32, hi: f32) -> Result<(), SceneError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(SceneError::invalid(format!("params.{field}"), value, format!("{lo} ..= {hi}")))
    }
}

/// Checks that an integer count is within `lo ..= hi`, naming `params.<field>` otherwise.
pub fn check_count(field: &str, value: u32, lo: u32, hi: u32) -> Result<(), SceneError> {
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(SceneError::invalid(format!("params.{field}"), value, format!("{lo} ..= {hi}")))
    }
}
