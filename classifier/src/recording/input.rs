//! What an input path holds: one file, a scan directory with its `manifest.json` (frames, their
//! indices and poses), or a directory of point-cloud files (in name order); and each file's layout,
//! decided once per file ([`InputLayout::of`]) and carried in its frames' provenance.

use std::path::{Path, PathBuf};

use glam::{Affine3A, Mat4};
use serde::Serialize;

use super::RecordingError;

/// How a file's points are laid out, decided per file from its name: the one place a new input
/// layout (nuScenes' `.pcd.bin`, a `--layout` choice) is added.
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
    /// A `sensor_msgs/msg/PointCloud2` message of a ROS 2 bag.
    PointCloud2,
}

impl InputLayout {
    /// The file extensions of the file layouts, as listed in messages.
    pub const EXTENSIONS: &'static str = ".pcd, .ply, .las or .bin";

    /// The layout of the file `path`, from its extension (any case); `None` for a file of no
    /// layout the reader knows.
    pub fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "pcd" => Self::Pcd,
            "ply" => Self::Ply,
            "las" => Self::Las,
            "bin" => Self::KittiBin,
            _ => return None,
        })
    }

    /// The layout of `path`, or an error naming the file and the layouts there are.
    pub fn of_file(path: &Path) -> Result<Self, RecordingError> {
        Self::of(path).ok_or_else(|| RecordingError::Unsupported { path: path.to_path_buf() })
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
