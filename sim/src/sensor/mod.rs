//! Sensor models: each turns its parameters into a [`ScanPattern`] (the beams of one frame on an
//! ordered grid) and a [`Measurement`] (range limits, noise, quantisation, echoes).
//! TODO(sensor helper): the models.

mod pattern;

pub use pattern::{Firing, Measurement, ScanPattern};

use serde::{Deserialize, Serialize};

/// A sensor model and its parameters (TOML: a table with `model = "..."`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum SensorSpec {}

impl SensorSpec {
    /// Model name, e.g. `ibeo-lux`, `vlp16`.
    pub fn model_name(&self) -> String {
        match *self {}
    }
    /// The beams of one frame.
    pub fn pattern(&self) -> ScanPattern {
        match *self {}
    }
    /// The range measurement model.
    pub fn measurement(&self) -> Measurement {
        match *self {}
    }
}
