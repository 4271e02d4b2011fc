//! The production caster: an obvhs BVH (PLOC build) over the scene's triangles, traversed with the
//! watertight triangle test of [`super::watertight`].
//!
//! - Triangles are copied into BVH order (leaf order) so that a leaf's triangles are contiguous in
//!   memory; `order_to_triangle` maps back to [`SceneMesh::triangles`].
//! - Every primitive box is padded by [`BvhCaster::pad_m`] before the build, so that rounding in the
//!   slab test can never cull a node whose triangle the ray touches exactly on the box boundary
//!   (flat ground gives zero-thickness boxes): the BVH is as watertight as the triangle test.
//! - [`Caster::cast_batch`] exploits LiDAR coherence: consecutive rays of a batch are neighbours on
//!   the sensor grid, so the triangle the previous ray hit (and its leaf) is tested first; a hit there
//!   gives the traversal a short `t_max` from the start, which culls most of the far nodes.
//!   The result is the same closest hit as [`Caster::cast`] (ties between triangles at exactly the
//!   same distance may pick the other triangle; a tie is not a leak).

use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::leaf_collapser::collapse;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::ploc::{PlocBuilder, PlocSearchDistance, SortPrecision};
use obvhs::ray::{Ray as ORay, RayHit};

use super::watertight::RayPre;
use super::{Caster, Hit, Ray};
use crate::scene::SceneMesh;

/// Which obvhs tree the caster traverses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BvhLayout {
    /// Binary BVH (obvhs `Bvh2`, leaves of up to [`BvhOptions::max_prims_per_leaf`] triangles).
    #[default]
    Binary,
    /// Compressed wide BVH8 (obvhs `CwBvh`, SIMD node tests, up to 3 triangles per leaf).
    Wide,
}

/// Build and traversal options of [`BvhCaster`] (the defaults are the fastest measured).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhOptions {
    /// Tree layout.
    pub layout: BvhLayout,
    /// Test the previous ray's hit triangle first in [`Caster::cast_batch`].
    pub coherent: bool,
    /// Largest number of triangles per leaf (binary: 1..=255, wide: 1..=3).
    pub max_prims_per_leaf: u32,
    /// Fraction of nodes considered for reinsertion after the PLOC build (0 = none).
    pub reinsertion_ratio: f32,
}

impl Default for BvhOptions {
    fn default() -> Self {
        Self { layout: BvhLayout::Binary, coherent: true, max_prims_per_leaf: 4, reinsertion_ratio: 0.02 }
    }
}

enum Tree {
    Empty,
    Binary(Bvh2),
    Wide(CwBvh),
}

/// Production caster: obvhs BVH + watertight triangles; rayon over rays in [`Caster::cast_all`].
pub struct BvhCaster {
    tree: Tree,
    /// Triangle corners in BVH order.
    tris: Vec<[Vec3; 3]>,
    /// BVH order -> index into [`SceneMesh::triangles`].
    order_to_triangle: Vec<u32>,
    options: BvhOptions,
    pad_m: f32,
}

impl BvhCaster {
    /// Builds the BVH over `mesh` with the default options.
    pub fn new(mesh: &SceneMesh) -> Self {
        Self::with_options(mesh, BvhOptions::default())
    }

    /// Builds the BVH over `mesh` with `options`.
    pub fn with_options(mesh: &SceneMesh, options: BvhOptions) -> Self {
        let pad_m = match mesh.bounds() {
            Some((lo, hi)) => 4e-6 * (lo.abs().max(hi.abs()).max_element() + (hi - lo).length()) + 1e-6,
            None => 0.0,
        };
        if mesh.is_empty() {
            return Self { tree: Tree::Empty, tris: Vec::new(), order_to_triangle: Vec::new(), options, pad_m };
        }
        let pad = Vec3A::splat(pad_m);
        let aabbs: Vec<Aabb> = (0..mesh.len())
            .map(|i| {
                let [a, b, c] = mesh.triangle(i);
                let (a, b, c) = (Vec3A::from(a), Vec3A::from(b), Vec3A::from(c));
                Aabb::new(a.min(b).min(c) - pad, a.max(b).max(c) + pad)
            })
            .collect();
        let mut bvh2 = PlocBuilder::with_capacity(aabbs.len()).build(
            PlocSearchDistance::Low,
            &aabbs,
            (0..aabbs.len() as u32).collect(),
            SortPrecision::U64,
            2,
        );
        if options.reinsertion_ratio > 0.0 {
            ReinsertionOptimizer::default().run(&mut bvh2, options.reinsertion_ratio, None);
        }
        let (tree, indices) = match options.layout {
            BvhLayout::Binary => {
                collapse(&mut bvh2, options.max_prims_per_leaf.clamp(1, 255), 3.0);
                let idx = std::mem::take(&mut bvh2.primitive_indices);
                (Tree::Binary(bvh2), idx)
            }
            BvhLayout::Wide => {
                let mut cw = bvh2_to_cwbvh(&bvh2, options.max_prims_per_leaf.clamp(1, 3), true, false);
                let idx = std::mem::take(&mut cw.primitive_indices);
                (Tree::Wide(cw), idx)
            }
        };
        let tris = indices.iter().map(|&i| mesh.triangle(i as usize)).collect();
        Self { tree, tris, order_to_triangle: indices, options, pad_m }
    }

    /// Padding added to every primitive box, metres.
    pub fn pad_m(&self) -> f32 {
        self.pad_m
    }

    /// The options this caster was built with.
    pub fn options(&self) -> BvhOptions {
        self.options
    }

    /// Closest hit with an optional seed: `(bvh-order index, t)` of a hit already known.
    #[inline(always)]
    fn cast_seeded(&self, ray: &Ray, pre: &RayPre, seed: Option<(u32, f32)>) -> Option<(u32, f32)> {
        let limit = seed.map_or(ray.t_max, |(_, t)| t);
        // obvhs accepts `t < ray.tmax`: widen by one ulp for an inclusive `t_max` when unseeded,
        // stay strict against a seed (a tie keeps the seed).
        let tmax = if seed.is_some() { limit } else { limit.next_up() };
        let o = ORay::new(Vec3A::from(ray.origin), Vec3A::from(ray.dir), 0.0, tmax);
        let tris = &self.tris;
        let test = |r: &ORay, id: usize| -> f32 {
            let [a, b, c] = tris[id];
            pre.intersect(a, b, c, r.tmax).unwrap_or(f32::INFINITY)
        };
        let mut hit = RayHit::none();
        let found = match &self.tree {
            Tree::Empty => false,
            Tree::Binary(b) => b.ray_traverse(o, &mut hit, test),
            Tree::Wide(w) => w.ray_traverse(o, &mut hit, test),
        };
        if found { Some((hit.primitive_id, hit.t)) } else { seed }
    }

    fn to_hit(&self, (prim, t): (u32, f32)) -> Hit {
        Hit { t, triangle: self.order_to_triangle[prim as usize] }
    }
}

impl Caster for BvhCaster {
    fn cast(&self, ray: &Ray) -> Option<Hit> {
        let pre = RayPre::new(ray);
        self.cast_seeded(ray, &pre, None).map(|h| self.to_hit(h))
    }

    fn cast_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        if !self.options.coherent {
            for (r, o) in rays.iter().zip(out.iter_mut()) {
                *o = self.cast(r);
            }
            return;
        }
        let mut prev: Option<u32> = None;
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            let pre = RayPre::new(r);
            let seed = prev.and_then(|p| {
                let [a, b, c] = self.tris[p as usize];
                pre.intersect(a, b, c, r.t_max).map(|t| (p, t))
            });
            let h = self.cast_seeded(r, &pre, seed);
            prev = h.map(|(p, _)| p);
            *o = h.map(|h| self.to_hit(h));
        }
    }
}
