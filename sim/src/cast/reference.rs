//! The reference caster: parry3d's BVH (`parry3d::partitioning::Bvh`, the structure a parry
//! `TriMesh` builds and traverses: binned SAH build, best-first `cast_ray` traversal) with the same
//! watertight triangle test as the production backend. It is a reference for the BVH traversal of
//! [`super::BvhCaster`], not for the triangle test.
//!
//! What was done about parry's mesh building: no `TriMesh` is constructed. `TriMesh::new` would keep
//! the vertices as given (it merges duplicates or drops degenerate triangles only with flags), but
//! its BVH is built over exact triangle boxes, and rounding in the slab test can cull a node whose
//! triangle a ray touches exactly on the box boundary (zero-thickness boxes of flat ground). So the
//! leaves are built here, the same way `TriMesh` builds them (`Bvh::from_iter` with the binned
//! strategy, one leaf per triangle, leaf index = triangle index), from boxes padded like the
//! production backend's. Degenerate triangles stay in the tree; the watertight test never hits them.

use glam::Vec3;
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use parry3d::query::Ray as PRay;

use super::watertight::RayPre;
use super::{Caster, Hit, Ray};
use crate::scene::SceneMesh;

/// Reference caster: parry3d BVH traversal + the watertight triangle test.
pub struct ParryCaster {
    bvh: Bvh,
    tris: Vec<[Vec3; 3]>,
}

impl ParryCaster {
    /// Builds parry's BVH over `mesh` (one leaf per triangle, padded boxes).
    pub fn new(mesh: &SceneMesh) -> Self {
        let pad_m = match mesh.bounds() {
            Some((lo, hi)) => 4e-6 * (lo.abs().max(hi.abs()).max_element() + (hi - lo).length()) + 1e-6,
            None => 0.0,
        };
        let tris: Vec<[Vec3; 3]> = (0..mesh.len()).map(|i| mesh.triangle(i)).collect();
        let pad = Vec3::splat(pad_m);
        let leaves =
            tris.iter().enumerate().map(|(i, &[a, b, c])| (i, Aabb::new(a.min(b).min(c) - pad, a.max(b).max(c) + pad)));
        let bvh = Bvh::from_iter(BvhBuildStrategy::Binned, leaves);
        Self { bvh, tris }
    }
}

impl Caster for ParryCaster {
    fn cast(&self, ray: &Ray) -> Option<Hit> {
        if self.tris.is_empty() {
            return None;
        }
        let pre = RayPre::new(ray);
        let pray = PRay::new(ray.origin, ray.dir);
        // parry accepts costs `< max_cost`: one ulp more makes `t_max` inclusive.
        let (id, t) = self.bvh.cast_ray(&pray, ray.t_max.next_up(), |id, best| {
            let [a, b, c] = self.tris[id as usize];
            pre.intersect(a, b, c, best.min(ray.t_max))
        })?;
        Some(Hit { t, triangle: id })
    }
}
