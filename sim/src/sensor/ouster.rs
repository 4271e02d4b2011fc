//! Ouster OS1 spinning sensors: the gen1 OS1-64 (staggered beam azimuths) and the rev6/7 OS1-128
//! (45 deg vertical FOV). Both use the destaggered grid of [`super::spinning`].
//!
//! # Ring numbering
//! Ouster numbers its channels from the **top** beam (channel 0 = highest elevation); our rows go
//! bottom-up (row 0 = lowest beam), so `row = channels - 1 - ouster_channel`
//! ([`ouster_channel_of_row`]).
//!
//! # Frames
//! The pattern is in Ouster's *sensor* frame (the housing base, x forward, y left, z up; our
//! convention): every beam starts [`OS1_LIDAR_TO_SENSOR_Z_M`] above it (the lidar-to-sensor
//! transform) and `beam_origin_radius_m` out from the spin axis along the beam's azimuth (Ouster's
//! `lidar_origin_to_beam_origin_mm`; representative defaults, the real value is in each unit's
//! metadata). All channels of a column fire together; a column lasts `period / columns`.

use serde::{Deserialize, Serialize};

use super::measure::{MeasurementParams, validate_measurement};
use super::spinning::{Laser, spinning_pattern};
use super::{Measurement, ScanPattern};
use crate::error::{Result, SimError, check_range};

/// Height of the lidar frame above Ouster's sensor frame, metres.
pub const OS1_LIDAR_TO_SENSOR_Z_M: f64 = 0.03618;

/// Gen1 OS1-64 beam azimuth offsets by Ouster channel modulo 4, degrees (positive left).
pub const OS1_GEN1_STAGGER_DEG: [f64; 4] = [3.164, 1.055, -1.055, -3.164];

/// The Ouster channel of our row `row` for a sensor with `channels` channels (channel 0 is the top).
pub fn ouster_channel_of_row(channels: usize, row: usize) -> usize {
    channels - 1 - row
}

/// The OS1 lidar modes shared by both models: columns and rotation rate.
fn validate_mode(field: &str, columns: u32, frequency_hz: f32) -> Result<()> {
    if ![512, 1024, 2048].contains(&columns) {
        return Err(SimError::invalid(format!("{field}.columns"), columns, "512, 1024 or 2048"));
    }
    if frequency_hz != 10.0 && frequency_hz != 20.0 {
        return Err(SimError::invalid(format!("{field}.frequency_hz"), frequency_hz, "10 or 20"));
    }
    if columns == 2048 && frequency_hz != 10.0 {
        return Err(SimError::invalid(
            format!("{field}.frequency_hz"),
            frequency_hz,
            "10 (2048 columns only run at 10 Hz)",
        ));
    }
    Ok(())
}

/// The measurement defaults of both OS1 models: 0.5 .. 120 m, sigma 0.01 m, 1 mm quantum, grazing
/// dropout beyond 89 deg, divergence 3 mrad (0.18 deg), one echo, echo separation 1 m, intensity
/// reference 10 m.
fn os1_measurement(params: &MeasurementParams) -> Measurement {
    params.apply(Measurement::spinning(0.5, 120.0, 0.01, 0.001).with_detection(40.0, 0.1))
}

/// Lasers of a uniform-elevation OS1 from the top channel down; returned bottom-up (row order).
fn os1_lasers(channels: usize, top_deg: f64, stagger_deg: &[f64], beam_origin_radius_m: f64) -> Vec<Laser> {
    let spacing_deg = 2.0 * top_deg / (channels - 1) as f64;
    let mut lasers: Vec<Laser> = (0..channels)
        .map(|ch| Laser {
            elevation_rad: (top_deg - spacing_deg * ch as f64).to_radians(),
            azimuth_offset_rad: stagger_deg[ch % stagger_deg.len()].to_radians(),
            origin_in_head_m: [beam_origin_radius_m, 0.0, OS1_LIDAR_TO_SENSOR_Z_M],
            time_offset_s: 0.0,
        })
        .collect();
    lasers.reverse();
    lasers
}

/// Gen1 Ouster OS1-64 (TOML `model = "os1-64"`).
///
/// 64 channels uniform from +16.611 to -16.611 deg (0.5273 deg apart); channel `ch` has the
/// staggered azimuth offset [`OS1_GEN1_STAGGER_DEG`]`[ch % 4]` (+-3.164 / +-1.055 deg = 9 / 3
/// columns at 1024 columns to within 0.0003 deg, 18 / 6 at 2048), destaggered so column `c` is one
/// azimuth.
/// Modes: 512, 1024 (default) or 2048 columns at 10 (default) or 20 Hz, 2048 only at 10 Hz.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Os1Gen1Spec {
    /// Columns per revolution: 512, 1024 (default) or 2048.
    pub columns: u32,
    /// Rotation rate, Hz: 10 (default) or 20.
    pub frequency_hz: f32,
    /// Distance of the beam origins from the spin axis, metres (representative default 0.012163).
    pub beam_origin_radius_m: f32,
    /// Overrides of the measurement defaults.
    pub measurement: MeasurementParams,
}

impl Default for Os1Gen1Spec {
    fn default() -> Self {
        Self {
            columns: 1024,
            frequency_hz: 10.0,
            beam_origin_radius_m: 0.012163,
            measurement: MeasurementParams::default(),
        }
    }
}

impl Os1Gen1Spec {
    /// Checks the parameters; `field` is the dotted prefix for error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        validate_mode(field, self.columns, self.frequency_hz)?;
        check_range(&format!("{field}.beam_origin_radius_m"), self.beam_origin_radius_m as f64, 0.0, 0.1)?;
        validate_measurement(&format!("{field}.measurement"), &self.measurement())
    }

    /// The beams of one revolution (destaggered).
    pub fn pattern(&self) -> ScanPattern {
        let lasers = os1_lasers(64, 16.611, &OS1_GEN1_STAGGER_DEG, self.beam_origin_radius_m as f64);
        spinning_pattern(&lasers, self.columns as usize, self.frequency_hz as f64)
    }

    /// The default measurement with overrides applied.
    pub fn measurement(&self) -> Measurement {
        os1_measurement(&self.measurement)
    }
}

/// Rev6/7 Ouster OS1-128 (TOML `model = "os1-128"`).
///
/// 128 channels uniform from +22.5 to -22.5 deg (45 deg FOV, 0.3543 deg apart), no azimuth
/// stagger. Modes: 512, 1024 or 2048 columns at 10 or 20 Hz, 2048 only at 10 Hz. The default is
/// 2048 x 10 Hz (the 128 x 2048 frames of the project's benchmarks; Ouster's own factory default
/// is 1024 x 10).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Os1Spec {
    /// Columns per revolution: 512, 1024 or 2048 (default).
    pub columns: u32,
    /// Rotation rate, Hz: 10 (default) or 20.
    pub frequency_hz: f32,
    /// Distance of the beam origins from the spin axis, metres (representative default 0.015806).
    pub beam_origin_radius_m: f32,
    /// Overrides of the measurement defaults.
    pub measurement: MeasurementParams,
}

impl Default for Os1Spec {
    fn default() -> Self {
        Self {
            columns: 2048,
            frequency_hz: 10.0,
            beam_origin_radius_m: 0.015806,
            measurement: MeasurementParams::default(),
        }
    }
}

impl Os1Spec {
    /// Checks the parameters; `field` is the dotted prefix for error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        validate_mode(field, self.columns, self.frequency_hz)?;
        check_range(&format!("{field}.beam_origin_radius_m"), self.beam_origin_radius_m as f64, 0.0, 0.1)?;
        validate_measurement(&format!("{field}.measurement"), &self.measurement())
    }

    /// The beams of one revolution.
    pub fn pattern(&self) -> ScanPattern {
        let lasers = os1_lasers(128, 22.5, &[0.0], self.beam_origin_radius_m as f64);
        spinning_pattern(&lasers, self.columns as usize, self.frequency_hz as f64)
    }

    /// The default measurement with overrides applied.
    pub fn measurement(&self) -> Measurement {
        os1_measurement(&self.measurement)
    }
}
