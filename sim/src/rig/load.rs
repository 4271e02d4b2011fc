//! Loading rigs by preset name or from TOML files, and validating them.

use std::path::Path;

use super::{Mount, Rig, presets};
use crate::error::{Result, SimError, check_range};

/// Largest number of sensors on one rig (sensor ids are `u8`, `u8::MAX` means "none").
pub const MAX_SENSORS: usize = 254;
/// Largest mount offset from the vehicle origin along any axis, metres.
pub const MAX_MOUNT_OFFSET_M: f64 = 100.0;

impl Mount {
    /// Checks that the position is finite and within +-100 m and the angles within +-360 deg;
    /// `field` is the dotted prefix for error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        let lim = MAX_MOUNT_OFFSET_M;
        check_range(&format!("{field}.x_m"), self.x_m as f64, -lim, lim)?;
        check_range(&format!("{field}.y_m"), self.y_m as f64, -lim, lim)?;
        check_range(&format!("{field}.z_m"), self.z_m as f64, -lim, lim)?;
        check_range(&format!("{field}.roll_deg"), self.roll_deg as f64, -360.0, 360.0)?;
        check_range(&format!("{field}.pitch_deg"), self.pitch_deg as f64, -360.0, 360.0)?;
        check_range(&format!("{field}.yaw_deg"), self.yaw_deg as f64, -360.0, 360.0)
    }
}

impl Rig {
    /// The built-in rig `name` (one of [`presets::PRESETS`]; the mounts are documented in
    /// [`presets`]). An unknown name gives [`SimError::UnknownName`] listing the known ones.
    pub fn preset(name: &str) -> Result<Rig> {
        presets::preset(name)
    }

    /// Loads a rig: a path ending in `.toml` is read with [`Rig::from_toml_str`], anything else is a
    /// preset name.
    pub fn load(name_or_path: &str) -> Result<Rig> {
        if name_or_path.ends_with(".toml") {
            let text = std::fs::read_to_string(name_or_path).map_err(|e| SimError::io(name_or_path, e))?;
            Rig::from_toml_str(&text, name_or_path)
        } else {
            Rig::preset(name_or_path)
        }
    }

    /// Parses and validates a rig TOML document. Syntax errors, unknown fields and wrong types give
    /// [`SimError::Toml`] with `path_for_errors` and the parser's message (field, line and column);
    /// out-of-range values give [`SimError::InvalidParameter`] naming the field, e.g.
    /// `sensors[1].spec.frequency_hz`. A missing `name` becomes the file stem of `path_for_errors`.
    pub fn from_toml_str(text: &str, path_for_errors: impl AsRef<Path>) -> Result<Rig> {
        let path = path_for_errors.as_ref();
        let mut rig: Rig =
            toml::from_str(text).map_err(|e| SimError::Toml { path: path.to_path_buf(), message: e.to_string() })?;
        if rig.name.is_empty() {
            rig.name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        }
        rig.validate()?;
        Ok(rig)
    }

    /// The rig as a TOML document that [`Rig::from_toml_str`] reads back to an equal rig.
    pub fn to_toml_string(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| SimError::invalid("rig", &self.name, format!("serialisable to TOML ({e})")))
    }

    /// Checks the rig: a non-empty name, 1 ..= 254 sensors with unique non-empty names, valid
    /// mounts and valid sensor parameters (errors name the field, e.g. `sensors[0].mount.z_m`).
    pub fn validate(&self) -> Result<()> {
        if self.name.trim().is_empty() {
            return Err(SimError::invalid("name", "\"\"", "a non-empty rig name"));
        }
        let n = self.sensors.len();
        if !(1..=MAX_SENSORS).contains(&n) {
            return Err(SimError::invalid("sensors", format!("{n} sensors"), format!("1 ..= {MAX_SENSORS} sensors")));
        }
        for (i, s) in self.sensors.iter().enumerate() {
            if s.name.trim().is_empty() {
                return Err(SimError::invalid(format!("sensors[{i}].name"), "\"\"", "a non-empty name"));
            }
            if self.sensors[..i].iter().any(|o| o.name == s.name) {
                return Err(SimError::invalid(format!("sensors[{i}].name"), &s.name, "a name unique within the rig"));
            }
            s.mount.validate(&format!("sensors[{i}].mount"))?;
            s.spec.validate(&format!("sensors[{i}].spec"))?;
        }
        Ok(())
    }
}
