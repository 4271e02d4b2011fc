//! Typed errors of the simulator.

use std::path::PathBuf;

/// Errors the simulator returns for bad input or failed I/O.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A parameter outside its allowed range (field name, value, allowed range).
    #[error("invalid value for `{field}`: {value} (allowed: {allowed})")]
    InvalidParameter {
        /// Dotted name of the field, e.g. `sensors[0].max_range_m`.
        field: String,
        /// The offending value, formatted.
        value: String,
        /// Human-readable allowed range, e.g. `0.0 < x <= 1000.0`.
        allowed: String,
    },
    /// A name that is not one of the known presets.
    #[error("unknown {kind} `{name}`; known: {known}")]
    UnknownName {
        /// What was looked up (`scene`, `rig`, `sensor model`).
        kind: &'static str,
        /// The name given.
        name: String,
        /// Comma-separated known names.
        known: String,
    },
    /// A TOML file that failed to parse (the message names the field and line).
    #[error("{path}: {message}")]
    Toml {
        /// File that failed.
        path: PathBuf,
        /// Parser message with line and column.
        message: String,
    },
    /// A file that is malformed, truncated or inconsistent.
    #[error("{path}: {message}")]
    BadFile {
        /// File that failed.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// An I/O error on a named file.
    #[error("{path}: {source}")]
    Io {
        /// File involved.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
}

impl SimError {
    /// Shorthand for [`SimError::InvalidParameter`].
    pub fn invalid(field: impl Into<String>, value: impl std::fmt::Display, allowed: impl Into<String>) -> Self {
        SimError::InvalidParameter { field: field.into(), value: value.to_string(), allowed: allowed.into() }
    }

    /// Shorthand for [`SimError::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        SimError::Io { path: path.into(), source }
    }

    /// Shorthand for [`SimError::BadFile`].
    pub fn bad_file(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        SimError::BadFile { path: path.into(), message: message.into() }
    }
}

/// Checks that `value` is finite and within `[lo, hi]`, naming `field` otherwise.
pub fn check_range(field: &str, value: f64, lo: f64, hi: f64) -> Result<(), SimError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(SimError::invalid(field, value, format!("{lo} ..= {hi}")))
    }
}

/// Result alias of the simulator.
pub type Result<T, E = SimError> = std::result::Result<T, E>;
