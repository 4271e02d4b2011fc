//! Point-cloud writers per frame: [`write_frame`] writes a frame in every requested format
//! (PCD, PLY, KITTI, LAS; see [`super::pcd`], [`super::ply`], [`super::kitti`], [`super::las`]),
//! each file atomically, and lists the files written with their point counts.
//!
//! The PCD is our organized layout unless [`Formats::pcd_layout`] names a ROS driver's (velodyne,
//! ouster: sensor-frame points for a single-sensor rig, see [`super::pcd::PcdLayout`]).
//!
//! File names per frame `k` (stem `frame_{k:06}`): `.pcd`, `.ply`, `.bin` + `.label` (+
//! `.calib.txt` when the KITTI points are in the sensor frame), `.las`, `.laz`. The formats are encoded
//! in parallel (rayon); the bytes do not depend on the thread count.

use std::path::Path;

use glam::Affine3A;
use serde::{Deserialize, Serialize};

use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};

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
    /// LAZ (compressed LAS 1.4, same content; needs the `laz` cargo feature).
    pub laz: bool,
    /// A ROS 2 bag of the whole scan (rosbag2 directory `bag/`, [`super::ros2`]); written by the
    /// scan, not per frame: [`write_frame`] leaves it to the caller.
    pub mcap: bool,
    /// Layout of the organized PCD: ours (default) or a ROS driver's ([`super::pcd::PcdLayout`]).
    pub pcd_layout: super::pcd::PcdLayout,
}

impl Formats {
    /// The names [`Formats::parse`] accepts.
    pub const NAMES: [&'static str; 7] = ["pcd", "pcd-ascii", "ply", "kitti", "las", "laz", "mcap"];

    /// Parses a comma-separated list such as `pcd,ply,kitti,las` (`pcd-ascii` = PCD in ASCII).
    /// Unknown names are refused with the list of allowed ones; an empty list is refused.
    pub fn parse(list: &str) -> Result<Self> {
        let mut f = Formats::default();
        for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            match name.to_ascii_lowercase().as_str() {
                "pcd" => f.pcd = true,
                "pcd-ascii" => {
                    f.pcd = true;
                    f.pcd_ascii = true
                }
                "ply" => f.ply = true,
                "kitti" => f.kitti = true,
                "las" => f.las = true,
                "mcap" => f.mcap = true,
                "laz" if cfg!(feature = "laz") => f.laz = true,
                "laz" => {
                    return Err(SimError::invalid(
                        "format",
                        "laz",
                        "pcd, pcd-ascii, ply, kitti, las, mcap (this build has no LAZ: build with `--features sim/laz`)",
                    ));
                }
                _ => return Err(SimError::invalid("format", name, Self::NAMES.join(", "))),
            }
        }
        if !(f.pcd || f.ply || f.kitti || f.las || f.laz || f.mcap) {
            return Err(SimError::invalid(
                "format",
                format!("`{list}`"),
                format!("one or more of {}", Self::NAMES.join(", ")),
            ));
        }
        Ok(f)
    }
}

/// A file written for a frame.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct WrittenFile {
    /// File name relative to the output directory.
    pub file: String,
    /// Format name (`pcd`, `ply`, `kitti-bin`, `kitti-label`, `kitti-calib`, `las`, `laz`).
    pub format: String,
    /// Number of points in the file (0 for the calibration file).
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

impl FrameContext {
    /// The frame the KITTI points are in, as the manifest's `kitti_frame` says it:
    /// `"sensor"` or `"vehicle"`.
    pub fn kitti_frame(&self) -> &'static str {
        if self.sensor_from_vehicle.is_some() { "sensor" } else { "vehicle" }
    }

    /// File stem `frame_NNNNNN`.
    pub fn stem(&self) -> String {
        format!("frame_{:06}", self.index)
    }
}

fn written(file: String, format: &str, points: usize) -> WrittenFile {
    WrittenFile { file, format: format.to_string(), points }
}

fn write_pcd(
    dir: &Path,
    stem: &str,
    cloud: &OrderedCloud,
    formats: &Formats,
    ctx: &FrameContext,
) -> Result<Vec<WrittenFile>> {
    let name = format!("{stem}.pcd");
    let n = super::pcd::write_layout(
        &dir.join(&name),
        cloud,
        formats.pcd_layout,
        formats.pcd_ascii,
        ctx.sensor_from_vehicle.as_ref(),
    )?;
    Ok(vec![written(name, "pcd", n)])
}

fn write_ply(dir: &Path, stem: &str, cloud: &OrderedCloud) -> Result<Vec<WrittenFile>> {
    let name = format!("{stem}.ply");
    let n = super::ply::write(&dir.join(&name), cloud)?;
    Ok(vec![written(name, "ply", n)])
}

fn write_kitti(dir: &Path, stem: &str, cloud: &OrderedCloud, ctx: &FrameContext) -> Result<Vec<WrittenFile>> {
    let sensor_from_vehicle = ctx.sensor_from_vehicle.as_ref();
    if let Some(t) = sensor_from_vehicle
        && (!t.is_finite() || t.matrix3.determinant().abs() < 1e-6)
    {
        return Err(SimError::invalid("sensor_from_vehicle", format!("{t:?}"), "a finite rigid transform"));
    }
    let (bin, label, n) = super::kitti::encode(cloud, sensor_from_vehicle)?;
    let (bin_name, label_name) = (format!("{stem}.bin"), format!("{stem}.label"));
    super::atomic::write_bytes_atomic(&dir.join(&bin_name), &bin)?;
    super::atomic::write_bytes_atomic(&dir.join(&label_name), &label)?;
    let mut files = vec![written(bin_name, "kitti-bin", n), written(label_name, "kitti-label", n)];
    if let Some(t) = sensor_from_vehicle {
        let calib_name = format!("{stem}.calib.txt");
        let text = super::kitti::calib_text(&t.inverse());
        super::atomic::write_bytes_atomic(&dir.join(&calib_name), text.as_bytes())?;
        files.push(written(calib_name, "kitti-calib", 0));
    }
    Ok(files)
}

fn write_las(dir: &Path, stem: &str, cloud: &OrderedCloud, formats: &Formats) -> Result<Vec<WrittenFile>> {
    let mut files = Vec::new();
    for (on, ext, compressed) in [(formats.las, "las", false), (formats.laz, "laz", true)] {
        if on {
            let name = format!("{stem}.{ext}");
            let n = super::las::write_with(&dir.join(&name), cloud, compressed)?;
            files.push(written(name, ext, n));
        }
    }
    Ok(files)
}

/// Writes the frame in every requested format into `dir`, atomically, and lists the files written
/// (in the order PCD, PLY, KITTI `.bin`, `.label`, calibration, LAS, LAZ).
pub fn write_frame(
    dir: &Path,
    cloud: &OrderedCloud,
    ctx: &FrameContext,
    formats: &Formats,
) -> Result<Vec<WrittenFile>> {
    cloud.check_consistent().map_err(|m| SimError::invalid("cloud", m, "every field planes*rows*cols long"))?;
    let stem = ctx.stem();
    let none = || Ok(Vec::new());
    let ((pcd, ply), (kitti, las)) = rayon::join(
        || {
            rayon::join(
                || if formats.pcd { write_pcd(dir, &stem, cloud, formats, ctx) } else { none() },
                || if formats.ply { write_ply(dir, &stem, cloud) } else { none() },
            )
        },
        || {
            rayon::join(
                || if formats.kitti { write_kitti(dir, &stem, cloud, ctx) } else { none() },
                || if formats.las || formats.laz { write_las(dir, &stem, cloud, formats) } else { none() },
            )
        },
    );
    let mut files = pcd?;
    files.extend(ply?);
    files.extend(kitti?);
    files.extend(las?);
    Ok(files)
}
