//! The dataset file (`DATASET.toml`): sequences of scans to write in the SemanticKITTI layout, read
//! and checked before any frame is written.
//!
//! ```toml
//! name = "my-dataset"                  # optional, for the manifest
//! split = { train = [0, 1], valid = [2], test = [] }   # optional; default: every sequence in train
//!
//! [[sequences]]
//! id = 0                               # 0 ..= 99, unique: the folder sequences/00
//! scene = "city"                       # a scene name (`groundtruth list`) or a .toml scene file
//! seed = 1                             # scene generator and measurement noise
//! rig = "hdl64e-roof"                  # a rig preset or a .toml rig file
//! mount = { z_m = 1.9, pitch_deg = 1 } # optional: overrides of a single-sensor rig's mount
//! frames = 100                         # 1 ..= 100,000 (the simulator's limit per sequence)
//! speed_m_per_s = 10.0                 # constant speed, 0 ..= 100 m/s
//! yaw_rate_deg_per_s = 0.0             # constant yaw rate (|w| <= 114 deg/s), or:
//! waypoints_m = [[0, 0], [60, 0], [80, 20]]   # a polyline the ego follows at speed_m_per_s (> 0)
//! formats = ["pcd"]                    # optional extra files per frame: pcd, ply, las; `mcap`:
//!                                      # the sequence as a ROS 2 bag, sequences/NN/bag/
//! ideal = false                        # optional: no measurement effects
//! ```
//!
//! The frame rate is the rig's (its slowest sensor). Unknown fields, an unknown scene or rig, a
//! trajectory that leaves the scene's extent, zero or negative speed with waypoints, a frame count
//! of 0 or more than the limit, duplicate ids and ids over 99 are refused with the field named.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use anyhow::{Context, bail};
use serde::{Deserialize, Serialize};

/// Largest number of frames in a whole dataset without `--allow-large`.
pub const MAX_FRAMES_TOTAL: u64 = 10_000_000;

/// Largest sequence id (two digits, as SemanticKITTI's folders).
pub const MAX_SEQUENCE_ID: u32 = 99;

/// The dataset file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasetConfig {
    /// A name for the manifest (default `groundtruth-dataset`).
    #[serde(default = "default_name")]
    pub name: String,
    /// Which sequences are for training, validation and test (the label config's `split`).
    #[serde(default)]
    pub split: Option<Split>,
    /// The sequences.
    #[serde(default)]
    pub sequences: Vec<SequenceConfig>,
    /// Sequences drawn at random ([`super::generate`]), added after `sequences`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generate: Option<super::generate::Generate>,
    /// Training parameters of `groundtruth train --config` (ignored by `groundtruth dataset`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub train: Option<super::generate::TrainSection>,
    /// Weather of every sequence that sets none of its own (`[weather]`: `kind = "fog"`,
    /// `visibility_m = 50`; see `sim::effects::weather`); else the scene file's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weather: Option<sim::effects::weather::Weather>,
}

fn default_name() -> String {
    "groundtruth-dataset".to_string()
}

/// The label config's `split`: sequence ids per role.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Split {
    /// Training sequences.
    #[serde(default)]
    pub train: Vec<u32>,
    /// Validation sequences.
    #[serde(default)]
    pub valid: Vec<u32>,
    /// Test sequences.
    #[serde(default)]
    pub test: Vec<u32>,
}

/// Overrides of a mount's fields (metres, degrees; see `sim::Mount`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct MountOverride {
    /// Position x, metres.
    pub x_m: Option<f32>,
    /// Position y, metres.
    pub y_m: Option<f32>,
    /// Position z, metres.
    pub z_m: Option<f32>,
    /// Roll, degrees.
    pub roll_deg: Option<f32>,
    /// Pitch, degrees.
    pub pitch_deg: Option<f32>,
    /// Yaw, degrees.
    pub yaw_deg: Option<f32>,
}

/// One sequence: a scene, a rig and a trajectory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SequenceConfig {
    /// Sequence id, `0 ..= 99` (folder `sequences/NN`).
    pub id: u32,
    /// Scene name or TOML file.
    pub scene: String,
    /// Seed of the scene generator and the measurement noise.
    #[serde(default)]
    pub seed: u64,
    /// Rig preset name or TOML file.
    pub rig: String,
    /// Mount overrides (single-sensor rigs).
    #[serde(default)]
    pub mount: Option<MountOverride>,
    /// Number of frames.
    pub frames: u64,
    /// Ego speed, metres per second.
    #[serde(default)]
    pub speed_m_per_s: f64,
    /// Ego yaw rate, degrees per second (positive: left).
    #[serde(default)]
    pub yaw_rate_deg_per_s: f64,
    /// Waypoints `[x, y]` (world frame, metres) followed at `speed_m_per_s`.
    #[serde(default)]
    pub waypoints_m: Option<Vec<[f64; 2]>>,
    /// Extra files per frame beside `velodyne/`: any of `pcd`, `ply`, `las`.
    #[serde(default)]
    pub formats: Vec<String>,
    /// No measurement effects.
    #[serde(default)]
    pub ideal: bool,
    /// Range noise as a multiple of the sensor's own (`range_sigma_m`), 0 ..= 10.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_scale: Option<f64>,
    /// Probability that a return is dropped at random, 0 ..= 0.9.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dropout: Option<f64>,
    /// Intensities multiplied by this (clamped to 1), 0 ..= 10.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intensity_scale: Option<f64>,
    /// Weather of this sequence (`weather = { kind = "snow", rate_mm_h = 2 }`); default the
    /// dataset's `[weather]`, else the scene file's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weather: Option<sim::effects::weather::Weather>,
}

impl DatasetConfig {
    /// Reads and checks the dataset file (fields only; scenes, rigs and trajectories are checked
    /// by [`super::run`] once loaded); a `[generate]` table's sequences are drawn and added.
    pub fn load(path: &Path, allow_large: bool) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let mut config: DatasetConfig = toml::from_str(&text).with_context(|| format!("{}", path.display()))?;
        config.expand().with_context(|| format!("{}", path.display()))?;
        config.check(allow_large).with_context(|| format!("{}", path.display()))?;
        Ok(config)
    }

    /// Draws the `[generate]` table's sequences and appends them (ids after the largest given).
    pub fn expand(&mut self) -> anyhow::Result<()> {
        if let Some(g) = &self.generate {
            let first = self.sequences.iter().map(|s| s.id + 1).max().unwrap_or(0);
            let drawn = g.draw(first)?;
            self.sequences.extend(drawn);
        }
        if let Some(w) = self.weather {
            for s in self.sequences.iter_mut().filter(|s| s.weather.is_none()) {
                s.weather = Some(w);
            }
        }
        Ok(())
    }

    /// Checks ids, frame counts, speeds, waypoints and formats.
    pub fn check(&self, allow_large: bool) -> anyhow::Result<()> {
        if self.sequences.is_empty() {
            bail!("`sequences`: at least one sequence is needed");
        }
        let mut ids = BTreeSet::new();
        let mut total = 0u64;
        for (k, s) in self.sequences.iter().enumerate() {
            let at = format!("sequences[{k}]");
            if let Some(w) = &s.weather {
                w.validate().map_err(|e| anyhow::anyhow!("`{at}.weather`: {e}"))?;
            }
            if s.id > MAX_SEQUENCE_ID {
                bail!("`{at}.id` = {}: allowed 0 ..= {MAX_SEQUENCE_ID} (two-digit SemanticKITTI folders)", s.id);
            }
            if !ids.insert(s.id) {
                bail!("`{at}.id` = {}: a duplicate sequence id", s.id);
            }
            if s.frames == 0 || s.frames > sim::scan::MAX_FRAMES as u64 {
                bail!(
                    "`{at}.frames` = {}: allowed 1 ..= {} per sequence (the simulator's limit)",
                    s.frames,
                    sim::scan::MAX_FRAMES
                );
            }
            total += s.frames;
            if !(s.speed_m_per_s.is_finite() && (-100.0..=100.0).contains(&s.speed_m_per_s)) {
                bail!("`{at}.speed_m_per_s` = {}: allowed -100 ..= 100", s.speed_m_per_s);
            }
            if !(s.yaw_rate_deg_per_s.is_finite() && s.yaw_rate_deg_per_s.abs() <= 2f64.to_degrees()) {
                bail!("`{at}.yaw_rate_deg_per_s` = {}: allowed -114.59 ..= 114.59", s.yaw_rate_deg_per_s);
            }
            if let Some(w) = &s.waypoints_m {
                if w.len() < 2 {
                    bail!("`{at}.waypoints_m`: {} point(s); a path needs 2 or more", w.len());
                }
                if let Some(p) = w.iter().find(|p| !p.iter().all(|v| v.is_finite() && v.abs() <= 1e6)) {
                    bail!("`{at}.waypoints_m`: point {p:?} is not finite or beyond 1e6 m");
                }
                if s.speed_m_per_s <= 0.0 {
                    bail!("`{at}.speed_m_per_s` = {}: must be > 0 with waypoints", s.speed_m_per_s);
                }
                if s.yaw_rate_deg_per_s != 0.0 {
                    bail!("`{at}`: give waypoints_m or yaw_rate_deg_per_s, not both");
                }
            }
            for (name, value, max) in [
                ("noise_scale", s.noise_scale, 10.0),
                ("dropout", s.dropout, 0.9),
                ("intensity_scale", s.intensity_scale, 10.0),
            ] {
                if let Some(v) = value
                    && !(v.is_finite() && (0.0..=max).contains(&v))
                {
                    bail!("`{at}.{name}` = {v}: allowed 0 ..= {max}");
                }
            }
            for f in &s.formats {
                if !["pcd", "ply", "las", "mcap"].contains(&f.as_str()) {
                    bail!("`{at}.formats`: unknown format `{f}`; allowed: pcd, ply, las, mcap");
                }
            }
        }
        if total > MAX_FRAMES_TOTAL && !allow_large {
            bail!("{total} frames in all: more than {MAX_FRAMES_TOTAL}; pass --allow-large if that is meant");
        }
        if let Some(split) = &self.split {
            for (role, list) in [("train", &split.train), ("valid", &split.valid), ("test", &split.test)] {
                if let Some(id) = list.iter().find(|id| !ids.contains(id)) {
                    bail!("`split.{role}`: sequence {id} is not among the sequences");
                }
            }
        }
        Ok(())
    }

    /// The split: as given, or every sequence in `train`.
    pub fn split_or_default(&self) -> Split {
        self.split
            .clone()
            .unwrap_or_else(|| Split { train: self.sequences.iter().map(|s| s.id).collect(), ..Split::default() })
    }

    /// The canonical JSON of the configuration (what the manifest's id is the hash of).
    pub fn canonical(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }
}

/// Applies mount overrides to a single-sensor rig; refused for rigs of several sensors.
pub fn apply_mount(rig: &mut sim::Rig, mount: &MountOverride, at: &str) -> anyhow::Result<()> {
    if rig.sensors.len() != 1 {
        bail!("`{at}.mount`: the rig has {} sensors; mount overrides apply to single-sensor rigs", rig.sensors.len());
    }
    let m = &mut rig.sensors[0].mount;
    let fields: BTreeMap<&str, (Option<f32>, &mut f32)> = BTreeMap::from([
        ("x_m", (mount.x_m, &mut m.x_m)),
        ("y_m", (mount.y_m, &mut m.y_m)),
        ("z_m", (mount.z_m, &mut m.z_m)),
        ("roll_deg", (mount.roll_deg, &mut m.roll_deg)),
        ("pitch_deg", (mount.pitch_deg, &mut m.pitch_deg)),
        ("yaw_deg", (mount.yaw_deg, &mut m.yaw_deg)),
    ]);
    for (name, (value, slot)) in fields {
        if let Some(v) = value {
            let limit = if name.ends_with("_m") { 100.0 } else { 180.0 };
            if !(v.is_finite() && v.abs() <= limit) {
                bail!("`{at}.mount.{name}` = {v}: allowed -{limit} ..= {limit}");
            }
            *slot = v;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> anyhow::Result<DatasetConfig> {
        let c: DatasetConfig = toml::from_str(text)?;
        c.check(false)?;
        Ok(c)
    }

    const ONE: &str = "[[sequences]]\nid = 3\nscene = \"flat\"\nrig = \"vlp16-roof\"\nframes = 2\n";

    #[test]
    fn a_minimal_file_and_its_defaults() {
        let c = parse(ONE).unwrap();
        assert_eq!(c.name, "groundtruth-dataset");
        assert_eq!(c.sequences[0].id, 3);
        assert_eq!(c.split_or_default().train, vec![3]);
    }

    #[test]
    fn bad_files_are_refused_with_the_field_named() {
        let cases = [
            (format!("{ONE}colour = 1\n"), "unknown field"),
            (ONE.replace("id = 3", "id = 100"), "id"),
            (ONE.replace("frames = 2", "frames = 0"), "frames"),
            (format!("{ONE}{ONE}"), "duplicate"),
            (format!("{ONE}waypoints_m = [[0, 0], [10, 0]]\n"), "speed_m_per_s"),
            (format!("{ONE}speed_m_per_s = 5\nwaypoints_m = [[0, 0]]\n"), "waypoints_m"),
            (format!("{ONE}speed_m_per_s = nan\n"), "speed_m_per_s"),
            (format!("{ONE}formats = [\"xyz\"]\n"), "formats"),
            (format!("split = {{ train = [4] }}\n{ONE}"), "split.train"),
        ];
        for (text, needle) in cases {
            let e = format!("{:#}", parse(&text).unwrap_err());
            assert!(e.contains(needle), "`{text}` gave `{e}`, expected `{needle}`");
        }
    }

    #[test]
    fn mount_overrides_apply_to_one_sensor_rigs_only() {
        let mut rig = sim::Rig::load("vlp16-roof").unwrap();
        apply_mount(&mut rig, &MountOverride { z_m: Some(2.5), ..Default::default() }, "s").unwrap();
        assert_eq!(rig.sensors[0].mount.z_m, 2.5);
        let e = apply_mount(&mut rig, &MountOverride { z_m: Some(f32::NAN), ..Default::default() }, "s").unwrap_err();
        assert!(e.to_string().contains("mount.z_m"));
        let mut four = sim::Rig::load("lux-roof-4").unwrap();
        assert!(apply_mount(&mut four, &MountOverride::default(), "s").is_err());
    }
}
