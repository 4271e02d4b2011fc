//! The production caster: an obvhs BVH2 (PLOC build, reinsertion, leaf collapse) turned into an
//! 8-wide BVH with this crate's traversal (`wide.rs`), and the watertight triangle test of
//! [`super::watertight`]. obvhs's own BVH2 and CWBVH traversals stay selectable
//! ([`BvhLayout`]) for comparison.
//!
//! - Triangles are copied into leaf order so that a leaf's triangles are contiguous in memory;
//!   `order_to_triangle` maps back to [`SceneMesh::triangles`].
//! - Every primitive box is padded by [`BvhCaster::pad_m`] before the build, so that rounding in the
//!   slab test can never cull a node whose triangle the ray touches exactly on the box boundary
//!   (flat ground gives zero-thickness boxes): the BVH is as watertight as the triangle test.
//! - [`Caster::cast_batch`] exploits LiDAR coherence: consecutive rays of a batch are neighbours on
//!   the sensor grid (one origin or nearly, azimuths a fraction of a degree apart), so groups of
//!   [`BvhOptions::packet_rays`] rays are traversed together as a fan: one interval slab test per
//!   node for the whole group instead of one per ray, exact per-ray tests at the leaves (measured:
//!   about 1.7x the one-ray-at-a-time speed on the fixture). The origins of a fan may differ
//!   (per-laser offsets): the interval test covers them. Groups whose directions straddle an axis
//!   are cast one ray at a time. Optionally ([`BvhOptions::coherent`], off by default: measured no gain)
//!   the triangle the previous ray hit is tested first to seed a short `t_max`.
//! - Every ray gets the same closest hit as [`Caster::cast`], and the grouping depends only on the
//!   batch, so results never depend on the thread count. Of triangles at exactly the same distance
//!   (a shared edge, coplanar overlapping faces) the wide trees report the lowest mesh index, as
//!   the GPU backend does; the obvhs trees of [`BvhOptions`] may report another (a tie is not a
//!   leak).

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
use super::wide::Wide;
use super::{Caster, Hit, Ray};
use crate::scene::SceneMesh;

/// Which obvhs tree the caster traverses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BvhLayout {
    /// Binary BVH (obvhs `Bvh2`, leaves of up to [`BvhOptions::max_prims_per_leaf`] triangles).
    Binary,
    /// Compressed wide BVH8 (obvhs `CwBvh`, SIMD node tests, up to 3 triangles per leaf).
    Wide,
    /// 4-wide BVH collapsed from the obvhs `Bvh2`, with this crate's nearest-first traversal
    /// (structure-of-arrays slab tests of four children at once; see `wide.rs`).
    Four,
    /// 8-wide BVH collapsed the same way, with the same traversal over eight children at once (one
    /// 256-bit operation per plane with AVX2). The fastest: measured 1.2x [`BvhLayout::Four`] on
    /// the fixture's fans and on random rays (docs/benchmarks.md).
    #[default]
    Eight,
}

/// Build and traversal options of [`BvhCaster`] (the defaults are the fastest measured).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhOptions {
    /// Tree layout.
    pub layout: BvhLayout,
    /// Test the previous ray's hit triangle first in [`Caster::cast_batch`] (for fans: the hit of the
    /// same lane in the previous fan) to start with a short `t_max`.
    pub coherent: bool,
    /// Traverse groups of this many consecutive rays together in [`Caster::cast_batch`] (layout
    /// [`BvhLayout::Four`] and [`BvhLayout::Eight`] only; 4, 8, 16 or 32; 0 or 1: one ray at a
    /// time). A group whose directions share one octant is traversed as a fan (interval slab
    /// tests, see `wide.rs`);
    /// other groups one ray at a time.
    pub packet_rays: usize,
    /// Largest number of triangles per leaf (binary, 4- and 8-wide: 1..=255; obvhs's wide: 1..=3).
    pub max_prims_per_leaf: u32,
    /// Fraction of nodes considered for reinsertion after the PLOC build (0 = none).
    pub reinsertion_ratio: f32,
}

impl Default for BvhOptions {
    fn default() -> Self {
        Self {
            layout: BvhLayout::Eight,
            coherent: false,
            packet_rays: 16,
            max_prims_per_leaf: 8,
            reinsertion_ratio: 0.02,
        }
    }
}

enum Tree {
    Empty,
    Binary(Bvh2),
    Wide(CwBvh),
    Four(Wide<4>),
    Eight(Wide<8>),
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

/// Padding of every primitive box of `mesh`'s BVH, metres (see the module docs).
pub(crate) fn pad_for(mesh: &SceneMesh) -> f32 {
    match mesh.bounds() {
        Some((lo, hi)) => 4e-6 * (lo.abs().max(hi.abs()).max_element() + (hi - lo).length()) + 1e-6,
        None => 0.0,
    }
}

/// The obvhs BVH2 (PLOC build, then reinsertion when `reinsertion_ratio > 0`) over the triangles
/// of a non-empty `mesh`, every box padded by `pad_m`; leaves of one triangle each.
pub(crate) fn padded_bvh2(mesh: &SceneMesh, pad_m: f32, reinsertion_ratio: f32) -> Bvh2 {
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
    if reinsertion_ratio > 0.0 {
        ReinsertionOptimizer::default().run(&mut bvh2, reinsertion_ratio, None);
    }
    bvh2
}

impl BvhCaster {
    /// Builds the BVH over `mesh` with the default options.
    pub fn new(mesh: &SceneMesh) -> Self {
        Self::with_options(mesh, BvhOptions::default())
    }

    /// Builds the BVH over `mesh` with `options`.
    pub fn with_options(mesh: &SceneMesh, options: BvhOptions) -> Self {
        let pad_m = pad_for(mesh);
        if mesh.is_empty() {
            return Self { tree: Tree::Empty, tris: Vec::new(), order_to_triangle: Vec::new(), options, pad_m };
        }
        let mut bvh2 = padded_bvh2(mesh, pad_m, options.reinsertion_ratio);
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
            BvhLayout::Four | BvhLayout::Eight => {
                collapse(&mut bvh2, options.max_prims_per_leaf.clamp(1, 255), 3.0);
                let tri_of = |i: u32| mesh.triangle(i as usize);
                let (tree, tris, order) = if options.layout == BvhLayout::Four {
                    let (w, tris, order) = Wide::<4>::from_bvh2(&bvh2, tri_of).into_parts();
                    (Tree::Four(w), tris, order)
                } else {
                    let (w, tris, order) = Wide::<8>::from_bvh2(&bvh2, tri_of).into_parts();
                    (Tree::Eight(w), tris, order)
                };
                return Self { tree, tris, order_to_triangle: order, options, pad_m };
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
    fn cast_seeded(
        &self,
        ray: &Ray,
        pre: &RayPre,
        seed: Option<(u32, f32)>,
        stack: &mut Vec<(u32, f32)>,
    ) -> Option<(u32, f32)> {
        match &self.tree {
            Tree::Four(w) => return w.cast(pre, ray.dir, &self.tris, seed, stack),
            Tree::Eight(w) => return w.cast(pre, ray.dir, &self.tris, seed, stack),
            _ => {}
        }
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
            Tree::Four(_) | Tree::Eight(_) => false, // Handled above.
        };
        if found { Some((hit.primitive_id, hit.t)) } else { seed }
    }

    /// [`Caster::cast_batch`] for the wide trees, `N` rays at a time.
    #[inline(always)]
    fn batch_packets<const W: usize, const N: usize>(
        &self,
        w: &Wide<W>,
        rays: &[Ray],
        out: &mut [Option<Hit>],
        stack: &mut Vec<(u32, f32)>,
    ) {
        let mut prev: [Option<u32>; N] = [None; N];
        for (rs, os) in rays.chunks(N).zip(out.chunks_mut(N)) {
            let Ok(rs) = <&[Ray; N]>::try_from(rs) else {
                for (r, o) in rs.iter().zip(os.iter_mut()) {
                    *o = self.cast(r);
                }
                continue;
            };
            let pres: [RayPre; N] = std::array::from_fn(|i| RayPre::new(&rs[i]));
            let dirs: [Vec3; N] = std::array::from_fn(|i| rs[i].dir);
            let mut best: [Option<(u32, f32)>; N] = [None; N];
            if self.options.coherent {
                for i in 0..N {
                    best[i] = prev[i].and_then(|p| {
                        let [a, b, c] = self.tris[p as usize];
                        pres[i].intersect(a, b, c, rs[i].t_max).map(|t| (p, t))
                    });
                }
            }
            if !w.cast_fan(&pres, &dirs, &self.tris, &mut best, stack) {
                // Mixed direction signs (the fan straddles an axis): one ray at a time.
                for i in 0..N {
                    best[i] = w.cast(&pres[i], dirs[i], &self.tris, best[i], stack);
                }
            }
            for i in 0..N {
                prev[i] = best[i].map(|h| h.0);
                os[i] = best[i].map(|h| self.to_hit(h));
            }
        }
    }

    /// [`Caster::cast_batch`] in fans of [`BvhOptions::packet_rays`] rays, compiled for AVX2 where
    /// the CPU has it (the slab tests of eight children then take one 256-bit operation per plane;
    /// plain IEEE operations only, so the same bits).
    fn batch_fans<const W: usize>(
        &self,
        w: &Wide<W>,
        rays: &[Ray],
        out: &mut [Option<Hit>],
        stack: &mut Vec<(u32, f32)>,
    ) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.batch_fans_avx2(w, rays, out, stack);
            }
        }
        self.batch_fans_body(w, rays, out, stack);
    }

    /// [`BvhCaster::batch_fans_body`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn batch_fans_avx2<const W: usize>(
        &self,
        w: &Wide<W>,
        rays: &[Ray],
        out: &mut [Option<Hit>],
        stack: &mut Vec<(u32, f32)>,
    ) {
        self.batch_fans_body(w, rays, out, stack);
    }

    #[inline(always)]
    fn batch_fans_body<const W: usize>(
        &self,
        w: &Wide<W>,
        rays: &[Ray],
        out: &mut [Option<Hit>],
        stack: &mut Vec<(u32, f32)>,
    ) {
        match self.options.packet_rays {
            2..=4 => self.batch_packets::<W, 4>(w, rays, out, stack),
            5..=8 => self.batch_packets::<W, 8>(w, rays, out, stack),
            9..=16 => self.batch_packets::<W, 16>(w, rays, out, stack),
            _ => self.batch_packets::<W, 32>(w, rays, out, stack),
        }
    }

    fn to_hit(&self, (prim, t): (u32, f32)) -> Hit {
        Hit { t, triangle: self.order_to_triangle[prim as usize] }
    }
}

impl Caster for BvhCaster {
    fn cast(&self, ray: &Ray) -> Option<Hit> {
        let pre = RayPre::new(ray);
        self.cast_seeded(ray, &pre, None, &mut Vec::new()).map(|h| self.to_hit(h))
    }

    fn cast_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        let mut stack = Vec::with_capacity(64);
        if self.options.packet_rays > 1 {
            match &self.tree {
                Tree::Four(w) => return self.batch_fans(w, rays, out, &mut stack),
                Tree::Eight(w) => return self.batch_fans(w, rays, out, &mut stack),
                _ => {}
            }
        }
        if !self.options.coherent {
            for (r, o) in rays.iter().zip(out.iter_mut()) {
                let pre = RayPre::new(r);
                *o = self.cast_seeded(r, &pre, None, &mut stack).map(|h| self.to_hit(h));
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
            let h = self.cast_seeded(r, &pre, seed, &mut stack);
            prev = h.map(|(p, _)| p);
            *o = h.map(|h| self.to_hit(h));
        }
    }
}
