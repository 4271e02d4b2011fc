//! Hokuyo UTM-30LX: a 2-D scanner, 270 deg at 0.25 deg (1081 beams), 40 scans per second.
//!
//! # Steps, columns and time
//! The mirror turns counter-clockwise seen from above at 1440 steps per 25 ms turn (17.36 us per
//! step). Step 0 points at -135 deg (right), step 540 straight ahead, step 1080 at +135 deg
//! (left); step `s` fires `s * 17.36 us` after the scan start. Our columns run left to right, so
//! **column `c` is step `last - c`** and time decreases with the column index. A `fov_deg` subset
//! (e.g. 180 deg, seed 002's sparse scene) keeps the `fov / 0.25 + 1` steps centred on the front
//! (steps 180 ..= 900 = 721 beams at 180 deg); their times keep the full-scan step timing.
//!
//! The sensor frame's origin is the optical centre; a single scan is one row at elevation 0.

use serde::{Deserialize, Serialize};

use super::measure::{MeasurementParams, validate_measurement};
use super::{Firing, Measurement, ScanPattern};
use crate::error::{Result, SimError};

/// Angular step, degrees.
pub const UTM_STEP_DEG: f64 = 0.25;
/// Step of the front beam.
pub const UTM_FRONT_STEP: usize = 540;
/// Duration of one scan (one mirror turn), seconds.
pub const UTM_SCAN_PERIOD_S: f64 = 0.025;
/// Time between two steps: 25 ms / 1440, seconds (17.36 us).
pub const UTM_STEP_TIME_S: f64 = UTM_SCAN_PERIOD_S / 1440.0;

/// One beam of a Hokuyo scan: the step index and the azimuth in the scanner frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UtmBeam {
    /// Step index (0 = -135 deg, 540 = front, 1080 = +135 deg).
    pub step: usize,
    /// Azimuth, radians (positive left).
    pub azimuth_rad: f64,
    /// Time after the scan start, seconds.
    pub time_s: f64,
}

/// Checks a Hokuyo field of view: `0 < fov <= 270` and an even number of 0.25 deg steps (so the
/// beams are centred on the front).
pub fn validate_fov(field: &str, fov_deg: f32) -> Result<()> {
    let half_steps = fov_deg as f64 / (2.0 * UTM_STEP_DEG);
    if !(fov_deg.is_finite() && fov_deg > 0.0 && fov_deg <= 270.0 && (half_steps - half_steps.round()).abs() < 1e-6) {
        return Err(SimError::invalid(format!("{field}.fov_deg"), fov_deg, "0 < x <= 270, a multiple of 0.5"));
    }
    Ok(())
}

/// The beams of a scan with `fov_deg`, in column order (left to right: step decreasing).
pub fn utm_beams(fov_deg: f32) -> Vec<UtmBeam> {
    let half = (fov_deg as f64 / (2.0 * UTM_STEP_DEG)).round() as usize;
    let half = half.min(UTM_FRONT_STEP);
    ((UTM_FRONT_STEP - half)..=(UTM_FRONT_STEP + half))
        .rev()
        .map(|step| UtmBeam {
            step,
            azimuth_rad: ((step as f64 - UTM_FRONT_STEP as f64) * UTM_STEP_DEG).to_radians(),
            time_s: step as f64 * UTM_STEP_TIME_S,
        })
        .collect()
}

/// The UTM-30LX measurement defaults: 0.1 .. 30 m, sigma 0.01 m (the < 10 m figure, used at all
/// ranges), 1 mm quantum (ranges are reported in mm), grazing dropout beyond 89 deg, divergence
/// 0 (unverified: a thin beam), one echo (the -EW variant: `measurement.max_echoes = 3`), echo
/// separation 1 m, intensity reference 5 m.
pub fn utm_measurement(params: &MeasurementParams) -> Measurement {
    params.apply(Measurement {
        min_range_m: 0.1,
        max_range_m: 30.0,
        range_sigma_m: 0.01,
        range_quantum_m: 0.001,
        max_incidence_deg: 89.0,
        beam_divergence_rad: 0.0,
        max_echoes: 1,
        echo_separation_m: 1.0,
        intensity_reference_m: 5.0,
        detection_range_m: 30.0,
        detection_reflectance: 0.9,
    })
}

/// Hokuyo UTM-30LX, one scan per frame (TOML `model = "utm30lx"`): 1 row x 1081 columns (or
/// `fov_deg / 0.25 + 1`), frame period 25 ms.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Utm30lxSpec {
    /// Field of view centred on the front, degrees (default 270; 180 -> 721 beams).
    pub fov_deg: f32,
    /// Overrides of the measurement defaults.
    pub measurement: MeasurementParams,
}

impl Default for Utm30lxSpec {
    fn default() -> Self {
        Self { fov_deg: 270.0, measurement: MeasurementParams::default() }
    }
}

impl Utm30lxSpec {
    /// Checks the parameters; `field` is the dotted prefix for error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        validate_fov(field, self.fov_deg)?;
        validate_measurement(&format!("{field}.measurement"), &self.measurement())
    }

    /// The beams of one scan.
    pub fn pattern(&self) -> ScanPattern {
        let beams = utm_beams(self.fov_deg);
        let firings = beams
            .iter()
            .map(|b| {
                let (sin_az, cos_az) = b.azimuth_rad.sin_cos();
                Some(Firing {
                    origin_in_sensor: glam::Vec3::ZERO,
                    dir_in_sensor: glam::Vec3::new(cos_az as f32, sin_az as f32, 0.0),
                    time_s: b.time_s,
                })
            })
            .collect();
        ScanPattern {
            rows: 1,
            cols: beams.len(),
            firings,
            row_elevation_rad: vec![0.0],
            col_azimuth_rad: beams.iter().map(|b| b.azimuth_rad as f32).collect(),
            frame_period_s: UTM_SCAN_PERIOD_S,
        }
    }

    /// The default measurement with overrides applied.
    pub fn measurement(&self) -> Measurement {
        utm_measurement(&self.measurement)
    }
}
