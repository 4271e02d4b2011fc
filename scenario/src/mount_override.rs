//! Overrides of a sensor's mount (position and attitude), checked against their allowed ranges.

use sim::rig::Mount;

use crate::error::{Result, ScenarioError};

/// Overrides of one sensor's mount; `None` keeps the rig's value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MountOverride {
    /// Position x, metres (-50 ..= 50).
    pub x_m: Option<f32>,
    /// Position y, metres (-50 ..= 50).
    pub y_m: Option<f32>,
    /// Height above the ground, metres (-5 ..= 20).
    pub z_m: Option<f32>,
    /// Roll, degrees (-180 ..= 180).
    pub roll_deg: Option<f32>,
    /// Pitch, degrees, positive tilts the sensor down (-90 ..= 90).
    pub pitch_deg: Option<f32>,
    /// Yaw, degrees, positive turns it left (-360 ..= 360).
    pub yaw_deg: Option<f32>,
}

impl MountOverride {
    /// Checks every set field, naming `mount.<field>` and its range.
    pub fn validate(&self) -> Result<()> {
        let fields = [
            ("mount.x_m", self.x_m, -50.0, 50.0),
            ("mount.y_m", self.y_m, -50.0, 50.0),
            ("mount.z_m", self.z_m, -5.0, 20.0),
            ("mount.roll_deg", self.roll_deg, -180.0, 180.0),
            ("mount.pitch_deg", self.pitch_deg, -90.0, 90.0),
            ("mount.yaw_deg", self.yaw_deg, -360.0, 360.0),
        ];
        for (name, v, lo, hi) in fields {
            if let Some(v) = v
                && !(v.is_finite() && (lo..=hi).contains(&v))
            {
                return Err(ScenarioError::invalid(name, v, format!("{lo} ..= {hi}")));
            }
        }
        Ok(())
    }

    /// `mount` with the set fields replaced.
    pub fn apply(&self, mount: Mount) -> Mount {
        Mount {
            x_m: self.x_m.unwrap_or(mount.x_m),
            y_m: self.y_m.unwrap_or(mount.y_m),
            z_m: self.z_m.unwrap_or(mount.z_m),
            roll_deg: self.roll_deg.unwrap_or(mount.roll_deg),
            pitch_deg: self.pitch_deg.unwrap_or(mount.pitch_deg),
            yaw_deg: self.yaw_deg.unwrap_or(mount.yaw_deg),
        }
    }
}
