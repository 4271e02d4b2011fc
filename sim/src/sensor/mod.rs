//! Sensor models: each turns its parameters into a [`ScanPattern`] (the beams of one frame on an
//! ordered grid) and a [`Measurement`] (range limits, noise, quantisation, echoes).
//!
//! Models (TOML: a table with `model = "..."` and the model's fields, all optional with documented
//! defaults, unknown fields rejected):
//! - `ibeo-lux` ([`LuxSpec`]): 4 layers, constant or flexible resolution, per-layer windows.
//! - `utm30lx` ([`Utm30lxSpec`]): 2-D Hokuyo, 270 deg / 1081 beams, optional FOV subset.
//! - `utm30lx-nodding` ([`NoddingSpec`]): the Hokuyo on a nodding mount, one nod per frame.
//! - `vlp16`, `hdl64e` ([`Vlp16Spec`], [`Hdl64eSpec`]): Velodyne spinning sensors.
//! - `os1-64`, `os1-128` ([`Os1Gen1Spec`], [`Os1Spec`]): Ouster spinning sensors.
//! - `custom` ([`CustomSpec`]): a spinning sensor from a table of beams.
//! - the catalogue ([`catalogue`], [`CatalogueSpec`]): `hdl32e`, `vlp32c`, `vls128`, `os0-128`,
//!   `os2-128`, `pandar64`, `pandar-xt32`, `rs-helios-5515`, spinning sensors from their vendors'
//!   published tables, with return modes ([`ReturnMode`]).
//!
//! Grid rule (all models, see [`ScanPattern`]): row 0 lowest, rows up in elevation; column 0
//! left-most, azimuth decreasing with the column. Spinning sensors with staggered beams are
//! destaggered ([`spinning`]); the nodding Hokuyo's rows are scans ([`nodding`]).

pub mod catalogue;
pub mod custom;
pub mod hokuyo;
pub mod lux;
pub mod measure;
pub mod nodding;
pub mod ouster;
mod pattern;
pub mod spinning;
pub mod velodyne;

pub use catalogue::{CatalogueEntry, CatalogueSpec, ReturnMode};
pub use custom::{CustomBeam, CustomSpec};
pub use hokuyo::Utm30lxSpec;
pub use lux::{LuxMode, LuxSector, LuxSpec};
pub use measure::MeasurementParams;
pub use nodding::{NoddingSpec, TiltMode};
pub use ouster::{Os1Gen1Spec, Os1Spec};
pub use pattern::{Firing, Measurement, ScanPattern};
pub use velodyne::{Hdl64eSpec, Vlp16Spec};

use serde::{Deserialize, Serialize};

use crate::error::{Result, SimError};

/// The model names, as written in TOML (`model = "..."`): the built-in models, then the
/// catalogue's ([`catalogue::CATALOGUE_MODELS`]).
pub const MODELS: &[&str] = &[
    "ibeo-lux",
    "utm30lx",
    "utm30lx-nodding",
    "vlp16",
    "hdl64e",
    "os1-64",
    "os1-128",
    "custom",
    "hdl32e",
    "vlp32c",
    "vls128",
    "os0-128",
    "os2-128",
    "pandar64",
    "pandar-xt32",
    "rs-helios-5515",
];

/// A sensor model and its parameters (TOML: a table with `model = "..."`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model")]
pub enum SensorSpec {
    /// Ibeo LUX 4-layer.
    #[serde(rename = "ibeo-lux")]
    IbeoLux(LuxSpec),
    /// Hokuyo UTM-30LX, one 2-D scan per frame.
    #[serde(rename = "utm30lx")]
    Utm30lx(Utm30lxSpec),
    /// Hokuyo UTM-30LX on a nodding mount, one nod per frame.
    #[serde(rename = "utm30lx-nodding")]
    Utm30lxNodding(NoddingSpec),
    /// Velodyne VLP-16.
    #[serde(rename = "vlp16")]
    Vlp16(Vlp16Spec),
    /// Velodyne HDL-64E S2/S3.
    #[serde(rename = "hdl64e")]
    Hdl64e(Hdl64eSpec),
    /// Ouster OS1-64 gen1.
    #[serde(rename = "os1-64")]
    Os1_64(Os1Gen1Spec),
    /// Ouster OS1-128 rev6/7.
    #[serde(rename = "os1-128")]
    Os1_128(Os1Spec),
    /// A spinning sensor from a table of beams.
    #[serde(rename = "custom")]
    Custom(CustomSpec),
    /// Velodyne HDL-32E.
    #[serde(rename = "hdl32e")]
    Hdl32e(CatalogueSpec),
    /// Velodyne VLP-32C.
    #[serde(rename = "vlp32c")]
    Vlp32c(CatalogueSpec),
    /// Velodyne VLS-128.
    #[serde(rename = "vls128")]
    Vls128(CatalogueSpec),
    /// Ouster OS0-128.
    #[serde(rename = "os0-128")]
    Os0_128(CatalogueSpec),
    /// Ouster OS2-128.
    #[serde(rename = "os2-128")]
    Os2_128(CatalogueSpec),
    /// Hesai Pandar64.
    #[serde(rename = "pandar64")]
    Pandar64(CatalogueSpec),
    /// Hesai PandarXT-32.
    #[serde(rename = "pandar-xt32")]
    PandarXt32(CatalogueSpec),
    /// RoboSense RS-Helios 5515.
    #[serde(rename = "rs-helios-5515")]
    RsHelios5515(CatalogueSpec),
}

impl SensorSpec {
    /// The model `name` (one of [`MODELS`]) with all its defaults.
    pub fn default_for(name: &str) -> Result<Self> {
        Ok(match name {
            "ibeo-lux" => Self::IbeoLux(LuxSpec::default()),
            "utm30lx" => Self::Utm30lx(Utm30lxSpec::default()),
            "utm30lx-nodding" => Self::Utm30lxNodding(NoddingSpec::default()),
            "vlp16" => Self::Vlp16(Vlp16Spec::default()),
            "hdl64e" => Self::Hdl64e(Hdl64eSpec::default()),
            "os1-64" => Self::Os1_64(Os1Gen1Spec::default()),
            "os1-128" => Self::Os1_128(Os1Spec::default()),
            "custom" => Self::Custom(CustomSpec::default()),
            "hdl32e" => Self::Hdl32e(CatalogueSpec::default()),
            "vlp32c" => Self::Vlp32c(CatalogueSpec::default()),
            "vls128" => Self::Vls128(CatalogueSpec::default()),
            "os0-128" => Self::Os0_128(CatalogueSpec::default()),
            "os2-128" => Self::Os2_128(CatalogueSpec::default()),
            "pandar64" => Self::Pandar64(CatalogueSpec::default()),
            "pandar-xt32" => Self::PandarXt32(CatalogueSpec::default()),
            "rs-helios-5515" => Self::RsHelios5515(CatalogueSpec::default()),
            _ => {
                return Err(SimError::UnknownName {
                    kind: "sensor model",
                    name: name.to_string(),
                    known: MODELS.join(", "),
                });
            }
        })
    }

    /// Model name, e.g. `ibeo-lux`, `vlp16`.
    pub fn model_name(&self) -> String {
        match self {
            Self::IbeoLux(_) => "ibeo-lux",
            Self::Utm30lx(_) => "utm30lx",
            Self::Utm30lxNodding(_) => "utm30lx-nodding",
            Self::Vlp16(_) => "vlp16",
            Self::Hdl64e(_) => "hdl64e",
            Self::Os1_64(_) => "os1-64",
            Self::Os1_128(_) => "os1-128",
            Self::Custom(_) => "custom",
            Self::Hdl32e(_) => "hdl32e",
            Self::Vlp32c(_) => "vlp32c",
            Self::Vls128(_) => "vls128",
            Self::Os0_128(_) => "os0-128",
            Self::Os2_128(_) => "os2-128",
            Self::Pandar64(_) => "pandar64",
            Self::PandarXt32(_) => "pandar-xt32",
            Self::RsHelios5515(_) => "rs-helios-5515",
        }
        .to_string()
    }

    /// The rank of each of `rows` grid rows (0 lowest) in the order a driver writes one firing's
    /// lasers: the channel's index in a catalogued model's table, else the top beam first. With
    /// [`crate::io::kitti::firing_order`], a cloud's returns in its driver's point order.
    ///
    /// ```
    /// let spec = sim::sensor::SensorSpec::default_for("vlp16")?;
    /// assert_eq!(spec.firing_ranks(16)[15], 0); // the top beam fires first
    /// # Ok::<(), sim::SimError>(())
    /// ```
    pub fn firing_ranks(&self, rows: usize) -> Vec<usize> {
        match self.catalogued() {
            Some((entry, _)) => {
                let mut rank = vec![0; rows];
                for (row, channel) in entry.channel_of_row().into_iter().enumerate().take(rows) {
                    rank[row] = channel;
                }
                rank
            }
            None => (0..rows).map(|r| rows - 1 - r).collect(),
        }
    }

    /// The catalogue entry of a catalogued model and its settings (`None` for the built-in models).
    pub fn catalogued(&self) -> Option<(&'static CatalogueEntry, &CatalogueSpec)> {
        Some(match self {
            Self::Hdl32e(s) => (&catalogue::HDL32E, s),
            Self::Vlp32c(s) => (&catalogue::VLP32C, s),
            Self::Vls128(s) => (&catalogue::VLS128, s),
            Self::Os0_128(s) => (&catalogue::OS0_128, s),
            Self::Os2_128(s) => (&catalogue::OS2_128, s),
            Self::Pandar64(s) => (&catalogue::PANDAR64, s),
            Self::PandarXt32(s) => (&catalogue::PANDAR_XT32, s),
            Self::RsHelios5515(s) => (&catalogue::HELIOS_5515, s),
            Self::IbeoLux(_)
            | Self::Utm30lx(_)
            | Self::Utm30lxNodding(_)
            | Self::Vlp16(_)
            | Self::Hdl64e(_)
            | Self::Os1_64(_)
            | Self::Os1_128(_)
            | Self::Custom(_) => return None,
        })
    }

    /// The beams of one frame. Call [`SensorSpec::validate`] first: invalid parameters give a
    /// meaningless (possibly empty) pattern, never a panic.
    pub fn pattern(&self) -> ScanPattern {
        match self {
            Self::IbeoLux(s) => s.pattern(),
            Self::Utm30lx(s) => s.pattern(),
            Self::Utm30lxNodding(s) => s.pattern(),
            Self::Vlp16(s) => s.pattern(),
            Self::Hdl64e(s) => s.pattern(),
            Self::Os1_64(s) => s.pattern(),
            Self::Os1_128(s) => s.pattern(),
            Self::Custom(s) => s.pattern(),
            Self::Hdl32e(s) => s.pattern(&catalogue::HDL32E),
            Self::Vlp32c(s) => s.pattern(&catalogue::VLP32C),
            Self::Vls128(s) => s.pattern(&catalogue::VLS128),
            Self::Os0_128(s) => s.pattern(&catalogue::OS0_128),
            Self::Os2_128(s) => s.pattern(&catalogue::OS2_128),
            Self::Pandar64(s) => s.pattern(&catalogue::PANDAR64),
            Self::PandarXt32(s) => s.pattern(&catalogue::PANDAR_XT32),
            Self::RsHelios5515(s) => s.pattern(&catalogue::HELIOS_5515),
        }
    }

    /// The `measurement` overrides of the spec, to change (e.g. a noise level for a study).
    pub fn measurement_params_mut(&mut self) -> &mut MeasurementParams {
        match self {
            Self::IbeoLux(s) => &mut s.measurement,
            Self::Utm30lx(s) => &mut s.measurement,
            Self::Utm30lxNodding(s) => &mut s.measurement,
            Self::Vlp16(s) => &mut s.measurement,
            Self::Hdl64e(s) => &mut s.measurement,
            Self::Os1_64(s) => &mut s.measurement,
            Self::Os1_128(s) => &mut s.measurement,
            Self::Custom(s) => &mut s.measurement,
            Self::Hdl32e(s)
            | Self::Vlp32c(s)
            | Self::Vls128(s)
            | Self::Os0_128(s)
            | Self::Os2_128(s)
            | Self::Pandar64(s)
            | Self::PandarXt32(s)
            | Self::RsHelios5515(s) => &mut s.measurement,
        }
    }

    /// The range measurement model (the model's defaults with the `measurement` overrides applied).
    pub fn measurement(&self) -> Measurement {
        match self {
            Self::IbeoLux(s) => s.measurement(),
            Self::Utm30lx(s) => s.measurement(),
            Self::Utm30lxNodding(s) => s.measurement(),
            Self::Vlp16(s) => s.measurement(),
            Self::Hdl64e(s) => s.measurement(),
            Self::Os1_64(s) => s.measurement(),
            Self::Os1_128(s) => s.measurement(),
            Self::Custom(s) => s.measurement(),
            Self::Hdl32e(s) => s.measurement(&catalogue::HDL32E),
            Self::Vlp32c(s) => s.measurement(&catalogue::VLP32C),
            Self::Vls128(s) => s.measurement(&catalogue::VLS128),
            Self::Os0_128(s) => s.measurement(&catalogue::OS0_128),
            Self::Os2_128(s) => s.measurement(&catalogue::OS2_128),
            Self::Pandar64(s) => s.measurement(&catalogue::PANDAR64),
            Self::PandarXt32(s) => s.measurement(&catalogue::PANDAR_XT32),
            Self::RsHelios5515(s) => s.measurement(&catalogue::HELIOS_5515),
        }
    }

    /// Checks every parameter; errors name the field as `{field}.<name>` with the allowed range.
    pub fn validate(&self, field: &str) -> Result<()> {
        match self {
            Self::IbeoLux(s) => s.validate(field),
            Self::Utm30lx(s) => s.validate(field),
            Self::Utm30lxNodding(s) => s.validate(field),
            Self::Vlp16(s) => s.validate(field),
            Self::Hdl64e(s) => s.validate(field),
            Self::Os1_64(s) => s.validate(field),
            Self::Os1_128(s) => s.validate(field),
            Self::Custom(s) => s.validate(field),
            Self::Hdl32e(s) => s.validate(&catalogue::HDL32E, field),
            Self::Vlp32c(s) => s.validate(&catalogue::VLP32C, field),
            Self::Vls128(s) => s.validate(&catalogue::VLS128, field),
            Self::Os0_128(s) => s.validate(&catalogue::OS0_128, field),
            Self::Os2_128(s) => s.validate(&catalogue::OS2_128, field),
            Self::Pandar64(s) => s.validate(&catalogue::PANDAR64, field),
            Self::PandarXt32(s) => s.validate(&catalogue::PANDAR_XT32, field),
            Self::RsHelios5515(s) => s.validate(&catalogue::HELIOS_5515, field),
        }
    }
}
