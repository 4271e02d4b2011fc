//! Scene geometry: a triangle mesh whose every triangle carries a [`Surface`] record
//! (semantic class, instance id, reflectivity), plus the two built-in scenes of the simulator.

pub mod builtin;
mod class;
mod mesh;
pub mod ply;
pub mod semantic_kitti;
pub mod snow_cover;

pub use class::SemanticClass;
pub use mesh::{SceneMesh, Surface};
