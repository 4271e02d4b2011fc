//! What an input path holds: one file, a scan directory with its `manifest.json` (frames, their
//! indices and poses), or a directory of point-cloud files (in name order); and each file's layout,
//! decided once per file ([`InputLayout::decide`]: by name, by content or by `--layout`) and carried
//! in its frames' provenance with what decided it ([`LayoutBasis`]).

use std::path::{Path, PathBuf};

use glam::{Affine3A, Mat4};
use serde::Serialize;

use super::RecordingError;

/// How a file's points are laid out, decided once per file ([`InputLayout::decide`]): by its name,
/// by what its bytes give away (a headerless `.bin`: KITTI's 16-byte or nuScenes' 20-byte records,
/// [`sim::io::nuscenes::content_layout`]), or by the user's `--layout` ([`LayoutChoice`]); the one
/// place a new input layout is added.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum InputLayout {
    /// A PCD file (ours or a driver's; organized or not, any field order).
    Pcd,
    /// A PLY file.
    Ply,
    /// A LAS file.
    Las,
    /// KITTI-layout `.bin` records (x y z intensity, float32), a `.label` beside it where there is
    /// one.
    KittiBin,
    /// nuScenes-layout records (x y z intensity ring, float32: a `LIDAR_TOP` `.pcd.bin`); the ring
    /// orders the points ([`crate::ordering::table::ring_wishes`]).
    NuscenesBin,
    /// A `sensor_msgs/msg/PointCloud2` message of a ROS 2 bag.
    PointCloud2,
}

/// What decided a file's [`InputLayout`], as the reports name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LayoutBasis {
    /// The file's name (its extension; `.pcd.bin` is nuScenes).
    Name,
    /// What the file's bytes give away (a `.bin` whose length fits only nuScenes' records, or both
    /// layouts and a whole ring number as every point's fifth value).
    Content,
    /// The user's `--layout` (`layout=` in Python).
    Flag,
}

impl LayoutBasis {
    /// The name the reports print: `name`, `content` or `flag`.
    pub fn name(self) -> &'static str {
        match self {
            LayoutBasis::Name => "name",
            LayoutBasis::Content => "content",
            LayoutBasis::Flag => "flag",
        }
    }
}

/// The layout a user names for headerless `.bin` files (`--layout`), overriding the name and the
/// content.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayoutChoice {
    /// KITTI records: x y z intensity.
    Kitti,
    /// nuScenes records: x y z intensity ring.
    Nuscenes,
}

impl LayoutChoice {
    /// The names `--layout` takes.
    pub const NAMES: [&'static str; 2] = ["kitti", "nuscenes"];

    /// The choice called `name`; refused, listing [`LayoutChoice::NAMES`], for any other.
    pub fn named(name: &str) -> Result<Self, RecordingError> {
        match name {
            "kitti" => Ok(Self::Kitti),
            "nuscenes" => Ok(Self::Nuscenes),
            _ => Err(RecordingError::UnknownLayout { name: name.to_string() }),
        }
    }

    /// Its name, as `--layout` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Kitti => "kitti",
            Self::Nuscenes => "nuscenes",
        }
    }

    /// The layout it names.
    pub fn layout(self) -> InputLayout {
        match self {
            Self::Kitti => InputLayout::KittiBin,
            Self::Nuscenes => InputLayout::NuscenesBin,
        }
    }
}

impl InputLayout {
    /// The file extensions of the file layouts, as listed in messages.
    pub const EXTENSIONS: &'static str = ".pcd, .ply, .las, .bin or .pcd.bin";

    /// The layout of the file `path` from its name (any case): `.pcd.bin` is nuScenes, any other
    /// `.bin` KITTI (its content may say otherwise: [`InputLayout::decide`]); `None` for a file of
    /// no layout the reader knows.
    pub fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "pcd" => Self::Pcd,
            "ply" => Self::Ply,
            "las" => Self::Las,
            "bin"
                if path
                    .file_stem()
                    .and_then(|s| Path::new(s).extension())
                    .is_some_and(|e| e.eq_ignore_ascii_case("pcd")) =>
            {
                Self::NuscenesBin
            }
            "bin" => Self::KittiBin,
            _ => return None,
        })
    }

    /// The layout of `path` from its name, or an error naming the file and the layouts there are.
    pub fn of_file(path: &Path) -> Result<Self, RecordingError> {
        Self::of(path).ok_or_else(|| RecordingError::Unsupported { path: path.to_path_buf() })
    }

    /// Whether the layout is a headerless `.bin` (KITTI or nuScenes), whose layout `--layout` may
    /// name.
    pub fn is_raw(self) -> bool {
        matches!(self, Self::KittiBin | Self::NuscenesBin)
    }

    /// The layout of the file `path` whose bytes are `bytes`, and what decided it: `choice`
    /// (`--layout`) where given; else a `.pcd.bin` name (nuScenes; its reader refuses a file that
    /// is not); else, for a `.bin`, what its bytes give away
    /// ([`sim::io::nuscenes::content_layout`]: nuScenes where only its 20-byte records fit or
    /// every point's fifth value is a whole ring number, KITTI by name otherwise); else the name.
    /// Refused, naming the file: a name of no known layout, a `.bin` whose length fits neither
    /// layout, a `choice` for a file that is not a headerless `.bin`.
    pub fn decide(
        path: &Path,
        bytes: &[u8],
        choice: Option<LayoutChoice>,
    ) -> Result<(Self, LayoutBasis), RecordingError> {
        let by_name = Self::of_file(path)?;
        match (by_name, choice) {
            (named, Some(c)) if named.is_raw() => Ok((c.layout(), LayoutBasis::Flag)),
            (named, Some(c)) => Err(RecordingError::LayoutOfNonRaw { path: path.to_path_buf(), choice: c, named }),
            (Self::KittiBin, None) => match sim::io::nuscenes::content_layout(path, bytes)?.0 {
                sim::io::nuscenes::RawLayout::Nuscenes => Ok((Self::NuscenesBin, LayoutBasis::Content)),
                sim::io::nuscenes::RawLayout::Kitti => Ok((Self::KittiBin, LayoutBasis::Name)),
            },
            (named, None) => Ok((named, LayoutBasis::Name)),
        }
    }

    /// What the reports call the layout: `KITTI .bin (x y z intensity)`, `nuScenes .pcd.bin (x y z
    /// intensity ring)`, `PCD`, ...
    pub fn description(self) -> &'static str {
        match self {
            Self::Pcd => "PCD",
            Self::Ply => "PLY",
            Self::Las => "LAS",
            Self::KittiBin => "KITTI .bin (x y z intensity)",
            Self::NuscenesBin => "nuScenes .pcd.bin (x y z intensity ring)",
            Self::PointCloud2 => "PointCloud2",
        }
    }
}

/// One frame's file of an input.
#[derive(Clone, Debug, PartialEq)]
pub struct InputFile {
    /// Frame index: from the manifest, else from a `frame_NNNNNN` name, else the file's place in
    /// name order.
    pub index: usize,
    /// The file.
    pub path: PathBuf,
    /// The vehicle's pose (a scan directory's manifest); `None` where unknown.
    pub world_from_vehicle: Option<Affine3A>,
}

/// The index of a `frame_NNNNNN.*` file, else `fallback`.
fn frame_index_from_name(path: &Path, fallback: usize) -> usize {
    path.file_stem()
        .and_then(|s| s.to_str())
        .and_then(|s| s.strip_prefix("frame_"))
        .and_then(|s| s.parse().ok())
        .unwrap_or(fallback)
}

/// The frames' files of `input`: one file; a scan directory's frames from its `manifest.json`
/// (with their poses); or every file of a known layout in a directory, in name order. Refused: a
/// path that is neither a file nor a directory, a directory with no such file.
pub fn list_files(input: &Path) -> Result<Vec<InputFile>, RecordingError> {
    if input.is_file() {
        return Ok(vec![InputFile {
            index: frame_index_from_name(input, 0),
            path: input.to_path_buf(),
            world_from_vehicle: None,
        }]);
    }
    if !input.is_dir() {
        return Err(RecordingError::NotFound { path: input.to_path_buf() });
    }
    if input.join("manifest.json").is_file() {
        let m = sim::io::manifest::Manifest::read(input)?;
        return Ok(m
            .frames
            .iter()
            .map(|f| {
                let mat = Mat4::from_cols_array_2d(&f.world_from_vehicle).transpose();
                InputFile {
                    index: f.index,
                    path: input.join(&f.file),
                    world_from_vehicle: Some(Affine3A::from_mat4(mat)),
                }
            })
            .collect());
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(input)
        .map_err(|e| RecordingError::Io { path: input.to_path_buf(), error: e })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && InputLayout::of(p).is_some())
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(RecordingError::Empty { path: input.to_path_buf() });
    }
    Ok(files
        .into_iter()
        .enumerate()
        .map(|(k, p)| InputFile { index: frame_index_from_name(&p, k), path: p, world_from_vehicle: None })
        .collect())
}
