//! Shared helpers of the subcommands: resolving scene and rig names or files, parsing lists, and the
//! deprecated spellings of flags.

use anyhow::Context;
use groundtruth_scenario::ScanSpec;
use sim::{Rig, SceneMesh};

/// A scene ready to scan (the scenario crate's: mesh, ground under the ego vehicle, weather).
pub use groundtruth_scenario::LoadedScene;
/// Name of the 1.3 M-triangle benchmark terrain (`sim::cast::fixture`), accepted wherever a scene is.
pub use groundtruth_scenario::spec::FIXTURE_TERRAIN;
/// Every scene name this build knows: bundled, built-in, the benchmark terrain and the families.
pub use groundtruth_scenario::spec::scene_names;

/// Loads a scene (any name, family, file or TOML text a [`ScanSpec`]'s `scene` takes), generated
/// with `seed`.
pub fn load_scene_full(name_or_file: &str, seed: u64) -> anyhow::Result<LoadedScene> {
    let spec = ScanSpec { scene: name_or_file.to_string(), seed, ..ScanSpec::default() };
    spec.load_scene().with_context(|| format!("loading scene `{name_or_file}`"))
}

/// Loads a scene's mesh (see [`load_scene_full`]).
pub fn load_scene(name_or_file: &str, seed: u64) -> anyhow::Result<SceneMesh> {
    Ok(load_scene_full(name_or_file, seed)?.mesh)
}

/// Loads a rig by preset name, TOML file path or TOML text.
pub fn load_rig(name_or_file: &str) -> anyhow::Result<Rig> {
    groundtruth_scenario::spec::load_rig(name_or_file).with_context(|| format!("loading rig `{name_or_file}`"))
}

/// Scans a spec's scene with its rig: the scene loaded, [`ScanSpec::setup`], every frame cast and
/// varied as the spec says.
pub fn scan_spec(spec: &ScanSpec) -> anyhow::Result<Vec<sim::scan::Frame>> {
    let scene = spec.load_scene().with_context(|| format!("loading scene `{}`", spec.scene))?;
    let setup = spec.setup(&scene)?;
    let mut frames = sim::scan::scan(&scene.mesh, &setup.rig, &setup.config)
        .with_context(|| format!("scanning `{}`", spec.scene))?;
    for f in &mut frames {
        spec.vary(&mut f.cloud, f.index)?;
    }
    Ok(frames)
}

/// The ego speed given as `--speed-m-per-s` or as its deprecated spelling `--speed` (the same metres
/// per second; clap refuses both together), which says so on stderr; `None` when neither was given.
pub fn speed_m_per_s<T>(speed_m_per_s: Option<T>, deprecated_speed: Option<T>) -> Option<T> {
    if deprecated_speed.is_some() {
        eprintln!("warning: --speed is deprecated, use --speed-m-per-s (the same metres per second)");
    }
    speed_m_per_s.or(deprecated_speed)
}

/// The ego speed flag of the commands that scan with a default speed of their own (`demo`,
/// `bench scan`, `bench agreement`): `--speed-m-per-s`, and `--speed`, its deprecated spelling.
/// A command states its default in the flag's help (`mut_arg`).
#[derive(clap::Args, Debug, Clone)]
pub struct SpeedArgs {
    /// Ego speed, metres per second.
    #[arg(long, allow_negative_numbers = true, conflicts_with = "speed")]
    pub speed_m_per_s: Option<f32>,
    /// Deprecated spelling of --speed-m-per-s (metres per second); removed in the next release.
    #[arg(long, allow_negative_numbers = true, hide = true)]
    pub speed: Option<f32>,
}

impl SpeedArgs {
    /// The speed given (either spelling, [`speed_m_per_s`]), else `default`.
    pub fn or(&self, default: f32) -> f32 {
        speed_m_per_s(self.speed_m_per_s, self.speed).unwrap_or(default)
    }
}

/// Splits a comma-separated list, dropping empty items.
pub fn split_list(s: &str) -> Vec<String> {
    s.split(',').map(str::trim).filter(|x| !x.is_empty()).map(str::to_string).collect()
}

/// Scans `frames` frames of a scene (name or file, generated with `seed`) with a rig (name or
/// file), standing still; `ideal` turns measurement effects off.
pub fn scan_standing(
    scene: &str,
    rig: &str,
    seed: u64,
    frames: usize,
    ideal: bool,
) -> anyhow::Result<Vec<sim::scan::Frame>> {
    let frames = frames as u64;
    scan_spec(&ScanSpec { scene: scene.to_string(), rig: rig.to_string(), seed, frames, ideal, ..ScanSpec::default() })
}

pub use classifier::takes_model;

/// Builds the method `name` (see `groundtruth list`; `seed` seeds RANSAC; `model`: a trained model
/// file for the methods that take one, see [`takes_model`]) through [`classifier::method`].
pub fn method(
    name: &str,
    seed: u64,
    model: Option<&std::path::Path>,
) -> anyhow::Result<Box<dyn classifier::GroundClassifier + Send>> {
    Ok(classifier::method(name, &classifier::MethodOptions { seed, model })?)
}

/// Fails with the caster's device fault (out of memory, an adapter lost mid-run), if any: results
/// since then may be wrong, so the run stops before writing them (no fallback to the CPU: give
/// `--backend bvh` for that).
pub fn check_device(caster: &dyn sim::cast::Caster) -> anyhow::Result<()> {
    match caster.fault() {
        Some(fault) => {
            anyhow::bail!("{fault} (the frames cast since are not written; `--backend bvh` casts on the CPU)")
        }
        None => Ok(()),
    }
}

/// `--layout`: the records of headerless `.bin` files, whatever their names and bytes say
/// ([`classifier::recording::LayoutChoice`]).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayoutArg {
    /// KITTI: float32 x y z intensity (16 bytes per point).
    Kitti,
    /// nuScenes: float32 x y z intensity ring (20 bytes per point, a `LIDAR_TOP` `.pcd.bin`).
    Nuscenes,
}

impl From<LayoutArg> for classifier::recording::LayoutChoice {
    fn from(a: LayoutArg) -> Self {
        match a {
            LayoutArg::Kitti => Self::Kitti,
            LayoutArg::Nuscenes => Self::Nuscenes,
        }
    }
}

/// The report line of a file's layout: `FILE: read as LAYOUT, by BASIS` (`name`, `content` or
/// `flag`) for a nuScenes file and for any layout its name did not decide; `None` for the rest (a
/// KITTI `.bin`, PCD, PLY, LAS or bag message taken by its name, as before there were layouts to
/// tell apart).
pub fn layout_line(provenance: &classifier::recording::Provenance) -> Option<String> {
    use classifier::recording::{InputLayout, LayoutBasis};
    let said = provenance.layout == InputLayout::NuscenesBin || provenance.layout_by != LayoutBasis::Name;
    said.then(|| {
        let why = match (provenance.layout, provenance.layout_by) {
            (InputLayout::NuscenesBin, LayoutBasis::Content) => {
                "by its content (nuScenes' 20-byte records with a whole ring number on every point)"
            }
            (_, LayoutBasis::Content) => "by its content",
            (_, LayoutBasis::Flag) => "by --layout",
            (_, LayoutBasis::Name) => "by its name",
        };
        format!("{}: read as {}, {why}", provenance.file.display(), provenance.layout.description())
    })
}
