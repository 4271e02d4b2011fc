//! The `[generate]` table of a dataset file: sequences drawn at random, seeded, so that one short
//! file describes a training set that varies what real sensors and vehicles vary (the rig, the
//! mount's height, pitch and roll, the range noise, random dropout, the intensity scale, the
//! speed), over every scene family and many scene seeds; and the `[train]` table that
//! `groundtruth train --config` reads.
//!
//! ```toml
//! [generate]
//! seed = 1                                   # the draws
//! sequences = 96                             # 1 ..= 99 (with the listed ones: ids up to 99)
//! frames = 4                                 # per sequence
//! scenes = ["city", "rural", "highway"]      # scene k of sequence k: cycled
//! rigs = ["hdl64e-roof", "vlp16-roof"]       # cycled over the scenes' cycles (every pairing)
//! pairing = "cycled"                         # or "interleaved": rig k and scene k both cycled
//! scene_seed = [0, 10000]                    # uniform integer, inclusive
//! mount_z_m = [1.4, 2.4]                     # uniform; absent: the rig's own
//! pitch_deg = [-3.0, 3.0]                    # (+ = down), absent: the rig's own
//! roll_deg = [-2.0, 2.0]
//! speed_m_per_s = [0.0, 15.0]
//! noise_scale = [0.5, 2.0]                   # x the sensor's range sigma
//! dropout = [0.0, 0.1]                       # probability a return is lost
//! intensity_scale = [0.6, 1.4]
//! ```
//!
//! Drawn values are rounded (centimetres, hundredths of a degree, thousandths) so that the
//! manifest reads well; the same file and seed give the same sequences.

use anyhow::bail;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

use groundtruth_scenario::{MountOverride, ScanSpec};

use super::config::SequenceConfig;

/// How the drawn sequences pair scenes and rigs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Pairing {
    /// Scene `k mod scenes`, rig `(k / scenes) mod rigs`: every scene with one rig, then the
    /// next rig (all pairings once the sequences reach scenes x rigs).
    #[default]
    Cycled,
    /// Scene `k mod scenes`, rig `k mod rigs`: every rig and every scene from the first sequences
    /// on, each rig with scenes spread over the list (all pairings once the sequences reach their
    /// least common multiple). For more rigs x scenes than sequences.
    Interleaved,
}

/// The `[generate]` table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Generate {
    /// Seed of the draws.
    #[serde(default)]
    pub seed: u64,
    /// Sequences to draw.
    pub sequences: u32,
    /// Frames per sequence.
    pub frames: u64,
    /// Scenes, cycled.
    pub scenes: Vec<String>,
    /// Rigs (single-sensor rigs where mounts are drawn), cycled over the scenes' cycles.
    pub rigs: Vec<String>,
    /// How sequence `k` pairs a scene and a rig ([`Pairing`]).
    #[serde(default)]
    pub pairing: Pairing,
    /// Range of the scene seeds (inclusive).
    #[serde(default)]
    pub scene_seed: Option<[u64; 2]>,
    /// Range of the mount height, metres.
    #[serde(default)]
    pub mount_z_m: Option<[f64; 2]>,
    /// Range of the mount pitch, degrees.
    #[serde(default)]
    pub pitch_deg: Option<[f64; 2]>,
    /// Range of the mount roll, degrees.
    #[serde(default)]
    pub roll_deg: Option<[f64; 2]>,
    /// Range of the speed, metres per second.
    #[serde(default)]
    pub speed_m_per_s: Option<[f64; 2]>,
    /// Range of the noise scale.
    #[serde(default)]
    pub noise_scale: Option<[f64; 2]>,
    /// Range of the dropout probability.
    #[serde(default)]
    pub dropout: Option<[f64; 2]>,
    /// Range of the intensity scale.
    #[serde(default)]
    pub intensity_scale: Option<[f64; 2]>,
}

/// The `[train]` table: parameters of `groundtruth train --config` (each optional; see
/// `classifier::learned::train::TrainParams` for the defaults and ranges).
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainSection {
    /// The method (`learned`).
    #[serde(default)]
    pub method: Option<String>,
    /// Boosting rounds.
    #[serde(default)]
    pub trees: Option<usize>,
    /// Tree depth.
    #[serde(default)]
    pub depth: Option<usize>,
    /// Learning rate.
    #[serde(default)]
    pub eta: Option<f64>,
    /// Returns drawn per training frame.
    #[serde(default)]
    pub samples_per_frame: Option<usize>,
    /// Every this many frames one is held out.
    #[serde(default)]
    pub validation_every: Option<usize>,
    /// Seed of the sampling and the library.
    #[serde(default)]
    pub seed: Option<u64>,
}

fn rounded(x: f64, step: f64) -> f64 {
    (x / step).round() * step
}

impl Generate {
    /// The drawn sequences, with ids from `first_id` on.
    pub fn draw(&self, first_id: u32) -> anyhow::Result<Vec<SequenceConfig>> {
        if self.sequences == 0 || first_id + self.sequences > super::config::MAX_SEQUENCE_ID + 1 {
            bail!(
                "`generate.sequences` = {}: allowed 1 ..= {} (sequence ids {first_id} on, up to {})",
                self.sequences,
                super::config::MAX_SEQUENCE_ID + 1 - first_id.min(super::config::MAX_SEQUENCE_ID + 1),
                super::config::MAX_SEQUENCE_ID
            );
        }
        if self.scenes.is_empty() || self.rigs.is_empty() {
            bail!("`generate.scenes` and `generate.rigs` need at least one entry each");
        }
        let ranges = [
            ("mount_z_m", self.mount_z_m, -100.0, 100.0),
            ("pitch_deg", self.pitch_deg, -180.0, 180.0),
            ("roll_deg", self.roll_deg, -180.0, 180.0),
            ("speed_m_per_s", self.speed_m_per_s, -100.0, 100.0),
            ("noise_scale", self.noise_scale, 0.0, 10.0),
            ("dropout", self.dropout, 0.0, 0.9),
            ("intensity_scale", self.intensity_scale, 0.0, 10.0),
        ];
        for (name, r, lo, hi) in ranges {
            if let Some([a, b]) = r
                && !(a.is_finite() && b.is_finite() && lo <= a && a <= b && b <= hi)
            {
                bail!("`generate.{name}` = [{a}, {b}]: a range [low, high] within {lo} ..= {hi}");
            }
        }
        if let Some([a, b]) = self.scene_seed
            && a > b
        {
            bail!("`generate.scene_seed` = [{a}, {b}]: low must not exceed high");
        }
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(self.seed);
        let uniform = |rng: &mut rand_xoshiro::Xoshiro256PlusPlus, r: Option<[f64; 2]>, step: f64| -> Option<f64> {
            r.map(|[a, b]| rounded(if b > a { rng.random_range(a..=b) } else { a }, step))
        };
        let mut out = Vec::with_capacity(self.sequences as usize);
        for k in 0..self.sequences as usize {
            let scene = self.scenes[k % self.scenes.len()].clone();
            let rig = match self.pairing {
                Pairing::Cycled => self.rigs[(k / self.scenes.len()) % self.rigs.len()].clone(),
                Pairing::Interleaved => self.rigs[k % self.rigs.len()].clone(),
            };
            let z = uniform(&mut rng, self.mount_z_m, 0.01);
            let pitch = uniform(&mut rng, self.pitch_deg, 0.01);
            let roll = uniform(&mut rng, self.roll_deg, 0.01);
            let mount = (z.is_some() || pitch.is_some() || roll.is_some()).then(|| MountOverride {
                z_m: z.map(|v| v as f32),
                pitch_deg: pitch.map(|v| v as f32),
                roll_deg: roll.map(|v| v as f32),
                ..MountOverride::default()
            });
            let speed = uniform(&mut rng, self.speed_m_per_s, 0.01).unwrap_or(0.0);
            let noise_scale = uniform(&mut rng, self.noise_scale, 0.001);
            let dropout = uniform(&mut rng, self.dropout, 0.001);
            let intensity_scale = uniform(&mut rng, self.intensity_scale, 0.001);
            let seed = match self.scene_seed {
                Some([a, b]) => rng.random_range(a..=b),
                None => k as u64,
            };
            out.push(SequenceConfig {
                id: first_id + k as u32,
                spec: ScanSpec {
                    scene,
                    seed,
                    rig,
                    mount,
                    frames: self.frames,
                    speed_m_per_s: speed,
                    noise_scale,
                    dropout,
                    intensity_scale,
                    ..ScanSpec::default()
                },
                formats: Vec::new(),
            });
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn generate() -> Generate {
        toml::from_str(
            r#"
            seed = 3
            sequences = 12
            frames = 2
            scenes = ["city", "rural", "hill"]
            rigs = ["hdl64e-roof", "vlp16-roof"]
            scene_seed = [0, 1000]
            mount_z_m = [1.4, 2.4]
            pitch_deg = [-3.0, 3.0]
            dropout = [0.0, 0.1]
            "#,
        )
        .unwrap()
    }

    #[test]
    fn interleaved_pairing_reaches_every_rig_and_scene_in_fewer_sequences() {
        // 3 scenes x 4 rigs in 3 sequences: cycled gives one rig, interleaved three.
        let rigs: Vec<String> = ["hdl64e-roof", "vlp16-roof", "os1-64-roof", "os1-128-roof"].map(String::from).into();
        let base = Generate { sequences: 3, rigs, ..generate() };
        let rigs_of = |g: &Generate| {
            let mut r: Vec<String> = g.draw(0).unwrap().iter().map(|s| s.rig.clone()).collect();
            r.sort();
            r.dedup();
            r.len()
        };
        assert_eq!(rigs_of(&base), 1);
        let interleaved = Generate { pairing: Pairing::Interleaved, ..base };
        assert_eq!(rigs_of(&interleaved), 3);
        let scenes: Vec<String> = interleaved.draw(0).unwrap().iter().map(|s| s.scene.clone()).collect();
        assert_eq!(scenes, interleaved.scenes);
    }

    #[test]
    fn draws_are_seeded_in_range_and_cover_every_pairing() {
        let g = generate();
        let a = g.draw(5).unwrap();
        assert_eq!(a, g.draw(5).unwrap(), "the same draws for the same seed");
        assert_ne!(a, Generate { seed: 4, ..g.clone() }.draw(5).unwrap());
        assert_eq!(a.len(), 12);
        assert_eq!(a[0].id, 5);
        let mut pairs: Vec<(String, String)> = a.iter().map(|s| (s.scene.clone(), s.rig.clone())).collect();
        pairs.sort();
        pairs.dedup();
        assert_eq!(pairs.len(), 6, "3 scenes x 2 rigs");
        for s in &a {
            let m = s.mount.clone().unwrap();
            assert!((1.4..=2.4).contains(&m.z_m.unwrap()) && (-3.0..=3.0).contains(&m.pitch_deg.unwrap()));
            assert!(m.roll_deg.is_none());
            assert!((0.0..=0.1).contains(&s.dropout.unwrap()));
            assert!(s.noise_scale.is_none() && s.seed <= 1000);
        }
    }

    #[test]
    fn bad_tables_are_refused_naming_the_field() {
        let cases = [
            (Generate { sequences: 0, ..generate() }, "generate.sequences"),
            (Generate { sequences: 99, ..generate() }, "generate.sequences"),
            (Generate { rigs: vec![], ..generate() }, "generate.rigs"),
            (Generate { pitch_deg: Some([3.0, -3.0]), ..generate() }, "generate.pitch_deg"),
            (Generate { dropout: Some([0.0, 1.0]), ..generate() }, "generate.dropout"),
            (Generate { noise_scale: Some([f64::NAN, 1.0]), ..generate() }, "generate.noise_scale"),
        ];
        for (g, field) in cases {
            let e = g.draw(5).unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
    }
}
