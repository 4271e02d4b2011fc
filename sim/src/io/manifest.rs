//! `manifest.json`: what a scan wrote and how (scene, rig, seed, sensors and their mounts, grid
//! layout, and per frame the files, counts and vehicle pose). Other tools and our own commands
//! (`render`, `classify`) read it.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::formats::WrittenFile;
use crate::error::{Result, SimError};
use crate::motion::VehiclePose;
use crate::sensor::Measurement;

/// Manifest schema version.
pub const MANIFEST_VERSION: u32 = 1;

/// One sensor of the rig, as scanned.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorEntry {
    /// Sensor id (index in the rig and value of the `sensor` field of points).
    pub id: usize,
    /// Name in the rig.
    pub name: String,
    /// Model name.
    pub model: String,
    /// Rows of the sensor's own grid.
    pub rows: usize,
    /// Columns of the sensor's own grid.
    pub columns: usize,
    /// 4x4 row-major matrix taking sensor-frame points to the vehicle frame.
    pub vehicle_from_sensor: [[f32; 4]; 4],
    /// The mount it was computed from (metres, degrees).
    pub mount: crate::rig::Mount,
    /// Measurement model in force (ideal when the scan was ideal).
    pub measurement: Measurement,
    /// `merged_row_of_ring[r]`: the row of the merged grid holding this sensor's ring `r`.
    pub merged_row_of_ring: Vec<usize>,
}

/// One frame of the scan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameEntry {
    /// Frame index.
    pub index: usize,
    /// The main cloud file (the PCD if written, else the first file).
    pub file: String,
    /// Grid rows (times echo planes, as in the PCD's HEIGHT).
    pub rows: usize,
    /// Grid columns.
    pub cols: usize,
    /// Cells with a return.
    pub returns: usize,
    /// Returns on ground-truth ground.
    pub ground_returns: usize,
    /// Start of the frame, seconds since the start of the scan.
    pub start_time_s: f64,
    /// Vehicle pose at the start of the frame.
    pub vehicle_pose: VehiclePose,
    /// 4x4 row-major `world_from_vehicle` of `vehicle_pose`.
    pub world_from_vehicle: [[f32; 4]; 4],
    /// Every file written for this frame with its point count.
    pub files: Vec<WrittenFile>,
}

/// The whole manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Schema version ([`MANIFEST_VERSION`]).
    pub version: u32,
    /// Version of the program that wrote it.
    pub generator: String,
    /// Scene name or file.
    pub scene: String,
    /// Rig name or file.
    pub rig: String,
    /// Seed of the scan.
    pub seed: u64,
    /// Whether measurement effects were off.
    pub ideal: bool,
    /// Ego speed, metres per second.
    pub speed_m_per_s: f32,
    /// Ego yaw rate, radians per second.
    pub yaw_rate_rad_per_s: f32,
    /// The weather the scan was made in (`fog:visibility_m=50`; absent without weather).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weather: Option<String>,
    /// Frame period, seconds.
    pub frame_period_s: f64,
    /// Frame in which KITTI files hold their points: `sensor` (single-sensor rig) or `vehicle`.
    pub kitti_frame: String,
    /// Layout of the PCD files: `groundtruth` (ours), `velodyne` or `ouster` (the ROS drivers';
    /// `sim::io::pcd::PcdLayout`). Absent in older manifests: `groundtruth`.
    #[serde(default = "default_pcd_layout")]
    pub pcd_layout: String,
    /// Echo planes of the grid (PCD HEIGHT = planes x merged rows).
    pub planes: usize,
    /// How the grid is ordered (a sentence).
    pub ordering: String,
    /// The rig's sensors.
    pub sensors: Vec<SensorEntry>,
    /// The frames.
    pub frames: Vec<FrameEntry>,
    /// The full description the scan was made from (`groundtruth_scenario::ScanSpec` as JSON;
    /// `groundtruth scan --spec` takes it back to remake the files). Absent in older manifests.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spec: Option<serde_json::Value>,
}

fn default_pcd_layout() -> String {
    "groundtruth".into()
}

impl Manifest {
    /// Reads `DIR/manifest.json`.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join("manifest.json");
        let text = std::fs::read_to_string(&path).map_err(|e| SimError::io(&path, e))?;
        let m: Self = serde_json::from_str(&text).map_err(|e| SimError::bad_file(&path, e.to_string()))?;
        if m.version != MANIFEST_VERSION {
            return Err(SimError::bad_file(
                &path,
                format!("manifest version {} (this build reads {MANIFEST_VERSION})", m.version),
            ));
        }
        Ok(m)
    }

    /// Writes `DIR/manifest.json` atomically (pretty JSON).
    pub fn write(&self, dir: &Path) -> Result<()> {
        let path = dir.join("manifest.json");
        let mut text = serde_json::to_string_pretty(self).map_err(|e| SimError::bad_file(&path, e.to_string()))?;
        text.push('\n');
        super::atomic::write_bytes_atomic(&path, text.as_bytes())
    }
}

/// A 4x4 row-major matrix of an affine transform.
pub fn matrix_rows(a: &glam::Affine3A) -> [[f32; 4]; 4] {
    let m = glam::Mat4::from(*a).transpose();
    m.to_cols_array_2d()
}

/// The affine transform of a 4x4 row-major matrix written by [`matrix_rows`].
pub fn affine_from_rows(rows: &[[f32; 4]; 4]) -> glam::Affine3A {
    glam::Affine3A::from_mat4(glam::Mat4::from_cols_array_2d(rows).transpose())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrix_rows_round_trip_and_put_translation_in_the_last_column() {
        let a =
            glam::Affine3A::from_rotation_translation(glam::Quat::from_rotation_z(0.3), glam::Vec3::new(1.0, 2.0, 3.0));
        let rows = matrix_rows(&a);
        assert_eq!([rows[0][3], rows[1][3], rows[2][3]], [1.0, 2.0, 3.0]);
        assert_eq!(rows[3], [0.0, 0.0, 0.0, 1.0]);
        assert!(affine_from_rows(&rows).abs_diff_eq(a, 1e-6));
    }
}
