//! A custom spinning sensor built from a TOML table of beams.
//!
//! ```toml
//! model = "custom"
//! columns = 1024
//! frequency_hz = 10.0
//! [[beams]]
//! elevation_deg = -10.0
//! azimuth_offset_deg = 1.5      # optional, default 0 (positive left)
//! origin_offset_m = [0.0, 0.0, 0.05]  # optional, head frame, default 0
//! time_offset_s = 0.0           # optional, after the firing-cycle start, default 0
//! [measurement]                 # optional overrides of the defaults below
//! range_sigma_m = 0.02
//! ```
//!
//! Rows are the beams sorted by elevation (stable: beams of equal elevation keep their table order).
//! Each revolution has `columns` firing cycles of `1 / (frequency_hz * columns)`; the grid is
//! destaggered and origin offsets turn with the head (see [`super::spinning`]).
//!
//! Measurement defaults: 0.5 .. 100 m, sigma 0.02 m, no quantisation, grazing dropout beyond
//! 89 deg, divergence 3 mrad, one echo, echo separation 1 m, intensity reference 10 m.

use serde::{Deserialize, Serialize};

use super::measure::{MeasurementParams, validate_measurement};
use super::spinning::{Laser, spinning_pattern};
use super::{Measurement, ScanPattern};
use crate::error::{Result, SimError, check_range};

/// Largest number of beams of a custom sensor.
pub const CUSTOM_MAX_BEAMS: usize = 1024;
/// Largest number of columns of a custom sensor.
pub const CUSTOM_MAX_COLUMNS: u32 = 65_536;
/// Largest number of cells (beams x columns) of a custom sensor.
pub const CUSTOM_MAX_CELLS: usize = 16 * 1024 * 1024;

/// One beam of a custom sensor.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CustomBeam {
    /// Elevation, degrees (-90 < x < 90).
    pub elevation_deg: f32,
    /// Azimuth offset from the encoder angle, degrees (positive left; -180 ..= 180; default 0).
    #[serde(default)]
    pub azimuth_offset_deg: f32,
    /// Beam origin in the head frame (x along the beam azimuth, y left, z up), metres (default 0;
    /// each component -1 ..= 1).
    #[serde(default)]
    pub origin_offset_m: [f32; 3],
    /// Firing time after the start of the firing cycle, seconds (0 ..< frame period; default 0).
    #[serde(default)]
    pub time_offset_s: f32,
}

/// A custom spinning sensor (TOML `model = "custom"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CustomSpec {
    /// Columns (firing cycles) per revolution (1 ..= 65536; default 1024).
    pub columns: u32,
    /// Rotation rate, Hz (0.1 ..= 100; default 10).
    pub frequency_hz: f32,
    /// The beams (1 ..= 1024). Default: 32 beams from -15 to +16 deg in 1 deg steps.
    pub beams: Vec<CustomBeam>,
    /// Overrides of the measurement defaults.
    pub measurement: MeasurementParams,
}

impl Default for CustomSpec {
    fn default() -> Self {
        Self {
            columns: 1024,
            frequency_hz: 10.0,
            beams: (0..32)
                .map(|i| CustomBeam {
                    elevation_deg: -15.0 + i as f32,
                    azimuth_offset_deg: 0.0,
                    origin_offset_m: [0.0; 3],
                    time_offset_s: 0.0,
                })
                .collect(),
            measurement: MeasurementParams::default(),
        }
    }
}

impl CustomSpec {
    /// Checks the parameters; `field` is the dotted prefix for error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        if !(1..=CUSTOM_MAX_COLUMNS).contains(&self.columns) {
            return Err(SimError::invalid(
                format!("{field}.columns"),
                self.columns,
                format!("1 ..= {CUSTOM_MAX_COLUMNS}"),
            ));
        }
        check_range(&format!("{field}.frequency_hz"), self.frequency_hz as f64, 0.1, 100.0)?;
        let n = self.beams.len();
        if !(1..=CUSTOM_MAX_BEAMS).contains(&n) {
            return Err(SimError::invalid(
                format!("{field}.beams"),
                format!("{n} beams"),
                format!("1 ..= {CUSTOM_MAX_BEAMS} beams"),
            ));
        }
        if n * self.columns as usize > CUSTOM_MAX_CELLS {
            return Err(SimError::invalid(
                format!("{field}.columns"),
                self.columns,
                format!("beams x columns <= {CUSTOM_MAX_CELLS}"),
            ));
        }
        let period_s = 1.0 / self.frequency_hz as f64;
        for (i, b) in self.beams.iter().enumerate() {
            let name = |n: &str| format!("{field}.beams[{i}].{n}");
            let el = b.elevation_deg;
            if !(el.is_finite() && el > -90.0 && el < 90.0) {
                return Err(SimError::invalid(name("elevation_deg"), el, "-90 < x < 90"));
            }
            check_range(&name("azimuth_offset_deg"), b.azimuth_offset_deg as f64, -180.0, 180.0)?;
            for (k, v) in b.origin_offset_m.iter().enumerate() {
                check_range(&format!("{field}.beams[{i}].origin_offset_m[{k}]"), *v as f64, -1.0, 1.0)?;
            }
            let t = b.time_offset_s;
            if !(t.is_finite() && t >= 0.0 && (t as f64) < period_s) {
                return Err(SimError::invalid(
                    name("time_offset_s"),
                    t,
                    format!("0 <= x < frame period ({period_s} s)"),
                ));
            }
        }
        validate_measurement(&format!("{field}.measurement"), &self.measurement())
    }

    /// The lasers sorted by elevation (row order).
    pub fn lasers(&self) -> Vec<Laser> {
        let mut lasers: Vec<Laser> = self
            .beams
            .iter()
            .map(|b| Laser {
                elevation_rad: (b.elevation_deg as f64).to_radians(),
                azimuth_offset_rad: (b.azimuth_offset_deg as f64).to_radians(),
                origin_in_head_m: b.origin_offset_m.map(|v| v as f64),
                time_offset_s: b.time_offset_s as f64,
            })
            .collect();
        lasers.sort_by(|a, b| a.elevation_rad.total_cmp(&b.elevation_rad));
        lasers
    }

    /// The beams of one revolution.
    pub fn pattern(&self) -> ScanPattern {
        spinning_pattern(&self.lasers(), self.columns as usize, self.frequency_hz as f64)
    }

    /// The default measurement with overrides applied.
    pub fn measurement(&self) -> Measurement {
        self.measurement.apply(Measurement::spinning(0.5, 100.0, 0.02, 0.0))
    }
}
