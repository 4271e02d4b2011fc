//! Which sequences and frames a SemanticKITTI-layout directory holds, and reading one frame.
//!
//! A dataset root holds `sequences/NN/velodyne/NNNNNN.bin` with `sequences/NN/labels/NNNNNN.label`
//! beside them (SemanticKITTI's, KITTI-360 and others converted to it, and `groundtruth dataset`'s
//! output); a single sequence's folder holding `velodyne/` and `labels/` is taken too. Frames are
//! sorted by file name. `.bin`: float32 `x y z intensity` records (sensor frame); `.label`: one
//! uint32 per point, the class id in the lower 16 bits (the instance in the upper).

use std::path::{Path, PathBuf};

use super::DatasetError;

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
                if !label.is_file() {
                    return Err(DatasetError::MissingLabel { bin, label });
                }
                frames.push(LabelledFrame { sequence: id.clone(), stem, bin, label });
            }
            sequences.push(Sequence { id, dir: seq, frames });
        }
        Ok(Self { root: dir.to_path_buf(), sequences })
    }

    /// Every frame, sequence by sequence.
    pub fn frames(&self) -> impl Iterator<Item = &LabelledFrame> {
        self.sequences.iter().flat_map(|s| s.frames.iter())
    }
}

impl LabelledFrame {
    /// Reads the frame: its records (float32 `x y z intensity`) and its raw uint32 labels, checked
    /// against each other (a truncated `.bin`, a `.label` of another length are refused).
    pub fn read(&self) -> Result<(Vec<[f32; 4]>, Vec<u32>), DatasetError> {
        let bin = std::fs::read(&self.bin).map_err(|source| DatasetError::Io { path: self.bin.clone(), source })?;
        if bin.len() % 16 != 0 {
            return Err(DatasetError::Truncated { path: self.bin.clone(), bytes: bin.len() as u64 });
        }
        let label =
            std::fs::read(&self.label).map_err(|source| DatasetError::Io { path: self.label.clone(), source })?;
        let points = bin.len() / 16;
        if label.len() % 4 != 0 || label.len() / 4 != points {
            return Err(DatasetError::LabelCount {
                label: self.label.clone(),
                labels: label.len() / 4,
                bin: self.bin.clone(),
                points,
            });
        }
        let records = bin
            .chunks_exact(16)
            .map(|c| {
                let f = |k: usize| f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]]);
                [f(0), f(1), f(2), f(3)]
            })
            .collect();
        let labels = label.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
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
