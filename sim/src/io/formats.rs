//! Point-cloud writers per frame (PCD, PLY, KITTI, LAS). TODO(io helper): replace this stub.

use std::path::Path;

use glam::Affine3A;
use serde::{Deserialize, Serialize};

use crate::cloud::OrderedCloud;
use crate::error::Result;

/// Which files to write per frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Formats {
    /// Organized PCD (`frame_NNNNNN.pcd`).
    pub pcd: bool,
    /// PCD in ASCII rather than binary.
    pub pcd_ascii: bool,
    /// Binary little-endian PLY of the returns.
    pub ply: bool,
    /// SemanticKITTI `.bin` + `.label`.
    pub kitti: bool,
    /// LAS 1.4.
    pub las: bool,
}

/// A file written for a frame.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct WrittenFile {
    /// File name relative to the output directory.
    pub file: String,
    /// Format name (`pcd`, `ply`, `kitti-bin`, `kitti-label`, `las`).
    pub format: String,
    /// Number of points in the file.
    pub points: usize,
}

/// Everything a frame writer needs besides the cloud.
#[derive(Clone, Copy, Debug)]
pub struct FrameContext {
    /// Frame index (file stem `frame_{index:06}`).
    pub index: usize,
    /// For KITTI files of a single-sensor rig: the transform taking vehicle points to the sensor
    /// frame; `None` writes KITTI points in the vehicle frame.
    pub sensor_from_vehicle: Option<Affine3A>,
}

/// Writes the frame in every requested format into `dir`, atomically, and lists the files written.
pub fn write_frame(
    _dir: &Path,
    _cloud: &OrderedCloud,
    _ctx: &FrameContext,
    _formats: &Formats,
) -> Result<Vec<WrittenFile>> {
    Ok(Vec::new())
}
