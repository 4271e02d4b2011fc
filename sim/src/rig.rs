//! Rigs: one or more sensors, each with a `vehicle_from_sensor` mount; the built-in presets
//! ([`PRESETS`], see [`Rig::preset`] for every mount) and rig TOML files ([`Rig::from_toml_str`]).
//!
//! A rig file:
//! ```toml
//! name = "my-rig"                # optional, default the file stem
//! [[sensors]]
//! name = "front"
//! mount = { x_m = 3.7, y_m = 0.0, z_m = 0.5, pitch_deg = 1.0 }
//! spec = { model = "ibeo-lux", frequency_hz = 25.0 }
//! ```

use glam::{Affine3A, EulerRot, Quat, Vec3};
use serde::{Deserialize, Serialize};

use crate::sensor::SensorSpec;

mod load;
pub mod presets;

pub use presets::PRESETS;

/// Where a sensor sits on the vehicle: position in metres and roll / pitch / yaw in degrees
/// (ISO 8855 vehicle frame: x forward, y left, z up at ground level below the rear axle;
/// positive pitch tilts the sensor's x axis down, positive yaw turns it left).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Mount {
    /// Position x, metres.
    pub x_m: f32,
    /// Position y, metres.
    pub y_m: f32,
    /// Position z, metres.
    pub z_m: f32,
    /// Roll about x, degrees.
    #[serde(default)]
    pub roll_deg: f32,
    /// Pitch about y, degrees.
    #[serde(default)]
    pub pitch_deg: f32,
    /// Yaw about z, degrees.
    #[serde(default)]
    pub yaw_deg: f32,
}

impl Mount {
    /// The rigid transform taking sensor-frame points to the vehicle frame (yaw, then pitch, then roll).
    pub fn vehicle_from_sensor(&self) -> Affine3A {
        let rot = Quat::from_euler(
            EulerRot::ZYX,
            self.yaw_deg.to_radians(),
            self.pitch_deg.to_radians(),
            self.roll_deg.to_radians(),
        );
        Affine3A::from_rotation_translation(rot, Vec3::new(self.x_m, self.y_m, self.z_m))
    }
}

/// A sensor on a rig.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MountedSensor {
    /// Name unique within the rig, e.g. `front_left`.
    pub name: String,
    /// The model and its parameters.
    pub spec: SensorSpec,
    /// Where it sits.
    pub mount: Mount,
}

/// A set of sensors on one vehicle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rig {
    /// Rig name (preset name or file stem).
    #[serde(default)]
    pub name: String,
    /// The sensors; the index is the sensor id in clouds.
    pub sensors: Vec<MountedSensor>,
}
