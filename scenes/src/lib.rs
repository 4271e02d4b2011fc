//! `scenes`: seeded, parameterised generators that turn a TOML scene description into a labelled
//! triangle mesh ([`sim::SceneMesh`]), and the bundled scene files.
//!
//! A scene file looks like this (every `[params]` field is optional and has a documented default,
//! see the family's `Params` in [`families`]):
//!
//! ```toml
//! version = 1            # schema version, required
//! family = "ramp"        # one of families::NAMES
//! seed = 7               # optional, default 0; see below
//! [params]
//! slope_deg = 12.0
//! [[mesh]]               # optional user meshes (OBJ or PLY), any number
//! path = "statue.obj"    # relative to the TOML file
//! class = "other-structure"   # SemanticKITTI name or id
//! position = [20.0, -6.0, 0.0]
//! yaw_deg = 90.0
//! ```
//!
//! **Seeds.** The seed a generator uses is the file's `seed` plus the caller's seed (wrapping): with
//! the command line's default seed 0 a file's own seed is used as is, and `--seed N` gives N
//! further variants of every file.
//!
//! **Frame.** Metres, x forward, y left, z up; the ego vehicle starts at the origin facing +x on
//! ground of height [`Scene::ego_ground_z_m`] (0 for every bundled family). Lane markings are part
//! of the road surface itself (exactly coplanar, cut out by grid lines), so they are never above it.

pub mod error;
pub mod families;
pub mod grid;
pub mod noise;
pub mod objects;
pub mod schema;
pub mod user_mesh;

use std::path::{Path, PathBuf};

pub use error::SceneError;
use sim::SceneMesh;

/// A generated scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The labelled geometry.
    pub mesh: SceneMesh,
    /// Height of the ground under the ego origin (x = y = 0), metres.
    pub ego_ground_z_m: f32,
    /// Bundled name or file name the scene came from.
    pub name: String,
    /// Generator family.
    pub family: String,
    /// The seed the generator used (file seed + caller seed, wrapping).
    pub seed: u64,
    /// The file's `[weather]` table, if any: the weather scans of this scene use unless told
    /// otherwise.
    pub weather: Option<sim::effects::weather::Weather>,
}

/// The bundled scene files, by name.
const BUNDLED: [(&str, &str); 13] = [
    ("flat", include_str!("../scenes/flat.toml")),
    ("ramp-up", include_str!("../scenes/ramp-up.toml")),
    ("ramp-down", include_str!("../scenes/ramp-down.toml")),
    ("garage", include_str!("../scenes/garage.toml")),
    ("basin", include_str!("../scenes/basin.toml")),
    ("highway", include_str!("../scenes/highway.toml")),
    ("rural", include_str!("../scenes/rural.toml")),
    ("city", include_str!("../scenes/city.toml")),
    ("forest-sparse", include_str!("../scenes/forest-sparse.toml")),
    ("forest-moderate", include_str!("../scenes/forest-moderate.toml")),
    ("forest-dense", include_str!("../scenes/forest-dense.toml")),
    ("hill", include_str!("../scenes/hill.toml")),
    ("elevated", include_str!("../scenes/elevated.toml")),
];

/// Names of the bundled scenes.
pub fn bundled_names() -> Vec<&'static str> {
    BUNDLED.iter().map(|(n, _)| *n).collect()
}

/// The TOML text of a bundled scene.
pub fn bundled_text(name: &str) -> Option<&'static str> {
    BUNDLED.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// Generates the bundled scene `name` with `seed`.
pub fn load_bundled(name: &str, seed: u64) -> Result<Scene, SceneError> {
    let text = bundled_text(name).ok_or_else(|| unknown(name))?;
    // Bundled scenes place no user meshes; relative paths would resolve against the current directory.
    load_str(text, name, Path::new("."), seed)
}

/// Generates a scene from a bundled name or a path to a `.toml` file.
pub fn load(name_or_path: &str, seed: u64) -> Result<Scene, SceneError> {
    if bundled_text(name_or_path).is_some() {
        return load_bundled(name_or_path, seed);
    }
    let path = PathBuf::from(name_or_path);
    if path.extension().is_some_and(|e| e == "toml") || path.exists() {
        return load_file(&path, seed);
    }
    Err(unknown(name_or_path))
}

/// Generates a scene from a TOML file; user mesh paths resolve against the file's directory.
pub fn load_file(path: &Path, seed: u64) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| sim::SimError::io(path, source))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let mut scene = load_str(&text, &path.display().to_string(), &dir, seed)?;
    scene.name = name;
    Ok(scene)
}

/// Generates a scene from TOML text. `source_name` names it in errors; `base_dir` resolves user meshes.
pub fn load_str(text: &str, source_name: &str, base_dir: &Path, seed: u64) -> Result<Scene, SceneError> {
    let header = schema::header(text, source_name)?;
    let effective_seed = header.seed.unwrap_or(0).wrapping_add(seed);
    let (mut generated, meshes) = families::generate(&header.family, text, source_name, effective_seed)?;
    for (k, entry) in meshes.iter().enumerate() {
        let instance = entry.instance.unwrap_or_else(|| generated.ids.fresh());
        let placed = user_mesh::load_placed(entry, k, base_dir, instance)?;
        generated.mesh.append(&placed);
    }
    generated.mesh.validate().map_err(|m| SceneError::Toml { source_name: source_name.into(), message: m })?;
    Ok(Scene {
        mesh: generated.mesh,
        ego_ground_z_m: generated.ego_ground_z_m,
        name: source_name.to_string(),
        family: header.family,
        seed: effective_seed,
        weather: header.weather,
    })
}

fn unknown(name: &str) -> SceneError {
    SceneError::UnknownScene { name: name.into(), known: bundled_names().join(", ") }
}
