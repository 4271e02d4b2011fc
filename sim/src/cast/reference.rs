//! parry3d reference backend. TODO(caster helper).
use super::{Caster, Hit, Ray};
use crate::scene::SceneMesh;

/// Reference caster (stub).
pub struct ParryCaster;
impl ParryCaster {
    /// Builds the TriMesh.
    pub fn new(_mesh: &SceneMesh) -> Self {
        Self
    }
}
impl Caster for ParryCaster {
    fn cast(&self, _ray: &Ray) -> Option<Hit> {
        todo!()
    }
}
