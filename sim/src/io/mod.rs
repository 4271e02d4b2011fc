//! Files: atomic writes, the scan manifest, and point-cloud formats.
//!
//! Writers (one file per format and frame, all written atomically): [`pcd`] (organized PCD, binary
//! or ASCII), [`ply`] (binary little-endian PLY of the returns), [`kitti`] (SemanticKITTI `.bin` +
//! `.label` + calibration) and [`las`] (LAS 1.4, point format 6); [`nuscenes`] reads nuScenes'
//! `.pcd.bin` sweeps (and tells them from KITTI `.bin` files) and their lidarseg labels. [`formats::write_frame`] writes
//! the requested subset for one frame. Readers for PCD, PLY and KITTI accept our own files and
//! other tools' files and never panic on malformed input: they return [`crate::SimError::BadFile`]
//! naming the file and what is wrong.

pub mod atomic;
pub mod formats;
pub mod kitti;
pub mod las;
mod lzf;
pub mod manifest;
pub mod nuscenes;
pub mod pcd;
pub mod ply;
pub(crate) mod plyfile;
mod read_util;
pub mod ros2;
