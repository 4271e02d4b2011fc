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
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};

/// One file format a frame can be written in: the one list every front end (the CLI's `--format`,
/// dataset files, Python's `write`) takes its names from. To add a format, add it here, to
/// [`write_file`] and to [`Formats`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Organized binary PCD (`.pcd`).
    Pcd,
    /// Organized ASCII PCD (`.pcd`).
    PcdAscii,
    /// Binary little-endian PLY of the returns (`.ply`).
    Ply,
    /// SemanticKITTI `.bin` + `.label` (+ `.calib.txt` for sensor-frame points).
    Kitti,
    /// LAS 1.4 (`.las`).
    Las,
    /// LAZ, compressed LAS 1.4 (`.laz`; needs the `laz` cargo feature).
    Laz,
    /// A ROS 2 bag of the whole scan (rosbag2 directory with one MCAP file; [`super::ros2`]).
    Mcap,
}

impl Format {
    /// Every format, in the order of [`Format::name`]s in messages.
    pub const ALL: [Format; 7] =
        [Format::Pcd, Format::PcdAscii, Format::Ply, Format::Kitti, Format::Las, Format::Laz, Format::Mcap];

    /// The name front ends take (`pcd`, `pcd-ascii`, `ply`, `kitti`, `las`, `laz`, `mcap`).
    pub fn name(self) -> &'static str {
        match self {
            Format::Pcd => "pcd",
            Format::PcdAscii => "pcd-ascii",
            Format::Ply => "ply",
            Format::Kitti => "kitti",
            Format::Las => "las",
            Format::Laz => "laz",
            Format::Mcap => "mcap",
        }
    }

    /// Whether this build writes the format (LAZ needs the `laz` cargo feature).
    pub fn available(self) -> bool {
        self != Format::Laz || cfg!(feature = "laz")
    }

    /// The names of the formats this build writes, in [`Format::ALL`]'s order.
    pub fn available_names() -> Vec<&'static str> {
        Format::ALL.into_iter().filter(|f| f.available()).map(Format::name).collect()
    }

    /// The extension of the frame's main file (`bin` for KITTI; `mcap` for the bag's file).
    pub fn extension(self) -> &'static str {
        match self {
            Format::Pcd | Format::PcdAscii => "pcd",
            Format::Kitti => "bin",
            other => other.name(),
        }
    }

    /// The format a file extension names (`pcd`, `ply`, `bin`, `las`, `laz`, `mcap`), if any.
    pub fn from_extension(extension: &str) -> Option<Format> {
        match extension.to_ascii_lowercase().as_str() {
            "pcd" => Some(Format::Pcd),
            "ply" => Some(Format::Ply),
            "bin" => Some(Format::Kitti),
            "las" => Some(Format::Las),
            "laz" => Some(Format::Laz),
            "mcap" => Some(Format::Mcap),
            _ => None,
        }
    }

    /// Parses a name (case-insensitive), refusing an unknown one with the allowed names under
    /// `field`, and `laz` where this build has no LAZ.
    pub fn parse_field(name: &str, field: &str) -> Result<Format> {
        let lower = name.trim().to_ascii_lowercase();
        match Format::ALL.into_iter().find(|f| f.name() == lower) {
            Some(Format::Laz) if !cfg!(feature = "laz") => Err(SimError::invalid(
                field,
                "laz",
                "pcd, pcd-ascii, ply, kitti, las, mcap (this build has no LAZ: build with `--features sim/laz`)",
            )),
            Some(f) => Ok(f),
            None => Err(SimError::invalid(field, name, Formats::NAMES.join(", "))),
        }
    }
}

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

    /// The per-frame formats chosen, in the order [`write_frame`] lists their files (the bag is the
    /// scan's, not a frame's).
    pub fn per_frame(&self) -> Vec<Format> {
        let pcd = if self.pcd_ascii { Format::PcdAscii } else { Format::Pcd };
        [
            (self.pcd, pcd),
            (self.ply, Format::Ply),
            (self.kitti, Format::Kitti),
            (self.las, Format::Las),
            (self.laz, Format::Laz),
        ]
        .into_iter()
        .filter_map(|(on, f)| on.then_some(f))
        .collect()
    }

    /// Parses a comma-separated list such as `pcd,ply,kitti,las` (`pcd-ascii` = PCD in ASCII).
    /// Unknown names are refused with the list of allowed ones; an empty list is refused.
    pub fn parse(list: &str) -> Result<Self> {
        let mut f = Formats::default();
        for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            match Format::parse_field(name, "format")? {
                Format::Pcd => f.pcd = true,
                Format::PcdAscii => {
                    f.pcd = true;
                    f.pcd_ascii = true
                }
                Format::Ply => f.ply = true,
                Format::Kitti => f.kitti = true,
                Format::Las => f.las = true,
                Format::Laz => f.laz = true,
                Format::Mcap => f.mcap = true,
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

/// Writes `cloud` as one file of `format` at `path`, atomically, and lists what it wrote: KITTI
/// also writes the `.label` beside the `.bin` (and `STEM.calib.txt` where the points are in the
/// sensor frame, `sensor_from_vehicle`, which the PCD's driver layouts use too). `Mcap` is a
/// whole scan's bag, not one file: refused here ([`super::ros2`] writes it). File names in the list
/// are relative to `path`'s directory.
pub fn write_file(
    path: &Path,
    cloud: &OrderedCloud,
    format: Format,
    pcd_layout: super::pcd::PcdLayout,
    sensor_from_vehicle: Option<&Affine3A>,
) -> Result<Vec<WrittenFile>> {
    let name = |p: &Path| p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let one = |n: usize, format: &str| Ok(vec![written(name(path), format, n)]);
    match format {
        Format::Pcd | Format::PcdAscii => {
            let n = super::pcd::write_layout(path, cloud, pcd_layout, format == Format::PcdAscii, sensor_from_vehicle)?;
            one(n, "pcd")
        }
        Format::Ply => one(super::ply::write(path, cloud)?, "ply"),
        Format::Las => one(super::las::write_with(path, cloud, false)?, "las"),
        Format::Laz => one(super::las::write_with(path, cloud, true)?, "laz"),
        Format::Kitti => {
            if let Some(t) = sensor_from_vehicle
                && (!t.is_finite() || t.matrix3.determinant().abs() < 1e-6)
            {
                return Err(SimError::invalid("sensor_from_vehicle", format!("{t:?}"), "a finite rigid transform"));
            }
            let (bin, label, n) = super::kitti::encode(cloud, sensor_from_vehicle)?;
            let label_path = path.with_extension("label");
            super::atomic::write_bytes_atomic(path, &bin)?;
            super::atomic::write_bytes_atomic(&label_path, &label)?;
            let mut files = vec![written(name(path), "kitti-bin", n), written(name(&label_path), "kitti-label", n)];
            if let Some(t) = sensor_from_vehicle {
                let calib_path = path.with_file_name(format!("{}.calib.txt", name(&path.with_extension(""))));
                let text = super::kitti::calib_text(&t.inverse());
                super::atomic::write_bytes_atomic(&calib_path, text.as_bytes())?;
                files.push(written(name(&calib_path), "kitti-calib", 0));
            }
            Ok(files)
        }
        Format::Mcap => Err(SimError::invalid("format", "mcap", "a per-frame format (the bag is written per scan)")),
    }
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
    let sensor_from_vehicle = ctx.sensor_from_vehicle.as_ref();
    // The PCD's sensor frame is its layout's (a driver's); KITTI's is the context's.
    let write = |format: Format| {
        let path = dir.join(format!("{stem}.{}", format.extension()));
        write_file(&path, cloud, format, formats.pcd_layout, sensor_from_vehicle)
    };
    let per_frame = formats.per_frame();
    let written: Vec<Result<Vec<WrittenFile>>> = per_frame.into_par_iter().map(write).collect();
    let mut files = Vec::new();
    for w in written {
        files.extend(w?);
    }
    Ok(files)
}
