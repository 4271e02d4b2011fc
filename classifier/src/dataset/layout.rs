//! Which sequences and frames a labelled dataset directory holds, and reading one frame.
//!
//! Two layouts ([`FrameFormat`]):
//!
//! - **SemanticKITTI**: a dataset root holds `sequences/NN/velodyne/NNNNNN.bin` with
//!   `sequences/NN/labels/NNNNNN.label` beside them (SemanticKITTI's, KITTI-360 and others
//!   converted to it, and `groundtruth dataset`'s output); a single sequence's folder holding
//!   `velodyne/` and `labels/` is taken too. Frames are sorted by file name. `.bin`: float32
//!   `x y z intensity` records (sensor frame); `.label`: one uint32 per point, the class id in the
//!   lower 16 bits (the instance in the upper).
//! - **nuScenes-lidarseg**: a folder holding `lidar/NAME.pcd.bin` (nuScenes sweeps: float32 `x y z
//!   intensity ring`) with `lidarseg/NAME_lidarseg.bin` beside them (one uint8 class id per point):
//!   nuScenes keeps the sweeps as `samples/LIDAR_TOP/<name>.pcd.bin` and the labels as
//!   `lidarseg/<version>/<sample_data token>_lidarseg.bin`, so the folder is made by linking each
//!   sweep under its sample_data token (`docs/real-recordings.md`). The folder is one sequence (its
//!   name the id); the class ids become SemanticKITTI's
//!   ([`sim::io::nuscenes::lidarseg_to_semantic_kitti`]: ground 24-27 as road, other-ground,
//!   sidewalk, terrain; noise and the ego vehicle left out), so every protocol scores them.

use std::path::{Path, PathBuf};

use sim::SemanticClass;

use super::DatasetError;
use crate::recording::{InputLayout, LayoutBasis, LayoutChoice, RecordingError};

/// The layout of a labelled dataset's frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FrameFormat {
    /// KITTI `.bin` records with SemanticKITTI `.label` files.
    SemanticKitti,
    /// nuScenes `.pcd.bin` sweeps with lidarseg `_lidarseg.bin` files.
    NuscenesLidarseg,
}

/// A frame's points in file order, as [`LabelledFrame::read_points`] reads them.
#[derive(Clone, Debug, PartialEq)]
pub struct FramePoints {
    /// `x y z intensity` per point (sensor frame).
    pub records: Vec<[f32; 4]>,
    /// The ring (laser) per point, where the format has one (nuScenes).
    pub rings: Option<Vec<u16>>,
    /// The class per point (SemanticKITTI ids).
    pub classes: Vec<SemanticClass>,
    /// The cloud file's layout and what decided it (a `velodyne/*.bin` holding nuScenes records is
    /// read as one: [`InputLayout::decide`]).
    pub layout: (InputLayout, LayoutBasis),
}

/// One labelled frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LabelledFrame {
    /// The sequence's id (its folder name).
    pub sequence: String,
    /// The frame's file stem, e.g. `000042`.
    pub stem: String,
    /// The cloud.
    pub bin: PathBuf,
    /// Its labels.
    pub label: PathBuf,
    /// The layout of the two files.
    pub format: FrameFormat,
}

/// One sequence and its frames.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sequence {
    /// The folder name, e.g. `08`.
    pub id: String,
    /// The folder.
    pub dir: PathBuf,
    /// Its frames in file-name order.
    pub frames: Vec<LabelledFrame>,
}

/// The sequences of a dataset directory.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DatasetLayout {
    /// The directory given.
    pub root: PathBuf,
    /// Its sequences in folder-name order.
    pub sequences: Vec<Sequence>,
    /// The layout of its frames.
    pub format: FrameFormat,
}

impl DatasetLayout {
    /// Lists the sequences of `dir` (a dataset root or one sequence's folder), only those named in
    /// `only` where given. Refused: a directory in neither layout, a sequence without `labels/`,
    /// a `.bin` without its `.label`, a sequence without frames, an unknown name in `only`.
    ///
    /// ```
    /// use classifier::dataset::DatasetLayout;
    /// let dir = tempfile::tempdir()?;
    /// let seq = dir.path().join("sequences/07");
    /// std::fs::create_dir_all(seq.join("velodyne"))?;
    /// std::fs::create_dir_all(seq.join("labels"))?;
    /// std::fs::write(seq.join("velodyne/000000.bin"), [0u8; 16])?;
    /// std::fs::write(seq.join("labels/000000.label"), [0u8; 4])?;
    /// let layout = DatasetLayout::open(dir.path(), None)?;
    /// assert_eq!(layout.sequences[0].id, "07");
    /// assert_eq!(layout.frames().count(), 1);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn open(dir: &Path, only: Option<&[String]>) -> Result<Self, DatasetError> {
        if Self::is_lidarseg(dir) {
            return Self::open_lidarseg(dir, only);
        }
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| DatasetError::Io { path, source }
        };
        let mut folders: Vec<(String, PathBuf)> = if dir.join("velodyne").is_dir() {
            let id = dir.file_name().and_then(|n| n.to_str()).unwrap_or("00").to_string();
            vec![(id, dir.to_path_buf())]
        } else if dir.join("sequences").is_dir() {
            let root = dir.join("sequences");
            let mut v = Vec::new();
            for entry in std::fs::read_dir(&root).map_err(io(&root))? {
                let path = entry.map_err(io(&root))?.path();
                if path.join("velodyne").is_dir()
                    && let Some(name) = path.file_name().and_then(|n| n.to_str())
                {
                    v.push((name.to_string(), path.clone()));
                }
            }
            v
        } else {
            Vec::new()
        };
        folders.sort();
        if folders.is_empty() {
            return Err(DatasetError::NotADataset { dir: dir.to_path_buf() });
        }
        if let Some(only) = only {
            for id in only {
                if !folders.iter().any(|(f, _)| f == id) {
                    let known = folders.iter().map(|(f, _)| f.as_str()).collect::<Vec<_>>().join(", ");
                    return Err(DatasetError::UnknownSequence { id: id.clone(), dir: dir.to_path_buf(), known });
                }
            }
            folders.retain(|(f, _)| only.contains(f));
        }
        let mut sequences = Vec::with_capacity(folders.len());
        for (id, seq) in folders {
            let (velodyne, labels) = (seq.join("velodyne"), seq.join("labels"));
            if !labels.is_dir() {
                return Err(DatasetError::NoLabels { dir: seq });
            }
            let mut bins: Vec<PathBuf> = Vec::new();
            for entry in std::fs::read_dir(&velodyne).map_err(io(&velodyne))? {
                let path = entry.map_err(io(&velodyne))?.path();
                if path.extension().is_some_and(|e| e == "bin") {
                    bins.push(path);
                }
            }
            bins.sort();
            if bins.is_empty() {
                return Err(DatasetError::EmptySequence { dir: velodyne });
            }
            let mut frames = Vec::with_capacity(bins.len());
            for bin in bins {
                let stem = bin.file_stem().and_then(|s| s.to_str()).unwrap_or_default().to_string();
                let label = labels.join(format!("{stem}.label"));
                frames.push(LabelledFrame::with_label(&id, stem, bin, label, FrameFormat::SemanticKitti)?);
            }
            sequences.push(Sequence { id, dir: seq, frames });
        }
        Ok(Self { root: dir.to_path_buf(), sequences, format: FrameFormat::SemanticKitti })
    }

    /// Whether `dir` has the folders of a labelled dataset: `sequences/` (a dataset root),
    /// `velodyne/` (one sequence's folder) or `lidar/` with `lidarseg/` (a nuScenes-lidarseg
    /// folder). [`DatasetLayout::open`] says what is wrong with one that holds no frames.
    pub fn is_dataset(dir: &Path) -> bool {
        dir.join("sequences").is_dir() || dir.join("velodyne").is_dir() || Self::is_lidarseg(dir)
    }

    /// Whether `dir` is a nuScenes-lidarseg folder: `lidar/` with `lidarseg/`.
    fn is_lidarseg(dir: &Path) -> bool {
        dir.join("lidar").is_dir() && dir.join("lidarseg").is_dir()
    }

    /// A nuScenes-lidarseg folder (module docs): `lidar/NAME.pcd.bin` with
    /// `lidarseg/NAME_lidarseg.bin`, one sequence named after the folder. Refused: a sweep without
    /// its labels, no sweeps, `only` naming another sequence.
    fn open_lidarseg(dir: &Path, only: Option<&[String]>) -> Result<Self, DatasetError> {
        let id = dir
            .canonicalize()
            .ok()
            .and_then(|d| d.file_name().and_then(|n| n.to_str()).map(str::to_string))
            .unwrap_or_else(|| "nuscenes".to_string());
        if let Some(only) = only
            && let Some(other) = only.iter().find(|s| **s != id)
        {
            return Err(DatasetError::UnknownSequence { id: other.clone(), dir: dir.to_path_buf(), known: id });
        }
        let (lidar, lidarseg) = (dir.join("lidar"), dir.join("lidarseg"));
        let mut bins: Vec<(String, PathBuf)> = Vec::new();
        for entry in std::fs::read_dir(&lidar).map_err(|source| DatasetError::Io { path: lidar.clone(), source })? {
            let path = entry.map_err(|source| DatasetError::Io { path: lidar.clone(), source })?.path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default();
            if let Some(stem) = name.strip_suffix(".pcd.bin") {
                bins.push((stem.to_string(), path.clone()));
            }
        }
        bins.sort();
        if bins.is_empty() {
            return Err(DatasetError::EmptySequence { dir: lidar });
        }
        let mut frames = Vec::with_capacity(bins.len());
        for (stem, bin) in bins {
            let label = lidarseg.join(format!("{stem}_lidarseg.bin"));
            frames.push(LabelledFrame::with_label(&id, stem, bin, label, FrameFormat::NuscenesLidarseg)?);
        }
        let sequences = vec![Sequence { id, dir: dir.to_path_buf(), frames }];
        Ok(Self { root: dir.to_path_buf(), sequences, format: FrameFormat::NuscenesLidarseg })
    }

    /// Every frame, sequence by sequence.
    pub fn frames(&self) -> impl Iterator<Item = &LabelledFrame> {
        self.sequences.iter().flat_map(|s| s.frames.iter())
    }

    /// The same dataset holding only the frames `frames` (by place, clamped to the sequence's) of
    /// its sequence number `sequence` (none where there is no such sequence): a sequence's first
    /// frames, or one frame, to be read as a recording of their own.
    pub fn part(&self, sequence: usize, frames: std::ops::Range<usize>) -> Self {
        let sequences = self
            .sequences
            .get(sequence)
            .map(|s| {
                let end = frames.end.min(s.frames.len());
                let frames = s.frames.get(frames.start.min(end)..end).unwrap_or_default().to_vec();
                Sequence { id: s.id.clone(), dir: s.dir.clone(), frames }
            })
            .into_iter()
            .collect();
        Self { root: self.root.clone(), sequences, format: self.format }
    }
}

impl LabelledFrame {
    /// The frame of `bin` with its labels in `label` (refused when that file is missing).
    fn with_label(
        sequence: &str,
        stem: String,
        bin: PathBuf,
        label: PathBuf,
        format: FrameFormat,
    ) -> Result<Self, DatasetError> {
        if !label.is_file() {
            return Err(DatasetError::MissingLabel { bin, label });
        }
        Ok(Self { sequence: sequence.to_string(), stem, bin, label, format })
    }

    /// Reads the frame's points in file order with their classes (SemanticKITTI ids) and, for a
    /// nuScenes sweep, their rings; checked as [`LabelledFrame::read`] checks a SemanticKITTI frame,
    /// a nuScenes sweep as [`sim::io::nuscenes`] reads it (20-byte records, whole rings, one label
    /// byte per point, class ids of the lidarseg taxonomy).
    ///
    /// A SemanticKITTI frame's `.bin` is read in the layout `choice` names (`--layout`), else in
    /// the one its bytes give away ([`InputLayout::decide`]: nuScenes records renamed `.bin` are
    /// read as nuScenes, with their rings), else as KITTI records.
    pub fn read_points(&self, choice: Option<LayoutChoice>) -> Result<FramePoints, DatasetError> {
        if self.format == FrameFormat::NuscenesLidarseg {
            let p = sim::io::nuscenes::read_points(&self.bin)?;
            let classes = sim::io::nuscenes::read_lidarseg(&self.label, &self.bin, p.points.len())?;
            let records = p.points.iter().zip(&p.intensity).map(|(q, &i)| [q.x, q.y, q.z, i]).collect();
            let layout = (InputLayout::NuscenesBin, LayoutBasis::Name);
            return Ok(FramePoints { records, rings: Some(p.rings), classes, layout });
        }
        let bin = std::fs::read(&self.bin).map_err(|source| DatasetError::Io { path: self.bin.clone(), source })?;
        let layout = InputLayout::decide(&self.bin, &bin, choice).map_err(|e| match e {
            RecordingError::File(e) => DatasetError::File(e),
            e => DatasetError::Invalid {
                flag: "--layout",
                value: self.bin.display().to_string(),
                allowed: e.to_string(),
            },
        })?;
        let (records, rings, raw_labels) = if layout.0 == InputLayout::NuscenesBin {
            let mut p = sim::io::nuscenes::NuscenesPoints::default();
            sim::io::nuscenes::points_from_bytes_into(&self.bin, &bin, &mut p)?;
            let records = p.points.iter().zip(&p.intensity).map(|(q, &i)| [q.x, q.y, q.z, i]).collect();
            (records, Some(p.rings), self.read_labels(p.points.len())?)
        } else {
            let (records, labels) = self.kitti_from_bytes(&bin)?;
            (records, None, labels)
        };
        let classes = raw_labels.iter().map(|&l| SemanticClass((l & 0xFFFF) as u16)).collect();
        Ok(FramePoints { records, rings, classes, layout })
    }

    /// The `.label`'s raw uint32 labels, checked against the cloud's `points`.
    fn read_labels(&self, points: usize) -> Result<Vec<u32>, DatasetError> {
        let label =
            std::fs::read(&self.label).map_err(|source| DatasetError::Io { path: self.label.clone(), source })?;
        if label.len() % 4 != 0 || label.len() / 4 != points {
            return Err(DatasetError::LabelCount {
                label: self.label.clone(),
                labels: label.len() / 4,
                bin: self.bin.clone(),
                points,
            });
        }
        Ok(label.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect())
    }

    /// Reads the frame: its records (float32 `x y z intensity`) and its raw uint32 labels, checked
    /// against each other (a truncated `.bin`, a `.label` of another length are refused).
    /// A nuScenes sweep gives its `x y z intensity` and its classes as SemanticKITTI ids.
    pub fn read(&self) -> Result<(Vec<[f32; 4]>, Vec<u32>), DatasetError> {
        if self.format == FrameFormat::NuscenesLidarseg {
            let p = self.read_points(None)?;
            return Ok((p.records, p.classes.iter().map(|c| u32::from(c.0)).collect()));
        }
        let bin = std::fs::read(&self.bin).map_err(|source| DatasetError::Io { path: self.bin.clone(), source })?;
        self.kitti_from_bytes(&bin)
    }

    /// The KITTI records of the `.bin`'s bytes `bin` and the `.label`'s raw labels, checked
    /// against each other.
    fn kitti_from_bytes(&self, bin: &[u8]) -> Result<(Vec<[f32; 4]>, Vec<u32>), DatasetError> {
        if !bin.len().is_multiple_of(16) {
            return Err(DatasetError::Truncated { path: self.bin.clone(), bytes: bin.len() as u64 });
        }
        let labels = self.read_labels(bin.len() / 16)?;
        let records = bin
            .chunks_exact(16)
            .map(|c| {
                let f = |k: usize| f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]]);
                [f(0), f(1), f(2), f(3)]
            })
            .collect();
        Ok((records, labels))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(dir: &Path, seq: &str, stem: &str, points: usize, labels: Option<usize>) {
        let s = dir.join("sequences").join(seq);
        std::fs::create_dir_all(s.join("velodyne")).unwrap();
        std::fs::create_dir_all(s.join("labels")).unwrap();
        std::fs::write(s.join(format!("velodyne/{stem}.bin")), vec![0u8; 16 * points]).unwrap();
        if let Some(n) = labels {
            std::fs::write(s.join(format!("labels/{stem}.label")), vec![0u8; 4 * n]).unwrap();
        }
    }

    #[test]
    fn sequences_and_frames_are_listed_in_order_and_filtered() {
        let dir = tempfile::tempdir().unwrap();
        frame(dir.path(), "08", "000001", 3, Some(3));
        frame(dir.path(), "08", "000000", 2, Some(2));
        frame(dir.path(), "00", "000000", 1, Some(1));
        let l = DatasetLayout::open(dir.path(), None).unwrap();
        let ids: Vec<_> = l.frames().map(|f| format!("{}/{}", f.sequence, f.stem)).collect();
        assert_eq!(ids, ["00/000000", "08/000000", "08/000001"]);
        let only = DatasetLayout::open(dir.path(), Some(&["08".to_string()])).unwrap();
        assert_eq!(only.frames().count(), 2);
        let (rec, lab) = only.sequences[0].frames[1].read().unwrap();
        assert_eq!((rec.len(), lab.len()), (3, 3));
        // One sequence's folder works alone.
        let one = DatasetLayout::open(&dir.path().join("sequences/08"), None).unwrap();
        assert_eq!(one.sequences[0].id, "08");
        let e = DatasetLayout::open(dir.path(), Some(&["05".to_string()])).unwrap_err().to_string();
        assert!(e.contains("--sequences") && e.contains("05") && e.contains("00, 08"), "{e}");
    }

    #[test]
    fn bad_datasets_are_refused_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let e = DatasetLayout::open(dir.path(), None).unwrap_err().to_string();
        assert!(e.contains("not a SemanticKITTI-layout dataset"), "{e}");
        // A .bin without its .label.
        frame(dir.path(), "00", "000000", 2, None);
        let e = DatasetLayout::open(dir.path(), None).unwrap_err().to_string();
        assert!(e.contains("000000.label"), "{e}");
        // A label count that differs from the cloud's.
        frame(dir.path(), "00", "000000", 2, Some(3));
        let l = DatasetLayout::open(dir.path(), None).unwrap();
        let e = l.sequences[0].frames[0].read().unwrap_err().to_string();
        assert!(e.contains("3 labels") && e.contains("2 points"), "{e}");
        // A truncated cloud.
        std::fs::write(dir.path().join("sequences/00/velodyne/000000.bin"), [0u8; 20]).unwrap();
        let e = l.sequences[0].frames[0].read().unwrap_err().to_string();
        assert!(e.contains("20 bytes"), "{e}");
        // No labels folder; an empty sequence.
        std::fs::remove_dir_all(dir.path().join("sequences/00/labels")).unwrap();
        let e = DatasetLayout::open(dir.path(), None).unwrap_err().to_string();
        assert!(e.contains("no `labels/`"), "{e}");
        std::fs::create_dir_all(dir.path().join("sequences/00/labels")).unwrap();
        std::fs::remove_file(dir.path().join("sequences/00/velodyne/000000.bin")).unwrap();
        let e = DatasetLayout::open(dir.path(), None).unwrap_err().to_string();
        assert!(e.contains("no `.bin` frames"), "{e}");
    }
}
