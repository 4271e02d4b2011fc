//! The scene of a [`super::ScanSpec`]: every kind of scene any front end names, resolved in one
//! order and loaded in one place.

use std::path::{Path, PathBuf};

use crate::error::{Result, ScenarioError};
use crate::geometry::Geometry;
use crate::param_value::ParamValue;

/// Name of the 1.3 M-triangle benchmark terrain (`sim::cast::fixture`), accepted wherever a scene is.
pub const FIXTURE_TERRAIN: &str = "fixture-terrain";

/// Every scene name: the bundled library, the simulator's built-ins that are not also bundled
/// (`flat-objects`), the benchmark terrain and the generator families (default parameters).
pub fn scene_names() -> Vec<String> {
    let mut names: Vec<String> = sim::scene::builtin::NAMES.iter().map(|s| s.to_string()).collect();
    for n in scenes::bundled_names().into_iter().chain([FIXTURE_TERRAIN]).chain(scenes::families::NAMES) {
        if !names.iter().any(|k| k == n) {
            names.push(n.to_string());
        }
    }
    names
}

/// Whether `s` is TOML text rather than a name or a path (a newline, or a `key = value`).
pub(crate) fn is_toml_text(s: &str) -> bool {
    s.contains('\n') || s.contains('=')
}

/// Where a scene comes from, in the order a name is resolved.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum SceneSource {
    /// Scene TOML text (user meshes resolve against the current directory).
    Text(String),
    /// The benchmark terrain.
    Fixture,
    /// A simulator built-in that no bundled scene shadows (`flat-objects`).
    Builtin(String),
    /// A bundled scene.
    Bundled(String),
    /// A generator family with its default parameters.
    Family(String),
    /// A scene TOML file (user meshes resolve against its directory).
    File(PathBuf),
}

impl SceneSource {
    /// Resolves `scene`: TOML text, `fixture-terrain`, a built-in, a bundled scene, a family, then a
    /// `.toml` (or any existing) file.
    pub(crate) fn resolve(scene: &str) -> Result<Self> {
        let bundled = scenes::bundled_names().contains(&scene);
        Ok(if is_toml_text(scene) {
            Self::Text(scene.to_string())
        } else if scene == FIXTURE_TERRAIN {
            Self::Fixture
        } else if sim::scene::builtin::NAMES.contains(&scene) && !bundled {
            Self::Builtin(scene.to_string())
        } else if bundled {
            Self::Bundled(scene.to_string())
        } else if scenes::families::NAMES.contains(&scene) {
            Self::Family(scene.to_string())
        } else if scene.ends_with(".toml") || Path::new(scene).is_file() {
            Self::File(PathBuf::from(scene))
        } else {
            return Err(ScenarioError::invalid(
                "scene",
                format!("`{scene}`"),
                format!("{} (or a .toml scene file, or scene TOML text)", scene_names().join(", ")),
            ));
        })
    }
}

/// A scene ready to scan: its mesh, the ground under the ego vehicle, its own weather, and what it
/// is (for reports and the scenario API's regions).
pub struct LoadedScene {
    /// The mesh.
    pub mesh: sim::SceneMesh,
    /// Ground height below the ego vehicle's start, metres.
    pub ego_ground_z_m: f32,
    /// The scene file's `[weather]`, if any.
    pub weather: Option<sim::effects::weather::Weather>,
    /// The generator family (`ramp`, `city`, ...), or the built-in scene's name.
    pub family: String,
    /// The scene's name: the bundled name, family, file path, or `scenario TOML`.
    pub name: String,
    /// The family's region-defining parameters.
    pub(crate) geometry: Geometry,
}

impl LoadedScene {
    /// A mesh built in code (a test's shapes) as a scene: ground under the ego at z = 0, no
    /// weather, no family geometry.
    pub fn from_mesh(mesh: sim::SceneMesh, name: &str) -> Self {
        Self {
            mesh,
            ego_ground_z_m: 0.0,
            weather: None,
            family: name.to_string(),
            name: name.to_string(),
            geometry: Geometry::Other,
        }
    }
}

impl std::fmt::Debug for LoadedScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LoadedScene")
            .field("name", &self.name)
            .field("family", &self.family)
            .field("triangles", &self.mesh.len())
            .field("ego_ground_z_m", &self.ego_ground_z_m)
            .field("weather", &self.weather)
            .finish()
    }
}

/// Generates the scene of `source` with `params` overriding its family's parameters and `seed`
/// added to its own.
pub(crate) fn load(
    source: SceneSource,
    params: &std::collections::BTreeMap<String, ParamValue>,
    seed: u64,
) -> Result<LoadedScene> {
    let (text, name, base_dir) = match source {
        SceneSource::Fixture | SceneSource::Builtin(_) => {
            if let Some(k) = params.keys().next() {
                return Err(ScenarioError::invalid(
                    format!("params.{k}"),
                    "(set)",
                    "none: built-in scenes take no parameters",
                ));
            }
            let (mesh, scene) = match source {
                SceneSource::Builtin(name) => (sim::scene::builtin::builtin(&name)?, name),
                _ => (sim::cast::fixture::terrain_scene(), FIXTURE_TERRAIN.to_string()),
            };
            return Ok(LoadedScene {
                mesh,
                ego_ground_z_m: 0.0,
                weather: None,
                family: scene.clone(),
                name: scene,
                geometry: Geometry::Other,
            });
        }
        SceneSource::Text(t) => (t, "scenario TOML".to_string(), PathBuf::from(".")),
        SceneSource::Bundled(n) => {
            let t = scenes::bundled_text(&n).unwrap_or_default().to_string();
            (t, n, PathBuf::from("."))
        }
        SceneSource::Family(f) => {
            (format!("version = 1\nfamily = {}\n", toml::Value::String(f.clone())), f, PathBuf::from("."))
        }
        SceneSource::File(p) => {
            let t = std::fs::read_to_string(&p).map_err(|source| ScenarioError::Io { path: p.clone(), source })?;
            let dir = p.parent().map(Path::to_path_buf).unwrap_or_default();
            (t, p.display().to_string(), dir)
        }
    };
    let text = with_params(text, &name, params)?;
    let scene = scenes::load_str(&text, &name, &base_dir, seed)?;
    let geometry = Geometry::parse(&scene.family, &text, &name)?;
    Ok(LoadedScene {
        mesh: scene.mesh,
        ego_ground_z_m: scene.ego_ground_z_m,
        weather: scene.weather,
        family: scene.family,
        name,
        geometry,
    })
}

/// The scene's TOML text with the parameter overrides in its `[params]` table (unchanged when
/// there are none).
fn with_params(text: String, name: &str, params: &std::collections::BTreeMap<String, ParamValue>) -> Result<String> {
    if params.is_empty() {
        return Ok(text);
    }
    let mut doc: toml::Table = text.parse().map_err(|e: toml::de::Error| scenes::SceneError::Toml {
        source_name: name.to_string(),
        message: e.to_string(),
    })?;
    let table = doc.entry("params").or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let toml::Value::Table(table) = table else {
        return Err(ScenarioError::invalid("params", "not a table", "a [params] table"));
    };
    for (k, v) in params {
        if let ParamValue::Float(f) = v
            && !f.is_finite()
        {
            return Err(ScenarioError::invalid(format!("params.{k}"), f, "a finite number"));
        }
        table.insert(k.clone(), v.to_toml());
    }
    toml::to_string(&doc).map_err(|e| ScenarioError::invalid("params", e, "TOML values"))
}
