//! obvhs BVH backend. TODO(caster helper).
use super::{Caster, Hit, Ray};
use crate::scene::SceneMesh;

/// Production caster (stub).
pub struct BvhCaster;
impl BvhCaster {
    /// Builds the BVH.
    pub fn new(_mesh: &SceneMesh) -> Self {
        Self
    }
}
impl Caster for BvhCaster {
    fn cast(&self, _ray: &Ray) -> Option<Hit> {
        todo!()
    }
}
