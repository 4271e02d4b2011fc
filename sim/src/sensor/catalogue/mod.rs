//! The sensor catalogue: spinning sensors from their vendors' and drivers' published tables.
//!
//! Each [`CatalogueEntry`] holds a model's published per-channel elevation and azimuth-offset
//! table, its per-channel firing times inside a firing cycle, the rotation rates (and Ouster
//! column modes) it allows, its range limits, the return modes it supports and the output layout
//! of its ROS 2 driver. The sources (repository, path and commit of every table) are listed in
//! `docs/sensors.md` and on each entry.
//!
//! A catalogued sensor is a TOML sensor table with the model's name and a few optional fields
//! ([`CatalogueSpec`]):
//! ```toml
//! model = "vlp32c"            # one of CATALOGUE_MODELS
//! frequency_hz = 10.0         # optional: one of the model's rates (default: its factory rate)
//! return_mode = "dual"        # optional: one of the model's return modes (default: strongest)
//! columns = 1024              # Ouster only: 512, 1024 or 2048
//! [measurement]               # optional overrides (not max_echoes: set return_mode)
//! range_sigma_m = 0.03
//! ```
//!
//! The beams become a destaggered grid exactly as a [`super::CustomSpec`] does (rows = channels
//! sorted by elevation, stable; columns = firing cycles per revolution rounded to the nearest
//! integer, see [`super::spinning`]).

mod hesai;
mod ouster;
mod return_mode;
mod robosense;
mod velodyne;

pub use hesai::{PANDAR_XT32, PANDAR64};
pub use ouster::{OS0_128, OS2_128};
pub use return_mode::ReturnMode;
pub use robosense::HELIOS_5515;
pub use velodyne::{HDL32E, VLP32C, VLS128};

use serde::{Deserialize, Serialize};

use super::measure::{MeasurementParams, validate_measurement};
use super::spinning::{Laser, columns_per_revolution, spinning_pattern};
use super::{Measurement, ScanPattern};
use crate::error::{Result, SimError};

/// How a model's revolution is divided into columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColumnRule {
    /// Columns = firing cycles per revolution (rounded to the nearest integer): Velodyne, Hesai,
    /// RoboSense.
    FiringCycle {
        /// One firing cycle (all channels fire once), nanoseconds.
        cycle_ns: u32,
    },
    /// Columns chosen from the sensor's lidar modes (Ouster): `(columns, rates in Hz)`.
    Modes {
        /// The allowed modes: columns and the rotation rates each runs at.
        modes: &'static [(u32, &'static [f32])],
        /// The factory default columns.
        default_columns: u32,
    },
}

/// Which ring number a driver writes for a channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RingNumbering {
    /// The channel's rank in elevation, 0 = the lowest beam (ros-drivers/velodyne).
    ElevationFromBottom,
    /// The channel's index in the published table (Ouster: 0 = the top beam; Hesai, RoboSense:
    /// laser id - 1, not in elevation order).
    TableOrder,
}

/// How a driver orders the points of one cloud.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointOrder {
    /// Organized, HEIGHT = rings, rows from the lowest beam, no-returns as NaN
    /// (velodyne_pointcloud's organized cloud; our `--pcd-layout velodyne`).
    OrganizedBottomFirst,
    /// Organized, HEIGHT = channels, row 0 = channel 0 (the top beam), destaggered columns,
    /// no-returns as zeros (ouster-ros; our `--pcd-layout ouster`).
    OrganizedTopFirst,
    /// One row (HEIGHT = 1) in firing order: the channels of one firing cycle in table order,
    /// then the next cycle; no-returns dropped; in dual mode both returns of a cycle are written
    /// before the next cycle (nebula).
    FiringOrder,
}

/// A driver's ROS 2 output layout (`sensor_msgs/PointCloud2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriverLayout {
    /// The driver and its point type.
    pub driver: &'static str,
    /// Point fields as `(name, PCD type and size)`, e.g. `("ring", "U2")`.
    pub fields: &'static [(&'static str, &'static str)],
    /// The ring (channel) field's numbering.
    pub ring: RingNumbering,
    /// The point order.
    pub order: PointOrder,
    /// The per-point time field's name and meaning.
    pub time: &'static str,
}

/// One catalogued model: its published tables and limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CatalogueEntry {
    /// TOML model name, e.g. `vlp32c`.
    pub model: &'static str,
    /// Vendor and product, e.g. `Velodyne VLP-32C`.
    pub product: &'static str,
    /// Elevation of each channel in the published table's order, degrees (up positive).
    pub elevation_deg: &'static [f64],
    /// Azimuth offset of each channel as published, degrees, in the vendor's sign convention
    /// (see [`CatalogueEntry::azimuth_sign`]).
    pub azimuth_offset_deg: &'static [f64],
    /// +1 where the published azimuth offset is positive to the left (Velodyne's
    /// `rot_correction`), -1 where it is positive to the right, clockwise seen from above (Ouster's
    /// `beam_azimuth_angles`, Hesai's and RoboSense's angle tables).
    pub azimuth_sign: f64,
    /// Firing time of each channel after the start of its firing cycle, nanoseconds.
    pub firing_offset_ns: &'static [u32],
    /// Beam origin of every channel in the head frame (x along the beam azimuth, y left, z up),
    /// metres.
    pub beam_origin_m: [f64; 3],
    /// How a revolution is divided into columns.
    pub columns: ColumnRule,
    /// Allowed rotation rates, Hz.
    pub rates_hz: &'static [f32],
    /// Factory default rotation rate, Hz.
    pub default_rate_hz: f32,
    /// Measurement defaults (range limits, noise, quantum; `max_echoes` comes from the return
    /// mode).
    pub measurement: Measurement,
    /// The return modes the sensor supports.
    pub return_modes: &'static [ReturnMode],
    /// The ROS 2 driver's output layout.
    pub driver: DriverLayout,
}

/// Every catalogued model.
pub const CATALOGUE: [&CatalogueEntry; 8] =
    [&HDL32E, &VLP32C, &VLS128, &OS0_128, &OS2_128, &PANDAR64, &PANDAR_XT32, &HELIOS_5515];

/// The catalogued model names, as written in TOML (`CATALOGUE[i].model`).
pub const CATALOGUE_MODELS: [&str; CATALOGUE.len()] = catalogue_models();

const fn catalogue_models() -> [&'static str; CATALOGUE.len()] {
    let mut out = [""; CATALOGUE.len()];
    let mut i = 0;
    while i < out.len() {
        out[i] = CATALOGUE[i].model;
        i += 1;
    }
    out
}

/// The catalogue entry of `model`, if it is catalogued.
pub fn entry(model: &str) -> Option<&'static CatalogueEntry> {
    CATALOGUE.iter().copied().find(|e| e.model == model)
}

impl CatalogueEntry {
    /// Number of channels (lasers).
    pub fn channels(&self) -> usize {
        self.elevation_deg.len()
    }

    /// The channel (table index) of each grid row: rows are the channels sorted by elevation,
    /// lowest first (stable).
    pub fn channel_of_row(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.channels()).collect();
        order.sort_by(|&a, &b| self.elevation_deg[a].total_cmp(&self.elevation_deg[b]));
        order
    }
}

/// The user's settings of a catalogued sensor (TOML: the model name plus these optional fields).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CatalogueSpec {
    /// Rotation rate, Hz (one of the model's rates; default its factory rate).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frequency_hz: Option<f32>,
    /// Columns per revolution (Ouster models only: one of the lidar modes; default 1024).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub columns: Option<u32>,
    /// Return mode (one the model supports; default `strongest`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub return_mode: Option<ReturnMode>,
    /// Overrides of the measurement defaults (all but `max_echoes`, which the return mode sets).
    pub measurement: MeasurementParams,
}

fn list_f32(values: &[f32]) -> String {
    values.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(", ")
}

impl CatalogueSpec {
    /// The rotation rate, Hz.
    pub fn frequency_hz(&self, entry: &CatalogueEntry) -> f32 {
        self.frequency_hz.unwrap_or(entry.default_rate_hz)
    }

    /// The return mode.
    pub fn return_mode(&self) -> ReturnMode {
        self.return_mode.unwrap_or(ReturnMode::Strongest)
    }

    /// Columns per revolution.
    pub fn columns(&self, entry: &CatalogueEntry) -> usize {
        match entry.columns {
            ColumnRule::FiringCycle { cycle_ns } => {
                columns_per_revolution(cycle_ns as f64 * 1e-9, self.frequency_hz(entry) as f64)
            }
            ColumnRule::Modes { default_columns, .. } => self.columns.unwrap_or(default_columns) as usize,
        }
    }

    /// Checks the settings against `entry`; errors name the field (`{field}.frequency_hz`, ...)
    /// and the allowed values.
    pub fn validate(&self, entry: &CatalogueEntry, field: &str) -> Result<()> {
        let f = self.frequency_hz(entry);
        if !entry.rates_hz.contains(&f) {
            return Err(SimError::invalid(
                format!("{field}.frequency_hz"),
                f,
                format!("one of {} (the {}'s rates)", list_f32(entry.rates_hz), entry.product),
            ));
        }
        match entry.columns {
            ColumnRule::FiringCycle { .. } => {
                if let Some(c) = self.columns {
                    return Err(SimError::invalid(
                        format!("{field}.columns"),
                        c,
                        format!(
                            "left out: the {}'s columns follow its firing cycle ({} at {f} Hz)",
                            entry.product,
                            self.columns(entry)
                        ),
                    ));
                }
            }
            ColumnRule::Modes { modes, default_columns } => {
                let c = self.columns.unwrap_or(default_columns);
                let allowed = || modes.iter().map(|m| m.0.to_string()).collect::<Vec<_>>().join(", ");
                let Some((_, rates)) = modes.iter().find(|m| m.0 == c) else {
                    return Err(SimError::invalid(format!("{field}.columns"), c, format!("one of {}", allowed())));
                };
                if !rates.contains(&f) {
                    return Err(SimError::invalid(
                        format!("{field}.frequency_hz"),
                        f,
                        format!("one of {} with {c} columns", list_f32(rates)),
                    ));
                }
            }
        }
        let mode = self.return_mode();
        if !entry.return_modes.contains(&mode) {
            return Err(SimError::invalid(
                format!("{field}.return_mode"),
                mode.name(),
                format!("one of {} (the {}'s return modes)", ReturnMode::names(entry.return_modes), entry.product),
            ));
        }
        if let Some(e) = self.measurement.max_echoes {
            return Err(SimError::invalid(
                format!("{field}.measurement.max_echoes"),
                e,
                format!("left out: set return_mode ({})", ReturnMode::names(entry.return_modes)),
            ));
        }
        validate_measurement(&format!("{field}.measurement"), &self.measurement(entry))
    }

    /// The lasers sorted by elevation (row order; stable for equal elevations).
    pub fn lasers(&self, entry: &CatalogueEntry) -> Vec<Laser> {
        entry
            .channel_of_row()
            .into_iter()
            .map(|ch| Laser {
                elevation_rad: entry.elevation_deg[ch].to_radians(),
                azimuth_offset_rad: (entry.azimuth_sign * entry.azimuth_offset_deg[ch]).to_radians(),
                origin_in_head_m: entry.beam_origin_m,
                time_offset_s: entry.firing_offset_ns[ch] as f64 * 1e-9,
            })
            .collect()
    }

    /// The beams of one revolution. Call [`CatalogueSpec::validate`] first.
    pub fn pattern(&self, entry: &CatalogueEntry) -> ScanPattern {
        spinning_pattern(&self.lasers(entry), self.columns(entry), self.frequency_hz(entry) as f64)
    }

    /// The model's measurement defaults with the return mode's echoes and the overrides applied.
    pub fn measurement(&self, entry: &CatalogueEntry) -> Measurement {
        let base = Measurement { max_echoes: self.return_mode().echoes(), ..entry.measurement };
        self.measurement.apply(base)
    }
}
