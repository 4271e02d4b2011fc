//! The generator families. Each module has a `Params` struct (the `[params]` table of a scene
//! file, every field optional with the documented default) and turns it plus a seed into geometry.

pub mod basin;
pub mod city;
pub mod elevated;
pub mod flat;
pub mod forest;
pub mod garage;
pub mod highway;
pub mod hill;
pub mod ramp;
pub mod rural;

use glam::Vec3;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::de::DeserializeOwned;
use sim::SceneMesh;

use crate::error::SceneError;
use crate::objects::Ids;
use crate::schema::{self, MeshEntry};

/// Family names accepted in `family = "..."`.
pub const NAMES: [&str; 12] = [
    "flat",
    "ramp",
    "garage",
    "basin",
    "highway",
    "rural",
    "city",
    "forest-sparse",
    "forest-moderate",
    "forest-dense",
    "hill",
    "elevated",
];

/// What a generator produces.
#[derive(Debug, Default)]
pub struct Generated {
    /// The geometry.
    pub mesh: SceneMesh,
    /// Ground height under the ego origin, metres.
    pub ego_ground_z_m: f32,
    /// The instance-id counter after the generator's objects (user meshes continue from it).
    pub ids: Ids,
}

/// A family's parameters: validated, then generated.
pub trait Family: DeserializeOwned + Default {
    /// Checks every parameter, naming `params.<field>` and its range on failure.
    fn validate(&self) -> Result<(), SceneError>;
    /// Builds the scene (parameters already validated).
    fn build(&self, seed: u64) -> Generated;
}

/// A deterministic random stream for `seed` and a per-purpose `stream` number.
pub fn rng(seed: u64, stream: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed ^ stream.wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

fn run<P: Family>(text: &str, source: &str, seed: u64) -> Result<(Generated, Vec<MeshEntry>), SceneError> {
    let doc = schema::doc::<P>(text, source)?;
    doc.params.validate()?;
    Ok((doc.params.build(seed), doc.mesh))
}

/// Parses the family's parameters from `text` and generates the scene.
pub fn generate(family: &str, text: &str, source: &str, seed: u64) -> Result<(Generated, Vec<MeshEntry>), SceneError> {
    match family {
        "flat" => run::<flat::Params>(text, source, seed),
        "ramp" => run::<ramp::Params>(text, source, seed),
        "garage" => run::<garage::Params>(text, source, seed),
        "basin" => run::<basin::Params>(text, source, seed),
        "highway" => run::<highway::Params>(text, source, seed),
        "rural" => run::<rural::Params>(text, source, seed),
        "city" => run::<city::Params>(text, source, seed),
        "forest-sparse" => run::<forest::Sparse>(text, source, seed),
        "forest-moderate" => run::<forest::Moderate>(text, source, seed),
        "forest-dense" => run::<forest::Dense>(text, source, seed),
        "hill" => run::<hill::Params>(text, source, seed),
        "elevated" => run::<elevated::Params>(text, source, seed),
        _ => Err(SceneError::UnknownFamily {
            source_name: source.into(),
            family: family.into(),
            known: NAMES.join(", "),
        }),
    }
}

/// Whether `p` is farther than `clear_m` from the ego origin (objects keep the ego's spot free).
pub fn clear_of_ego(p: Vec3, clear_m: f32) -> bool {
    p.truncate().length() > clear_m
}
