//! Velodyne spinning sensors: VLP-16 (interleaved firing order) and HDL-64E S2/S3 (non-uniform
//! elevation table, per-laser azimuth and origin offsets). Both use the destaggered grid of
//! [`super::spinning`].

use serde::{Deserialize, Serialize};

use super::measure::{MeasurementParams, UNSTATED_DETECTION_REFLECTANCE, validate_measurement};
use super::spinning::{Laser, columns_per_revolution, spinning_pattern};
use super::{Measurement, ScanPattern};
use crate::error::{Result, check_range};

/// VLP-16 time between two lasers of one firing sequence, seconds.
pub const VLP16_LASER_SPACING_S: f64 = 2.304e-6;
/// VLP-16 firing cycle (16 firings plus recharge), seconds.
pub const VLP16_CYCLE_S: f64 = 55.296e-6;

/// Velodyne VLP-16 (TOML `model = "vlp16"`).
///
/// 16 lasers at -15 .. +15 deg in 2 deg steps, fired every [`VLP16_LASER_SPACING_S`] in the
/// interleaved order -15, +1, -13, +3, ..., -1, +15 (firing slot `n` has elevation `n - 15` deg for
/// even `n` and `n` deg for odd `n`); one firing cycle is [`VLP16_CYCLE_S`]. Columns = firing
/// cycles per revolution rounded to the nearest integer (1808 at 10 Hz, 904 at 20 Hz, 3617 at
/// 5 Hz; see [`super::spinning`] for how the cycle is stretched to fit). No azimuth offsets: the
/// 16 firings of one cycle span 0.13 deg at 10 Hz and all fall in one column.
///
/// Measurement defaults: 0.5 .. 100 m, sigma 0.03 m, 2 mm quantum (the packet's distance unit),
/// grazing dropout beyond 89 deg, divergence 3 mrad, one echo (the dual-return mode: set
/// `measurement.max_echoes = 2`), echo separation 1 m, intensity reference 10 m.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Vlp16Spec {
    /// Rotation rate, Hz (5 ..= 20; default 10).
    pub frequency_hz: f32,
    /// Overrides of the measurement defaults.
    pub measurement: MeasurementParams,
}

impl Default for Vlp16Spec {
    fn default() -> Self {
        Self { frequency_hz: 10.0, measurement: MeasurementParams::default() }
    }
}

impl Vlp16Spec {
    /// Elevation of firing slot `n` (0..16) of the interleaved order, degrees.
    pub fn slot_elevation_deg(n: usize) -> f64 {
        if n.is_multiple_of(2) { n as f64 - 15.0 } else { n as f64 }
    }

    /// Number of columns at this rotation rate.
    pub fn columns(&self) -> usize {
        columns_per_revolution(VLP16_CYCLE_S, self.frequency_hz as f64)
    }

    /// Checks the parameters; `field` is the dotted prefix for error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        check_range(&format!("{field}.frequency_hz"), self.frequency_hz as f64, 5.0, 20.0)?;
        validate_measurement(&format!("{field}.measurement"), &self.measurement())
    }

    /// The beams of one revolution (rows sorted by elevation: row `r` is -15 + 2 r deg).
    pub fn pattern(&self) -> ScanPattern {
        let mut lasers: Vec<Laser> = (0..16)
            .map(|n| Laser {
                elevation_rad: Self::slot_elevation_deg(n).to_radians(),
                azimuth_offset_rad: 0.0,
                origin_in_head_m: [0.0; 3],
                time_offset_s: n as f64 * VLP16_LASER_SPACING_S,
            })
            .collect();
        lasers.sort_by(|a, b| a.elevation_rad.total_cmp(&b.elevation_rad));
        spinning_pattern(&lasers, self.columns(), self.frequency_hz as f64)
    }

    /// The default measurement with overrides applied.
    pub fn measurement(&self) -> Measurement {
        self.measurement
            .apply(Measurement::spinning(0.5, 100.0, 0.03, 0.002).with_detection(100.0, UNSTATED_DETECTION_REFLECTANCE))
    }
}

/// HDL-64E firing cycle: each laser fires at about 20.8 kHz, seconds.
pub const HDL64E_CYCLE_S: f64 = 48.0e-6;

/// The HDL-64E S2/S3 elevation table of `sensors.md`, sorted, degrees (32 lower-block lasers, then
/// 32 upper-block lasers).
pub const HDL64E_ELEVATIONS_DEG: [f64; 64] = [
    -24.71, -24.28, -23.76, -23.25, -22.74, -22.23, -21.71, -21.20, -20.69, -20.18, -19.67, -19.16, -18.56, -18.14,
    -17.63, -17.12, -16.62, -16.11, -15.60, -15.09, -14.58, -14.07, -13.56, -13.05, -12.54, -12.03, -11.51, -11.00,
    -10.49, -9.98, -9.46, -8.95, -8.52, -8.18, -7.84, -7.50, -7.16, -6.82, -6.48, -6.14, -5.80, -5.46, -5.12, -4.78,
    -4.44, -4.10, -3.76, -3.42, -3.08, -2.74, -2.40, -2.06, -1.72, -1.38, -1.04, -0.70, -0.36, -0.02, 0.32, 0.66, 1.00,
    1.34, 1.68, 2.02,
];

/// Representative per-laser azimuth offsets of the HDL-64E, degrees (positive left), cycled by
/// laser index within each block. The real values come from each unit's calibration file, which
/// we do not have; these span the -8.5 .. +9.9 deg of `sensors.md` the way the real ones do
/// (the lasers sit in four columns of the two lens groups).
const HDL64E_AZIMUTH_PATTERN_DEG: [[f64; 4]; 2] = [[-8.5, -3.1, 2.9, 8.2], [-7.6, -2.5, 4.3, 9.9]];

/// Velodyne HDL-64E S2/S3 (TOML `model = "hdl64e"`).
///
/// Rows are the 64 elevations of [`HDL64E_ELEVATIONS_DEG`], exact. Each laser also has an azimuth
/// offset and an origin offset from a **representative** calibration (see
/// [`Hdl64eSpec::calibration`]): the real table is per unit. All 64 lasers fire once per
/// [`HDL64E_CYCLE_S`] (the two blocks fire in parallel; their 1-2 us internal sequence is
/// neglected), which is 0.1728 deg at 10 Hz; columns = cycles per revolution rounded to the
/// nearest integer: 2083 at 10 Hz (360 / 2083 = 0.17283 deg per column), 4167 at 5 Hz, 1389 at
/// 15 Hz. The grid is destaggered (see [`super::spinning`]).
///
/// Measurement defaults: 0.9 .. 120 m (the 80 % reflectivity range), sigma 0.02 m, 2 mm quantum,
/// grazing dropout beyond 89 deg, divergence 2 mrad, one echo, echo separation 1 m, intensity
/// reference 12 m.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Hdl64eSpec {
    /// Rotation rate, Hz (5 ..= 15; default 10).
    pub frequency_hz: f32,
    /// Overrides of the measurement defaults.
    pub measurement: MeasurementParams,
}

impl Default for Hdl64eSpec {
    fn default() -> Self {
        Self { frequency_hz: 10.0, measurement: MeasurementParams::default() }
    }
}

impl Hdl64eSpec {
    /// The representative calibration, sorted by elevation (row order): laser `i` of block `b`
    /// (`b = 0` lower, `1` upper; `j = i mod 32`) has azimuth offset
    /// `HDL64E_AZIMUTH_PATTERN_DEG[b][j mod 4]`, a horizontal origin offset of +2.6 cm (left of the
    /// beam) for a positive azimuth offset and -2.6 cm otherwise, and a vertical origin offset
    /// rising linearly from 0.14 to 0.16 m (lower block) and 0.20 to 0.22 m (upper block).
    pub fn calibration() -> Vec<Laser> {
        HDL64E_ELEVATIONS_DEG
            .iter()
            .enumerate()
            .map(|(i, &el)| {
                let block = i / 32;
                let j = i % 32;
                let az = HDL64E_AZIMUTH_PATTERN_DEG[block][j % 4];
                let horizontal = if az > 0.0 { 0.026 } else { -0.026 };
                let vertical = [0.14, 0.20][block] + 0.02 * j as f64 / 31.0;
                Laser {
                    elevation_rad: el.to_radians(),
                    azimuth_offset_rad: az.to_radians(),
                    origin_in_head_m: [0.0, horizontal, vertical],
                    time_offset_s: 0.0,
                }
            })
            .collect()
    }

    /// Number of columns at this rotation rate.
    pub fn columns(&self) -> usize {
        columns_per_revolution(HDL64E_CYCLE_S, self.frequency_hz as f64)
    }

    /// Checks the parameters; `field` is the dotted prefix for error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        check_range(&format!("{field}.frequency_hz"), self.frequency_hz as f64, 5.0, 15.0)?;
        validate_measurement(&format!("{field}.measurement"), &self.measurement())
    }

    /// The beams of one revolution.
    pub fn pattern(&self) -> ScanPattern {
        spinning_pattern(&Self::calibration(), self.columns(), self.frequency_hz as f64)
    }

    /// The default measurement with overrides applied.
    pub fn measurement(&self) -> Measurement {
        self.measurement.apply(Measurement {
            min_range_m: 0.9,
            max_range_m: 120.0,
            range_sigma_m: 0.02,
            range_quantum_m: 0.002,
            max_incidence_deg: 89.0,
            beam_divergence_rad: 0.002,
            max_echoes: 1,
            echo_separation_m: 1.0,
            intensity_reference_m: 12.0,
            detection_range_m: 50.0,
            detection_reflectance: 0.1,
        })
    }
}
