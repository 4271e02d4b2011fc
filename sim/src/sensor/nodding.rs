//! A Hokuyo UTM-30LX on a nodding (tilting) mount, as in seed 002: one frame is one full nod.
//!
//! # Frames and pitch convention
//! The sensor frame of this model is the **tilt-axis frame**: origin on the tilt axis, x forward,
//! y left along the axis, z up; the rig mount places the axis (the `utm30lx-nodding` preset puts it
//! 0.55 m above the ground). The tilt `p` is an **elevation** (positive = nose up, the sign of seed
//! 002's "-75 .. +55 deg"), i.e. the opposite sign of [`crate::rig::Mount::pitch_deg`]. At tilt
//! `p` the scanner frame is the axis frame rotated by `-p` about y, so the front beam points at
//! elevation `p` and a beam at scanner azimuth `t` points along
//! `(cos t cos p, sin t, cos t sin p)`. The optical centre sits on a lever arm
//! (`lever_arm_m`, scanner frame; default 5 cm above the axis): `origin = Ry(-p) * lever_arm`, a
//! circle of radius `|lever_arm|` about the axis.
//!
//! # Grid
//! Row `i` is scan `i` (ring = scan index), column `c` is the Hokuyo step `last - c` (see
//! [`super::hokuyo`]). Scan 0 is taken at the lowest tilt, so rows go up in the elevation of the
//! front beam; for beams behind the axis (|azimuth| > 90 deg, the rear flanks of the 270 deg fan)
//! the elevation order is reversed, and at +-90 deg all rows point the same way. Grid neighbours
//! are still physical neighbours (adjacent scans, adjacent steps).
//!
//! # Time and tilt
//! Scan `i` starts at `i * 25 ms`; step `s` fires `s * 17.36 us` later; a frame lasts
//! `scans * 25 ms` (5 s for 200 scans). Nominal tilt of scan `i`:
//! `p_i = pitch_min + i * (pitch_max - pitch_min) / (scans - 1)` (0.653 deg per scan for the seed).
//! - `stepped`: the tilt holds `p_i` during scan `i` (it steps in the mirror's 90 deg dead zone).
//! - `continuous` (default): the tilt moves at a constant rate, `p(t) = pitch_min + rate * (t -
//!   t_front)` with `t_front` the time of the first scan's front beam, so every scan's front beam
//!   is at exactly `p_i` and a 270 deg scan spans 0.49 deg of tilt; each beam gets its own tilt.
//!
//! Each frame is one upward sweep (pitch_min to pitch_max); the return stroke is not scanned.

use serde::{Deserialize, Serialize};

use super::hokuyo::{UTM_FRONT_STEP, UTM_SCAN_PERIOD_S, UTM_STEP_TIME_S, utm_beams, utm_measurement, validate_fov};
use super::measure::{MeasurementParams, validate_measurement};
use super::{Firing, Measurement, ScanPattern};
use crate::error::{Result, SimError, check_range};

/// How the mount tilts during a nod.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum TiltMode {
    /// Constant tilt rate; every beam has its own interpolated tilt.
    #[default]
    Continuous,
    /// Tilt held constant during each scan.
    Stepped,
}

/// Hokuyo UTM-30LX on a nodding mount (TOML `model = "utm30lx-nodding"`): `scans` rows x 1081
/// columns (or `fov_deg / 0.25 + 1`). Measurement defaults are the UTM-30LX's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NoddingSpec {
    /// Field of view of each scan, centred on the front, degrees (default 270).
    pub fov_deg: f32,
    /// Lowest tilt (elevation of the front beam, first scan), degrees (default -75).
    pub pitch_min_deg: f32,
    /// Highest tilt (last scan), degrees (default +55).
    pub pitch_max_deg: f32,
    /// Scans per nod = rows (default 200).
    pub scans: u32,
    /// Continuous (default) or stepped tilt.
    pub tilt: TiltMode,
    /// Optical centre relative to the tilt axis in the scanner frame, metres (default `[0, 0, 0.05]`).
    pub lever_arm_m: [f32; 3],
    /// Overrides of the measurement defaults.
    pub measurement: MeasurementParams,
}

impl Default for NoddingSpec {
    fn default() -> Self {
        Self {
            fov_deg: 270.0,
            pitch_min_deg: -75.0,
            pitch_max_deg: 55.0,
            scans: 200,
            tilt: TiltMode::Continuous,
            lever_arm_m: [0.0, 0.0, 0.05],
            measurement: MeasurementParams::default(),
        }
    }
}

impl NoddingSpec {
    /// Nominal tilt of scan `i`, radians.
    pub fn scan_pitch_rad(&self, i: usize) -> f64 {
        let (lo, hi) = (self.pitch_min_deg as f64, self.pitch_max_deg as f64);
        let n = self.scans.max(2) as f64;
        (lo + i as f64 * (hi - lo) / (n - 1.0)).to_radians()
    }

    /// Tilt rate of the continuous mode, radians per second.
    pub fn tilt_rate_rad_per_s(&self) -> f64 {
        let (lo, hi) = (self.pitch_min_deg as f64, self.pitch_max_deg as f64);
        (hi - lo).to_radians() / ((self.scans.max(2) - 1) as f64 * UTM_SCAN_PERIOD_S)
    }

    /// Tilt at time `t_s` after the frame start during scan `i`, radians.
    pub fn pitch_at_rad(&self, i: usize, t_s: f64) -> f64 {
        match self.tilt {
            TiltMode::Stepped => self.scan_pitch_rad(i),
            TiltMode::Continuous => {
                let t_front_s = UTM_FRONT_STEP as f64 * UTM_STEP_TIME_S;
                (self.pitch_min_deg as f64).to_radians() + self.tilt_rate_rad_per_s() * (t_s - t_front_s)
            }
        }
    }

    /// Checks the parameters; `field` is the dotted prefix for error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        let f = |name: &str| format!("{field}.{name}");
        validate_fov(field, self.fov_deg)?;
        check_range(&f("pitch_min_deg"), self.pitch_min_deg as f64, -89.0, 89.0)?;
        check_range(&f("pitch_max_deg"), self.pitch_max_deg as f64, -89.0, 89.0)?;
        if self.pitch_max_deg <= self.pitch_min_deg {
            return Err(SimError::invalid(
                f("pitch_max_deg"),
                self.pitch_max_deg,
                format!("greater than pitch_min_deg ({}) and <= 89", self.pitch_min_deg),
            ));
        }
        if !(2..=10_000).contains(&self.scans) {
            return Err(SimError::invalid(f("scans"), self.scans, "2 ..= 10000"));
        }
        for (k, v) in self.lever_arm_m.iter().enumerate() {
            check_range(&format!("{field}.lever_arm_m[{k}]"), *v as f64, -1.0, 1.0)?;
        }
        validate_measurement(&f("measurement"), &self.measurement())
    }

    /// The beams of one nod.
    pub fn pattern(&self) -> ScanPattern {
        let beams = utm_beams(self.fov_deg);
        let rows = self.scans as usize;
        let cols = beams.len();
        let lever = self.lever_arm_m.map(|v| v as f64);
        let mut firings = Vec::with_capacity(rows * cols);
        for i in 0..rows {
            let scan_start_s = i as f64 * UTM_SCAN_PERIOD_S;
            for b in &beams {
                let time_s = scan_start_s + b.time_s;
                let (sin_p, cos_p) = self.pitch_at_rad(i, time_s).sin_cos();
                let (sin_t, cos_t) = b.azimuth_rad.sin_cos();
                // Ry(-p) applied to (x, y, z): (x cos p - z sin p, y, x sin p + z cos p).
                let rotate = |[x, y, z]: [f64; 3]| {
                    glam::Vec3::new((x * cos_p - z * sin_p) as f32, y as f32, (x * sin_p + z * cos_p) as f32)
                };
                firings.push(Some(Firing {
                    origin_in_sensor: rotate(lever),
                    dir_in_sensor: rotate([cos_t, sin_t, 0.0]),
                    time_s,
                }));
            }
        }
        ScanPattern {
            rows,
            cols,
            firings,
            row_elevation_rad: (0..rows).map(|i| self.scan_pitch_rad(i) as f32).collect(),
            col_azimuth_rad: beams.iter().map(|b| b.azimuth_rad as f32).collect(),
            frame_period_s: rows as f64 * UTM_SCAN_PERIOD_S,
        }
    }

    /// The default measurement with overrides applied.
    pub fn measurement(&self) -> Measurement {
        utm_measurement(&self.measurement)
    }
}
