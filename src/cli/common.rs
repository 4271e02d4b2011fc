//! Shared helpers of the subcommands: resolving scene and rig names or files, and parsing lists.

use anyhow::Context;
use sim::{Rig, SceneMesh};

/// A scene ready to scan: its mesh and the ground height under the ego vehicle.
pub struct LoadedScene {
    /// The mesh.
    pub mesh: SceneMesh,
    /// Ground height below the ego vehicle's start, metres.
    pub ego_ground_z_m: f32,
    /// The scene file's `[weather]`, if any.
    pub weather: Option<sim::effects::weather::Weather>,
}

/// Name of the 1.3 M-triangle benchmark terrain (`sim::cast::fixture`), accepted wherever a scene is.
pub const FIXTURE_TERRAIN: &str = "fixture-terrain";

/// Every scene name this build knows: the simulator's built-ins and the bundled library.
pub fn scene_names() -> Vec<String> {
    let mut names: Vec<String> = sim::scene::builtin::NAMES.iter().map(|s| s.to_string()).collect();
    for n in scenes::bundled_names() {
        if !names.iter().any(|k| k == n) {
            names.push(n.to_string());
        }
    }
    names
}

/// Loads a scene by bundled name, built-in name, or TOML file path, generated with `seed`.
pub fn load_scene_full(name_or_file: &str, seed: u64) -> anyhow::Result<LoadedScene> {
    if name_or_file == FIXTURE_TERRAIN {
        return Ok(LoadedScene { mesh: sim::cast::fixture::terrain_scene(), ego_ground_z_m: 0.0, weather: None });
    }
    let is_builtin = sim::scene::builtin::NAMES.contains(&name_or_file);
    let is_bundled = scenes::bundled_names().contains(&name_or_file);
    if is_builtin && !is_bundled {
        return Ok(LoadedScene {
            mesh: sim::scene::builtin::builtin(name_or_file)?,
            ego_ground_z_m: 0.0,
            weather: None,
        });
    }
    if !is_bundled && !name_or_file.ends_with(".toml") {
        anyhow::bail!(
            "unknown scene `{name_or_file}`; known: {} (or a path to a .toml scene file)",
            scene_names().join(", ")
        );
    }
    let scene = scenes::load(name_or_file, seed).with_context(|| format!("loading scene `{name_or_file}`"))?;
    Ok(LoadedScene { mesh: scene.mesh, ego_ground_z_m: scene.ego_ground_z_m, weather: scene.weather })
}

/// Loads a scene's mesh (see [`load_scene_full`]).
pub fn load_scene(name_or_file: &str, seed: u64) -> anyhow::Result<SceneMesh> {
    Ok(load_scene_full(name_or_file, seed)?.mesh)
}

/// The weather of a scan: `--weather SPEC` when given, else the scene file's `[weather]`.
pub fn weather(spec: Option<&str>, scene: &LoadedScene) -> anyhow::Result<Option<sim::effects::weather::Weather>> {
    match spec {
        Some(s) => Ok(Some(sim::effects::weather::Weather::parse(s).context("--weather")?)),
        None => Ok(scene.weather),
    }
}

/// Loads a rig by preset name or TOML file path.
pub fn load_rig(name_or_file: &str) -> anyhow::Result<Rig> {
    Rig::load(name_or_file).with_context(|| format!("loading rig `{name_or_file}`"))
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
    let loaded = load_scene_full(scene, seed)?;
    let rig = load_rig(rig)?;
    let config = sim::scan::ScanConfig { seed, frames, ideal, ego_z_m: loaded.ego_ground_z_m, ..Default::default() };
    sim::scan::scan(&loaded.mesh, &rig, &config).with_context(|| format!("scanning `{scene}`"))
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
