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
//! mount = { z_m = 1.9, pitch_deg = 1 } # optional: the mount override (ScanSpec's: a `sensor` and
//!                                      # `mode` absolute/relative; limits +-100 m, +-360 deg)
//! frames = 100                         # 1 ..= 100,000 (the simulator's limit per sequence)
//! speed_m_per_s = 10.0                 # constant speed, 0 ..= 100 m/s
//! yaw_rate_deg_per_s = 0.0             # constant yaw rate (|w| <= 114 deg/s), or:
//! waypoints_m = [[0, 0], [60, 0], [80, 20]]   # a polyline the ego follows at speed_m_per_s (> 0)
//! formats = ["pcd"]                    # optional extra files per frame: pcd, ply, las; `mcap`:
//!                                      # the sequence as a ROS 2 bag, sequences/NN/bag/
//! ideal = false                        # optional: no measurement effects
//! ```
//!
//! A sequence's fields besides `id` and `formats` are a `groundtruth_scenario::ScanSpec` (also
//! `params`, `family`, `noise_scale`, `dropout`, `intensity_scale`, `weather`), checked as every
//! front end checks it. The frame rate is the rig's (its slowest sensor). Unknown fields, an unknown scene or rig, a
//! trajectory that leaves the scene's extent, zero or negative speed with waypoints, a frame count
//! of 0 or more than the limit, duplicate ids and ids over 99 are refused with the field named.

use std::collections::BTreeSet;
use std::path::Path;

use anyhow::{Context, bail};
use groundtruth_scenario::ScanSpec;
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

/// One sequence: its id, the scan (a [`ScanSpec`], its fields beside `id` in the sequence's
/// table) and the extra files per frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SequenceConfig {
    /// Sequence id, `0 ..= 99` (folder `sequences/NN`).
    pub id: u32,
    /// The scan: scene, seed, rig, mount, frames, motion, effects, weather.
    #[serde(flatten)]
    pub spec: ScanSpec,
    /// Extra files per frame beside `velodyne/`: any of `pcd`, `ply`, `las`; `mcap`: a bag.
    #[serde(default)]
    pub formats: Vec<String>,
}

impl std::ops::Deref for SequenceConfig {
    type Target = ScanSpec;

    fn deref(&self) -> &ScanSpec {
        &self.spec
    }
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
            for s in self.sequences.iter_mut().filter(|s| s.spec.weather.is_none()) {
                s.spec.weather = Some(w);
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
            s.spec.validate().map_err(|e| anyhow::anyhow!("`{at}`: {e}"))?;
            if s.spec.backend.is_some() {
                bail!("`{at}.backend`: a dataset's backend is the command line's --backend");
            }
            if s.id > MAX_SEQUENCE_ID {
                bail!("`{at}.id` = {}: allowed 0 ..= {MAX_SEQUENCE_ID} (two-digit SemanticKITTI folders)", s.id);
            }
            if !ids.insert(s.id) {
                bail!("`{at}.id` = {}: a duplicate sequence id", s.id);
            }
            total += s.frames;
            for f in &s.formats {
                if !["pcd", "ply", "las", "mcap"].contains(&f.as_str()) {
                    bail!("`{at}.formats`: unknown format `{f}`; allowed: pcd, ply, las, mcap");
                }
                if f == "mcap" {
                    // The bags are zstd-compressed: refused here, before anything is written, in
                    // a build without the compression.
                    sim::io::ros2::BagCompression::default()
                        .check_built()
                        .with_context(|| format!("`{at}.formats`"))?;
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

    /// The canonical JSON of the configuration (what the manifest's id is the hash of): the shape
    /// it had before sequences were scan specs, so that a dataset keeps its id (and `--resume`
    /// keeps working) across that change; fields that only a scan spec has follow when set.
    pub fn canonical(&self) -> String {
        let sequences = self.sequences.iter().map(CanonicalSequence::of).collect();
        let c = CanonicalConfig {
            name: &self.name,
            split: &self.split,
            sequences,
            generate: &self.generate,
            train: &self.train,
            weather: &self.weather,
        };
        serde_json::to_string(&c).unwrap_or_default()
    }
}

/// [`DatasetConfig`] as [`DatasetConfig::canonical`] writes it.
#[derive(Serialize)]
struct CanonicalConfig<'a> {
    name: &'a str,
    split: &'a Option<Split>,
    sequences: Vec<CanonicalSequence<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    generate: &'a Option<super::generate::Generate>,
    #[serde(skip_serializing_if = "Option::is_none")]
    train: &'a Option<super::generate::TrainSection>,
    #[serde(skip_serializing_if = "Option::is_none")]
    weather: &'a Option<sim::effects::weather::Weather>,
}

/// A mount override's values, every field written (`null` when unset).
#[derive(Serialize)]
struct CanonicalMount {
    x_m: Option<f32>,
    y_m: Option<f32>,
    z_m: Option<f32>,
    roll_deg: Option<f32>,
    pitch_deg: Option<f32>,
    yaw_deg: Option<f32>,
}

/// A sequence in its canonical shape (see [`DatasetConfig::canonical`]).
#[derive(Serialize)]
struct CanonicalSequence<'a> {
    id: u32,
    scene: &'a str,
    seed: u64,
    rig: &'a str,
    mount: Option<CanonicalMount>,
    frames: u64,
    speed_m_per_s: f64,
    yaw_rate_deg_per_s: f64,
    waypoints_m: &'a Option<Vec<[f64; 2]>>,
    formats: &'a [String],
    ideal: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    noise_scale: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    dropout: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    intensity_scale: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    weather: Option<sim::effects::weather::Weather>,
    #[serde(skip_serializing_if = "Option::is_none")]
    family: &'a Option<String>,
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    params: &'a std::collections::BTreeMap<String, groundtruth_scenario::ParamValue>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mount_sensor: Option<&'a groundtruth_scenario::MountTarget>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mount_mode: Option<groundtruth_scenario::MountMode>,
}

impl<'a> CanonicalSequence<'a> {
    fn of(s: &'a SequenceConfig) -> Self {
        let spec = &s.spec;
        let mount = spec.mount.as_ref();
        CanonicalSequence {
            id: s.id,
            scene: &spec.scene,
            seed: spec.seed,
            rig: &spec.rig,
            mount: mount.map(|m| CanonicalMount {
                x_m: m.x_m,
                y_m: m.y_m,
                z_m: m.z_m,
                roll_deg: m.roll_deg,
                pitch_deg: m.pitch_deg,
                yaw_deg: m.yaw_deg,
            }),
            frames: spec.frames,
            speed_m_per_s: spec.speed_m_per_s,
            yaw_rate_deg_per_s: spec.yaw_rate_deg_per_s,
            waypoints_m: &spec.waypoints_m,
            formats: &s.formats,
            ideal: spec.ideal,
            noise_scale: spec.noise_scale,
            dropout: spec.dropout,
            intensity_scale: spec.intensity_scale,
            weather: spec.weather,
            family: &spec.family,
            params: &spec.params,
            mount_sensor: mount.and_then(|m| m.sensor.as_ref()),
            mount_mode: mount.map(|m| m.mode).filter(|m| *m != groundtruth_scenario::MountMode::Absolute),
        }
    }
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
    fn the_canonical_form_is_the_one_before_scan_specs() {
        // The id of a dataset written before sequences were scan specs (the same text then).
        let c = parse(&format!("{ONE}mount = {{ z_m = 2.0, pitch_deg = 2.0 }}\nspeed_m_per_s = 8.0\ndropout = 0.05\n"))
            .unwrap();
        assert_eq!(
            c.canonical(),
            "{\"name\":\"groundtruth-dataset\",\"split\":null,\"sequences\":[{\"id\":3,\"scene\":\"flat\",\"seed\":0,\
             \"rig\":\"vlp16-roof\",\"mount\":{\"x_m\":null,\"y_m\":null,\"z_m\":2.0,\"roll_deg\":null,\
             \"pitch_deg\":2.0,\"yaw_deg\":null},\"frames\":2,\"speed_m_per_s\":8.0,\"yaw_rate_deg_per_s\":0.0,\
             \"waypoints_m\":null,\"formats\":[],\"ideal\":false,\"dropout\":0.05}]}"
        );
    }

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
    fn the_spec_refusals_are_the_scan_specs() {
        // The same message as `scan --spec`, the scenario builder and Python give.
        for (extra, needle) in [
            ("yaw_rate = 0.3\n", "invalid value for `yaw_rate`"),
            ("mount = { z_m = 150.0 }\n", "invalid value for `mount.z_m`: 150 (allowed: -100 ..= 100)"),
            ("colour = 1\n", "unknown field `colour`"),
        ] {
            let e = format!("{:#}", parse(&format!("{ONE}{extra}")).unwrap_err());
            assert!(e.contains(needle), "{extra}: {e}");
        }
        let c = parse(&format!("{ONE}mount = {{ z_m = 2.5 }}\n")).unwrap();
        let rig = c.sequences[0].spec.rig().unwrap();
        assert_eq!(rig.sensors[0].mount.z_m, 2.5);
        let four = ONE.replace("vlp16-roof", "lux-roof-4");
        let c = parse(&format!("{four}mount = {{ z_m = 2.5 }}\n")).unwrap();
        assert!(c.sequences[0].spec.rig().unwrap_err().to_string().contains("mount.sensor"));
    }
}
