//! The scene file schema (version 1): header fields, the per-family `[params]` table and the
//! `[[mesh]]` entries for user meshes. Unknown fields are rejected everywhere.

use serde::Deserialize;
use serde::de::DeserializeOwned;

use crate::error::SceneError;

/// The schema version this build reads.
pub const VERSION: i64 = 1;

/// The fields every scene file has, read before the family is known.
#[derive(Debug, Clone)]
pub struct Header {
    /// Generator family name.
    pub family: String,
    /// The file's own seed, if any.
    pub seed: Option<u64>,
    /// The `[weather]` table, if any (`kind = "fog"`, `visibility_m = 50`; see
    /// [`sim::effects::weather::Weather`]).
    pub weather: Option<sim::effects::weather::Weather>,
}

#[derive(Deserialize)]
struct RawHeader {
    version: Option<toml::Value>,
    family: Option<String>,
    seed: Option<u64>,
    weather: Option<toml::Value>,
}

/// Reads `version`, `family` and `seed`, checking the version.
pub fn header(text: &str, source_name: &str) -> Result<Header, SceneError> {
    let raw: RawHeader = toml::from_str(text).map_err(|e| toml_error(source_name, e))?;
    match raw.version {
        None => {
            return Err(SceneError::Toml {
                source_name: source_name.into(),
                message: format!("missing `version = {VERSION}` (the scene schema version)"),
            });
        }
        Some(toml::Value::Integer(VERSION)) => {}
        Some(toml::Value::Integer(v)) => {
            return Err(SceneError::Version { source_name: source_name.into(), version: v });
        }
        Some(other) => {
            return Err(SceneError::Toml {
                source_name: source_name.into(),
                message: format!("`version` must be the integer {VERSION}, got {other}"),
            });
        }
    }
    let family = raw.family.ok_or_else(|| SceneError::Toml {
        source_name: source_name.into(),
        message: "missing `family` (the generator, e.g. family = \"ramp\")".into(),
    })?;
    let weather = match raw.weather {
        None => None,
        Some(v) => {
            let w: sim::effects::weather::Weather = v.try_into().map_err(|e: toml::de::Error| SceneError::Toml {
                source_name: source_name.into(),
                message: format!(
                    "[weather]: {} (kinds: clear, fog with visibility_m, rain or snow with rate_mm_h)",
                    e.message()
                ),
            })?;
            w.validate().map_err(|e| SceneError::Toml {
                source_name: source_name.into(),
                message: format!("[weather]: {e}"),
            })?;
            Some(w)
        }
    };
    Ok(Header { family, seed: raw.seed, weather })
}

/// A whole scene file with the parameters of one family.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct Doc<P> {
    /// Schema version (checked by [`header`]).
    pub version: i64,
    /// Family name.
    pub family: String,
    /// The file's seed.
    #[serde(default)]
    pub seed: Option<u64>,
    /// Family parameters.
    #[serde(default)]
    pub params: P,
    /// User meshes.
    #[serde(default)]
    pub mesh: Vec<MeshEntry>,
    /// The weather (read by [`header`]).
    #[serde(default)]
    pub weather: Option<toml::Value>,
}

/// Parses the whole file with the parameter type `P` of its family.
pub fn doc<P: DeserializeOwned + Default>(text: &str, source_name: &str) -> Result<Doc<P>, SceneError> {
    toml::from_str(text).map_err(|e| toml_error(source_name, e))
}

fn toml_error(source_name: &str, e: toml::de::Error) -> SceneError {
    SceneError::Toml { source_name: source_name.into(), message: e.to_string() }
}

/// A semantic class given by SemanticKITTI name (`"building"`) or id (`50`).
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(untagged)]
pub enum ClassSpec {
    /// Numeric id.
    Id(u16),
    /// Name as [`sim::SemanticClass::name`] spells it.
    Name(String),
}

impl ClassSpec {
    /// The class, or an error naming `field` and the known names.
    pub fn resolve(&self, field: &str) -> Result<sim::SemanticClass, SceneError> {
        let known: Vec<sim::SemanticClass> =
            (0..=u16::from(u8::MAX)).map(sim::SemanticClass).filter(|c| c.name() != "other").collect();
        let found = match self {
            ClassSpec::Id(id) => known.iter().find(|c| c.0 == *id),
            ClassSpec::Name(n) => known.iter().find(|c| c.name() == n),
        };
        found.copied().ok_or_else(|| {
            let names: Vec<String> = known.iter().map(|c| format!("{} ({})", c.name(), c.0)).collect();
            let value = match self {
                ClassSpec::Id(id) => id.to_string(),
                ClassSpec::Name(n) => format!("\"{n}\""),
            };
            SceneError::invalid(field, value, names.join(", "))
        })
    }
}

/// A user mesh placed in the scene.
#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct MeshEntry {
    /// OBJ or PLY file, relative to the scene file's directory (or absolute).
    pub path: String,
    /// Semantic class of every triangle.
    pub class: ClassSpec,
    /// Instance id; default: a fresh id after the generator's objects.
    #[serde(default)]
    pub instance: Option<u32>,
    /// Reflectivity in `[0, 1]`; default: the class's typical value.
    #[serde(default)]
    pub reflectivity: Option<f32>,
    /// Position of the mesh origin in the world, metres.
    #[serde(default)]
    pub position: [f32; 3],
    /// Heading about +z, degrees.
    #[serde(default)]
    pub yaw_deg: f32,
    /// Pitch about the (yawed) +y axis, degrees.
    #[serde(default)]
    pub pitch_deg: f32,
    /// Roll about the (yawed, pitched) +x axis, degrees.
    #[serde(default)]
    pub roll_deg: f32,
    /// Uniform scale applied before rotation (e.g. 0.01 for a mesh in centimetres).
    #[serde(default = "one")]
    pub scale: f32,
}

fn one() -> f32 {
    1.0
}
