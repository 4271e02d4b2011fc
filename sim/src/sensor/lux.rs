//! Ibeo LUX 4-layer (= SICK LD-MRS400001): a rotating-mirror scanner with four layers.
//!
//! # Grid
//! Rows are the 4 layers, bottom-up (-1.2, -0.4, +0.4, +1.2 deg). Columns are the shots of one
//! scan, from the start angle (+50 deg, left) clockwise to the end angle (-60 deg, right); a
//! column's azimuth is the same in every layer.
//! - **Constant resolution**: shots at `start - c * resolution`, both FOV ends included (the
//!   LD-MRS reports start and end angle inclusive): `(start - end) / resolution + 1` columns,
//!   441 for the default 110 deg at 0.25 deg (12.5 / 25 Hz) and 221 at 0.5 deg (50 Hz).
//! - **Flexible resolution** (12.5 Hz only): a list of up to 8 half-open sectors
//!   `[start_deg, next start)`, each contributing `width / resolution` shots at
//!   `start_deg - k * resolution`; the last sector ends at the end angle. The SICK driver's
//!   default map ([`LuxSpec::sick_default_sectors`]) gives 375 shots.
//!
//! # Per-layer windows and flanks
//! All 4 layers cover +35 .. -50 deg; only 2 layers cover the flanks +50 .. +35 and -50 .. -60.
//! Which two survive is unverified; the documented default keeps the **two lower layers (rows 0
//! and 1) in both flanks**: a LUX is mounted pitched down, so the lower layers carry the ground
//! and near obstacles while the upper pair mostly sees sky in the flanks. Each layer's window is a
//! parameter (`layer_windows_deg`); cells outside a layer's window are `None`.
//!
//! # Time
//! The mirror turns 360 deg per period, so the shot at azimuth `a` fires at
//! `(start_angle - a) / (360 deg * f)` after the scan start (55.6 us per 0.25 deg at 12.5 Hz).
//! All layers of a shot fire at the same time.

use serde::{Deserialize, Serialize};

use super::measure::{MeasurementParams, validate_measurement};
use super::{Firing, Measurement, ScanPattern};
use crate::error::{Result, SimError};

/// Resolution modes of the LUX.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum LuxMode {
    /// One angular step over the whole FOV.
    #[default]
    Constant,
    /// Sectors with their own steps (12.5 Hz only).
    Flexible,
}

/// One sector of a flexible-resolution map: from `start_deg` down to the next sector's start.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LuxSector {
    /// Left edge of the sector (its first shot), degrees.
    pub start_deg: f32,
    /// Angular step inside the sector: 0.125, 0.25, 0.5 or 1.0 deg.
    pub resolution_deg: f32,
}

/// Ibeo LUX 4-layer (TOML `model = "ibeo-lux"`). See the module documentation for the grid.
///
/// Measurement defaults: 0.3 .. 200 m, sigma 0.04 m (the spec's 10 cm accuracy read as 2.5
/// sigma), 0.01 m quantum (distances are sent in whole centimetres), grazing dropout beyond
/// 89 deg, divergence 0.08 deg (the horizontal beam width; the 0.8 deg vertical height is the
/// layer spacing), up to 3 echoes, echo separation 1 m (unverified), intensity reference 20 m.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LuxSpec {
    /// Scan frequency, Hz: 12.5 (default), 25 or 50.
    pub frequency_hz: f32,
    /// Constant (default) or flexible resolution.
    pub mode: LuxMode,
    /// Constant-resolution step, degrees; default 0.25 at 12.5 / 25 Hz and 0.5 at 50 Hz.
    /// Allowed: 0.125 (12.5 Hz only), 0.25 (not at 50 Hz), 0.5, 1.0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resolution_deg: Option<f32>,
    /// Flexible-resolution sectors, left to right; default the SICK map (375 shots).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sectors: Option<Vec<LuxSector>>,
    /// Scan start angle (left end of the FOV), degrees: default +50.
    pub start_angle_deg: f32,
    /// Scan end angle (right end of the FOV), degrees: default -60.
    pub end_angle_deg: f32,
    /// Layer elevations bottom-up, degrees: default -1.2, -0.4, +0.4, +1.2.
    pub layer_elevations_deg: [f32; 4],
    /// Per-layer azimuth window `[left, right]`, degrees: default lower two layers +50 .. -60,
    /// upper two +35 .. -50.
    pub layer_windows_deg: [[f32; 2]; 4],
    /// Overrides of the measurement defaults.
    pub measurement: MeasurementParams,
}

impl Default for LuxSpec {
    fn default() -> Self {
        Self {
            frequency_hz: 12.5,
            mode: LuxMode::Constant,
            resolution_deg: None,
            sectors: None,
            start_angle_deg: 50.0,
            end_angle_deg: -60.0,
            layer_elevations_deg: [-1.2, -0.4, 0.4, 1.2],
            layer_windows_deg: [[50.0, -60.0], [50.0, -60.0], [35.0, -50.0], [35.0, -50.0]],
            measurement: MeasurementParams::default(),
        }
    }
}

/// Angular steps the LUX supports, degrees.
const LUX_STEPS_DEG: [f32; 4] = [0.125, 0.25, 0.5, 1.0];
/// Largest shot count of a flexible scan.
const LUX_MAX_FLEXIBLE_SHOTS: usize = 440;
/// Largest total width of 0.125 deg sectors, degrees.
const LUX_MAX_FINE_WIDTH_DEG: f64 = 20.0;

impl LuxSpec {
    /// The SICK driver's default flexible map: +50 1.0, +35 0.5, +30 0.25, +20 0.125, 0 0.25,
    /// -20 0.5, -30 1.0, -40 0.5 (to -60): 375 shots.
    pub fn sick_default_sectors() -> Vec<LuxSector> {
        [(50.0, 1.0), (35.0, 0.5), (30.0, 0.25), (20.0, 0.125), (0.0, 0.25), (-20.0, 0.5), (-30.0, 1.0), (-40.0, 0.5)]
            .into_iter()
            .map(|(start_deg, resolution_deg)| LuxSector { start_deg, resolution_deg })
            .collect()
    }

    /// The constant-resolution step in use, degrees.
    pub fn constant_resolution_deg(&self) -> f32 {
        self.resolution_deg.unwrap_or(if self.frequency_hz >= 50.0 { 0.5 } else { 0.25 })
    }

    /// The sectors in use in flexible mode.
    pub fn flexible_sectors(&self) -> Vec<LuxSector> {
        self.sectors.clone().unwrap_or_else(Self::sick_default_sectors)
    }

    /// Shot azimuths of one scan, degrees, decreasing.
    pub fn shot_azimuths_deg(&self) -> Vec<f64> {
        let start = self.start_angle_deg as f64;
        let end = self.end_angle_deg as f64;
        match self.mode {
            LuxMode::Constant => {
                let res = self.constant_resolution_deg() as f64;
                let n = ((start - end) / res).round() as usize + 1;
                (0..n).map(|c| start - c as f64 * res).collect()
            }
            LuxMode::Flexible => {
                let sectors = self.flexible_sectors();
                let mut shots = Vec::new();
                for (i, s) in sectors.iter().enumerate() {
                    let from = s.start_deg as f64;
                    let to = sectors.get(i + 1).map_or(end, |n| n.start_deg as f64);
                    let res = s.resolution_deg as f64;
                    let n = ((from - to) / res).round() as usize;
                    shots.extend((0..n).map(|k| from - k as f64 * res));
                }
                shots
            }
        }
    }

    /// Checks the parameters; `field` is the dotted prefix for error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        let f = |name: &str| format!("{field}.{name}");
        let freq = self.frequency_hz;
        if ![12.5, 25.0, 50.0].contains(&freq) {
            return Err(SimError::invalid(f("frequency_hz"), freq, "12.5, 25 or 50"));
        }
        let (start, end) = (self.start_angle_deg, self.end_angle_deg);
        if !(start.is_finite() && (-60.0..=50.0).contains(&start)) {
            return Err(SimError::invalid(f("start_angle_deg"), start, "-60 ..= 50"));
        }
        if !(end.is_finite() && end >= -60.0 && end < start) {
            return Err(SimError::invalid(f("end_angle_deg"), end, format!("-60 <= x < start_angle_deg ({start})")));
        }
        match self.mode {
            LuxMode::Constant => {
                let res = self.constant_resolution_deg();
                let min_res = if freq == 12.5 {
                    0.125
                } else if freq == 25.0 {
                    0.25
                } else {
                    0.5
                };
                if !LUX_STEPS_DEG.contains(&res) || res < min_res {
                    return Err(SimError::invalid(
                        f("resolution_deg"),
                        res,
                        format!("one of 0.125, 0.25, 0.5, 1.0 and >= {min_res} at {freq} Hz"),
                    ));
                }
                let width = (start - end) as f64 / res as f64;
                if (width - width.round()).abs() > 1e-6 {
                    return Err(SimError::invalid(
                        f("end_angle_deg"),
                        end,
                        format!("start_angle_deg - end_angle_deg a multiple of resolution_deg ({res})"),
                    ));
                }
            }
            LuxMode::Flexible => self.validate_sectors(field)?,
        }
        for (i, &e) in self.layer_elevations_deg.iter().enumerate() {
            let prev = if i == 0 { -10.0 } else { self.layer_elevations_deg[i - 1] };
            if !(e.is_finite() && e > prev && e <= 10.0) {
                return Err(SimError::invalid(
                    format!("{field}.layer_elevations_deg[{i}]"),
                    e,
                    "-10 < x <= 10, increasing with the layer",
                ));
            }
        }
        for (i, w) in self.layer_windows_deg.iter().enumerate() {
            if !(w[0].is_finite() && w[1].is_finite() && w[0] > w[1] && w[0] <= 50.0 && w[1] >= -60.0) {
                return Err(SimError::invalid(
                    format!("{field}.layer_windows_deg[{i}]"),
                    format!("[{}, {}]", w[0], w[1]),
                    "[left, right] with 50 >= left > right >= -60",
                ));
            }
        }
        validate_measurement(&f("measurement"), &self.measurement())
    }

    /// Checks a flexible-resolution map.
    fn validate_sectors(&self, field: &str) -> Result<()> {
        let f = |name: &str| format!("{field}.{name}");
        if self.frequency_hz != 12.5 {
            return Err(SimError::invalid(f("mode"), "flexible", "flexible resolution only at frequency_hz = 12.5"));
        }
        let sectors = self.flexible_sectors();
        if sectors.is_empty() || sectors.len() > 8 {
            return Err(SimError::invalid(f("sectors"), format!("{} sectors", sectors.len()), "1 ..= 8 sectors"));
        }
        if sectors[0].start_deg != self.start_angle_deg {
            return Err(SimError::invalid(
                format!("{field}.sectors[0].start_deg"),
                sectors[0].start_deg,
                format!("equal to start_angle_deg ({})", self.start_angle_deg),
            ));
        }
        let mut fine_width = 0.0;
        for (i, s) in sectors.iter().enumerate() {
            let name = |n: &str| format!("{field}.sectors[{i}].{n}");
            let to = sectors.get(i + 1).map_or(self.end_angle_deg, |n| n.start_deg);
            if !(s.start_deg.is_finite() && s.start_deg > to) {
                return Err(SimError::invalid(
                    name("start_deg"),
                    s.start_deg,
                    format!("finite and greater than the next sector's start / end angle ({to})"),
                ));
            }
            if !LUX_STEPS_DEG.contains(&s.resolution_deg) {
                return Err(SimError::invalid(name("resolution_deg"), s.resolution_deg, "0.125, 0.25, 0.5 or 1.0"));
            }
            let width = (s.start_deg - to) as f64;
            let steps = width / s.resolution_deg as f64;
            if (steps - steps.round()).abs() > 1e-6 {
                return Err(SimError::invalid(
                    name("resolution_deg"),
                    s.resolution_deg,
                    format!("a divisor of the sector width ({width} deg)"),
                ));
            }
            if s.resolution_deg == 0.125 {
                fine_width += width;
            }
        }
        if fine_width > LUX_MAX_FINE_WIDTH_DEG {
            return Err(SimError::invalid(
                f("sectors"),
                format!("{fine_width} deg at 0.125 deg"),
                format!("at most {LUX_MAX_FINE_WIDTH_DEG} deg of 0.125 deg sectors"),
            ));
        }
        let shots = self.shot_azimuths_deg().len();
        if shots > LUX_MAX_FLEXIBLE_SHOTS {
            return Err(SimError::invalid(
                f("sectors"),
                format!("{shots} shots"),
                format!("at most {LUX_MAX_FLEXIBLE_SHOTS} shots per scan"),
            ));
        }
        Ok(())
    }

    /// The beams of one scan.
    pub fn pattern(&self) -> ScanPattern {
        let azimuths_deg = self.shot_azimuths_deg();
        let cols = azimuths_deg.len();
        let rows = 4;
        let rate_deg_per_s = 360.0 * self.frequency_hz as f64;
        let mut firings = Vec::with_capacity(rows * cols);
        for (layer, &el_deg) in self.layer_elevations_deg.iter().enumerate() {
            let (sin_el, cos_el) = (el_deg as f64).to_radians().sin_cos();
            let [left, right] = self.layer_windows_deg[layer].map(|a| a as f64);
            for &az_deg in &azimuths_deg {
                let inside = az_deg <= left + 1e-9 && az_deg >= right - 1e-9;
                firings.push(inside.then(|| {
                    let (sin_az, cos_az) = az_deg.to_radians().sin_cos();
                    Firing {
                        origin_in_sensor: glam::Vec3::ZERO,
                        dir_in_sensor: glam::Vec3::new(
                            (cos_el * cos_az) as f32,
                            (cos_el * sin_az) as f32,
                            sin_el as f32,
                        ),
                        time_s: (self.start_angle_deg as f64 - az_deg) / rate_deg_per_s,
                    }
                }));
            }
        }
        ScanPattern {
            rows,
            cols,
            firings,
            row_elevation_rad: self.layer_elevations_deg.iter().map(|e| e.to_radians()).collect(),
            col_azimuth_rad: azimuths_deg.iter().map(|a| a.to_radians() as f32).collect(),
            frame_period_s: 1.0 / self.frequency_hz as f64,
        }
    }

    /// The default measurement with overrides applied.
    pub fn measurement(&self) -> Measurement {
        self.measurement.apply(Measurement {
            min_range_m: 0.3,
            max_range_m: 200.0,
            range_sigma_m: 0.04,
            range_quantum_m: 0.01,
            max_incidence_deg: 89.0,
            beam_divergence_rad: 0.08_f32.to_radians(),
            max_echoes: 3,
            echo_separation_m: 1.0,
            intensity_reference_m: 20.0,
            detection_range_m: 50.0,
            detection_reflectance: 0.1,
        })
    }
}
