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
//!
//! Grid rule (all models, see [`ScanPattern`]): row 0 lowest, rows up in elevation; column 0
//! left-most, azimuth decreasing with the column. Spinning sensors with staggered beams are
//! destaggered ([`spinning`]); the nodding Hokuyo's rows are scans ([`nodding`]).

pub mod custom;
pub mod hokuyo;
pub mod lux;
pub mod measure;
pub mod nodding;
pub mod ouster;
mod pattern;
pub mod spinning;
pub mod velodyne;

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

/// The model names, as written in TOML (`model = "..."`).
pub const MODELS: &[&str] =
    &["ibeo-lux", "utm30lx", "utm30lx-nodding", "vlp16", "hdl64e", "os1-64", "os1-128", "custom"];

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
        }
        .to_string()
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
        }
    }
}
