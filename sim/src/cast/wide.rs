//! A `W`-wide BVH (4 or 8) collapsed from an obvhs `Bvh2`, with a closest-hit traversal that tests
//! the `W` child boxes of a node together (structure-of-arrays, so the slab tests vectorise: one
//! 256-bit operation per plane for eight children with AVX2) and visits children nearest first. Triangles are stored in the order the leaves are laid out, and each
//! leaf's triangles again four to a SIMD pack ([`TriPack`], `tri_pack.rs`): one ray tests a leaf
//! of up to four triangles at once.
//!
//! Collapse rule: starting from a binary node's two children, the inner child with the largest
//! surface area is replaced by its own two children until there are `W` or only leaves remain.
//!
//! Fans of rays ([`Wide::cast_fan`]) test inner nodes once for the whole fan (interval slab
//! tests) and a leaf child against all the fan's rays at once (the rays in the lanes).

use glam::Vec3;
use obvhs::bvh2::Bvh2;

use super::tri_pack::TriPack;
use super::watertight::RayPre;

/// Marks an unused child slot.
const EMPTY: u32 = u32::MAX;

/// One node: bounds of up to `W` children, structure-of-arrays.
#[derive(Clone, Copy, Debug)]
struct Node<const W: usize> {
    /// `bounds[a][k]`: axis `a` minimum (a = 0..3) and maximum (a = 3..6) of child `k`.
    bounds: [[f32; W]; 6],
    /// Inner child: node index; leaf child: its first [`TriPack`].
    child: [u32; W],
    /// 0 for an inner child, the triangle count for a leaf, [`EMPTY`] for an unused slot.
    count: [u32; W],
}

impl<const W: usize> Node<W> {
    fn empty() -> Self {
        let mut bounds = [[f32::INFINITY; W]; 6];
        bounds[3..].iter_mut().for_each(|b| *b = [f32::NEG_INFINITY; W]);
        Self { bounds, child: [0; W], count: [EMPTY; W] }
    }
}

/// The `W`-wide BVH and its triangles in layout order.
pub(super) struct Wide<const W: usize> {
    nodes: Vec<Node<W>>,
    /// Triangle corners in layout order.
    pub(super) tris: Vec<[Vec3; 3]>,
    /// Each leaf's triangles, four to a pack (a leaf's packs are consecutive).
    packs: Vec<TriPack>,
    /// Layout order -> index into the mesh's triangles.
    pub(super) order_to_triangle: Vec<u32>,
    /// The root is a single leaf (tiny meshes): `(first pack, triangle count)`.
    root_leaf: Option<(u32, u32)>,
}

/// Per-ray traversal constants.
struct RayBox {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    /// Index into `Node4::bounds` of the near plane per axis (min for a positive direction).
    near: [usize; 3],
    far: [usize; 3],
}

impl<const W: usize> Wide<W> {
    /// Collapses `bvh2` (with `primitive_indices` into `tris_of_mesh`) into a `W`-wide BVH.
    pub(super) fn from_bvh2(bvh2: &Bvh2, tri_of: impl Fn(u32) -> [Vec3; 3]) -> Self {
        // Sized once (growing them by doubling cost a tenth of the build of a 1.3 M-triangle mesh):
        // every triangle is in one leaf, a leaf has at least one pack, and the binary tree has at
        // least as many nodes as the wide one.
        let triangles = bvh2.primitive_indices.len();
        let mut w = Self {
            nodes: Vec::with_capacity(bvh2.nodes.len().div_ceil(W - 1)),
            tris: Vec::with_capacity(triangles),
            packs: Vec::with_capacity(bvh2.nodes.len().div_ceil(2).min(triangles)),
            order_to_triangle: Vec::with_capacity(triangles),
            root_leaf: None,
        };
        if bvh2.nodes.is_empty() {
            return w;
        }
        let root = &bvh2.nodes[0];
        if root.is_leaf() {
            let first = w.emit_leaf(bvh2, 0, &tri_of);
            w.root_leaf = Some((first, root.prim_count));
            return w;
        }
        w.nodes.push(Node::empty());
        w.fill(bvh2, 0, 0, &tri_of);
        w
    }

    /// The tree without its triangles, the triangles (layout order) and the layout order's mesh
    /// indices (also kept in the tree: its tie-break reads them).
    pub(super) fn into_parts(mut self) -> (Self, Vec<[Vec3; 3]>, Vec<u32>) {
        let tris = std::mem::take(&mut self.tris);
        let order = self.order_to_triangle.clone();
        (self, tris, order)
    }

    /// Appends the triangles of the binary leaf `node` and their packs; returns the first pack.
    fn emit_leaf(&mut self, bvh2: &Bvh2, node: usize, tri_of: &impl Fn(u32) -> [Vec3; 3]) -> u32 {
        let n = &bvh2.nodes[node];
        let first = self.tris.len();
        for i in n.first_index..n.first_index + n.prim_count {
            let prim = bvh2.primitive_indices[i as usize];
            self.tris.push(tri_of(prim));
            self.order_to_triangle.push(prim);
        }
        let first_pack = self.packs.len() as u32;
        self.packs.extend(TriPack::pack(&self.tris[first..], first as u32));
        first_pack
    }

    /// Fills node `slot` of `self` from the binary inner node `node`.
    fn fill(&mut self, bvh2: &Bvh2, node: usize, slot: usize, tri_of: &impl Fn(u32) -> [Vec3; 3]) {
        let first = bvh2.nodes[node].first_index as usize;
        // Up to W children, on the stack (a heap vector per node cost a tenth of the build).
        let mut kids = [0usize; W];
        (kids[0], kids[1]) = (first, first + 1);
        let mut len = 2;
        while len < W {
            let best = kids[..len]
                .iter()
                .enumerate()
                .filter(|(_, k)| !bvh2.nodes[**k].is_leaf())
                .max_by(|a, b| bvh2.nodes[*a.1].aabb().half_area().total_cmp(&bvh2.nodes[*b.1].aabb().half_area()));
            let Some((i, &k)) = best else { break };
            let f = bvh2.nodes[k].first_index as usize;
            // `swap_remove(i)`, then push both children.
            kids[i] = kids[len - 1];
            kids[len - 1] = f;
            kids[len] = f + 1;
            len += 1;
        }
        for (j, &k) in kids[..len].iter().enumerate() {
            let n = &bvh2.nodes[k];
            let bb = n.aabb();
            for a in 0..3 {
                self.nodes[slot].bounds[a][j] = bb.min[a];
                self.nodes[slot].bounds[a + 3][j] = bb.max[a];
            }
            if n.is_leaf() {
                let first = self.emit_leaf(bvh2, k, tri_of);
                self.nodes[slot].child[j] = first;
                self.nodes[slot].count[j] = n.prim_count;
            } else {
                let child = self.nodes.len();
                self.nodes.push(Node::empty());
                self.nodes[slot].child[j] = child as u32;
                self.nodes[slot].count[j] = 0;
                self.fill(bvh2, k, child, tri_of);
            }
        }
    }

    /// Closest hit `(layout index, t)` of the ray prepared in `pre` against `tris` (this tree's
    /// triangles in layout order, taken out of `self.tris` by the caller), not farther than `seed`'s `t`
    /// (and, with a seed, strictly closer than it, so a tie keeps the seed).
    #[inline(always)]
    pub(super) fn cast(
        &self,
        pre: &RayPre,
        dir: Vec3,
        tris: &[[Vec3; 3]],
        seed: Option<(u32, f32)>,
        stack: &mut Vec<(u32, f32)>,
    ) -> Option<(u32, f32)> {
        let mut best = seed;
        let mut best_t = seed.map_or(pre.t_max, |s| s.1);
        if let Some((first, count)) = self.root_leaf {
            self.leaf(tris, pre, first, count, &mut best, &mut best_t);
            return best;
        }
        if self.nodes.is_empty() {
            return best;
        }
        let inv_dir = [safe_inv(dir.x), safe_inv(dir.y), safe_inv(dir.z)];
        let near = |a: usize| a + usize::from(inv_dir[a] < 0.0) * 3;
        let far = |a: usize| a + usize::from(inv_dir[a] >= 0.0) * 3;
        let rb = RayBox {
            origin: pre.origin.to_array(),
            inv_dir,
            near: [near(0), near(1), near(2)],
            far: [far(0), far(1), far(2)],
        };
        stack.clear();
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            let (t_near, hit) = slab(n, &rb, best_t);
            // Children met, nearest first.
            let (order, m) = nearest_first(&t_near, hit);
            // Leaves at once (they shorten `best_t` for their siblings), inner children after.
            let mut inner = [(0u32, 0.0f32); W];
            let mut q = 0;
            for &(k, t) in &order[..m] {
                if n.count[k] == 0 {
                    inner[q] = (n.child[k], t);
                    q += 1;
                } else if t <= best_t {
                    self.leaf(tris, pre, n.child[k], n.count[k], &mut best, &mut best_t);
                }
            }
            // Descend into the nearest inner child; push the others farthest first.
            match next_node(&inner[..q], stack, best_t) {
                Some(c) => node = c,
                None => return best,
            }
        }
    }

    /// Asks the CPU to start loading the triangle packs of the leaf children of `n` in `hit` (bit `k`
    /// for child `k`): a fan's leaf tests otherwise wait on memory (the packs of a large scene do
    /// not fit in the caches).
    #[inline(always)]
    fn prefetch_leaves(&self, n: &Node<W>, hit: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            let mut todo = hit;
            while todo != 0 {
                let k = todo.trailing_zeros() as usize;
                todo &= todo - 1;
                let count = n.count[k];
                if count == 0 {
                    continue;
                }
                let first = n.child[k] as usize;
                let packs = &self.packs[first..first + count.div_ceil(4) as usize];
                let bytes = std::mem::size_of_val(packs);
                let base = packs.as_ptr().cast::<i8>();
                for offset in (0..bytes).step_by(64) {
                    // SAFETY: `base + offset` lies within `packs`; a prefetch never faults.
                    #[allow(unsafe_code)]
                    unsafe {
                        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(base.add(offset));
                    }
                }
            }
        }
    }

    /// The closest hit among a leaf's `count` triangles (packs from `first_pack` on, tested in
    /// layout order); of triangles at exactly the same distance (a shared edge, coplanar overlapping
    /// faces), the one with the lowest mesh index, so that every layout of the tree and the GPU
    /// backend report the same triangle (and label).
    #[inline(always)]
    fn leaf(
        &self,
        tris: &[[Vec3; 3]],
        pre: &RayPre,
        first_pack: u32,
        count: u32,
        best: &mut Option<(u32, f32)>,
        best_t: &mut f32,
    ) {
        let ids = &self.order_to_triangle;
        let first_pack = first_pack as usize;
        for pack in &self.packs[first_pack..first_pack + count.div_ceil(4) as usize] {
            // `intersect` keeps `t <= best_t`: a tie is `t == best_t`.
            pack.intersect(pre, tris, best_t, |i, t| {
                let better = match *best {
                    None => true,
                    Some((j, bt)) => t < bt || ids[i as usize] < ids[j as usize],
                };
                if better {
                    *best = Some((i, t));
                }
                better
            });
        }
    }
}

/// `1 / d`, or +-1e30 (with the sign of `d`) where that would overflow: slab distances stay finite
/// or infinite but never NaN (`0 * inf`) for a ray lying exactly in a box face.
#[inline(always)]
fn safe_inv(d: f32) -> f32 {
    if d.abs() < 1e-30 { 1e30f32.copysign(d) } else { 1.0 / d }
}

/// Slab test of the `W` children: entry distances and which children the ray meets in `[0, t_max]`
/// (bit `k` for child `k`).
#[inline(always)]
fn slab<const W: usize>(n: &Node<W>, rb: &RayBox, t_max: f32) -> ([f32; W], u32) {
    let mut t_near = [0.0f32; W];
    let mut t_far = [t_max; W];
    for a in 0..3 {
        let (o, i) = (rb.origin[a], rb.inv_dir[a]);
        let lo = &n.bounds[rb.near[a]];
        let hi = &n.bounds[rb.far[a]];
        for k in 0..W {
            t_near[k] = t_near[k].max((lo[k] - o) * i);
            t_far[k] = t_far[k].min((hi[k] - o) * i);
        }
    }
    let mut hit = 0u32;
    for k in 0..W {
        hit |= u32::from(t_near[k] <= t_far[k]) << k;
    }
    (t_near, hit)
}

impl<const W: usize> Wide<W> {
    /// Closest hits of `N` rays whose directions have the same sign on every axis (a small fan of
    /// LiDAR beams), or `false` without touching `best` when they do not.
    ///
    /// Inner nodes are tested once for the whole fan with interval arithmetic: per axis, the fan's
    /// origins span `[o_lo, o_hi]` (one point for most sensors, a few centimetres for per-laser
    /// offsets) and its inverse directions `[i_lo, i_hi]`, so the plane `b` is reached between the
    /// smallest and the largest of the four products `(b - o) i` at the interval corners (the product
    /// is bilinear); a node is entered when `max_axis(min entry) <= min_axis(max exit)`, a superset of
    /// "some ray meets the box". Leaves get an exact per-ray slab test before their triangles are
    /// tested for that ray, so each ray gets the same closest hit as [`Wide::cast`] (up to exact
    /// ties).
    #[inline(always)]
    pub(super) fn cast_fan<const N: usize>(
        &self,
        pres: &[RayPre; N],
        dirs: &[Vec3; N],
        tris: &[[Vec3; 3]],
        best: &mut [Option<(u32, f32)>; N],
        stack: &mut Vec<(u32, f32)>,
    ) -> bool {
        if self.root_leaf.is_some() || self.nodes.is_empty() {
            return false;
        }
        let inv: [[f32; 3]; N] =
            std::array::from_fn(|r| [safe_inv(dirs[r].x), safe_inv(dirs[r].y), safe_inv(dirs[r].z)]);
        let mut i_lo = [f32::INFINITY; 3];
        let mut i_hi = [f32::NEG_INFINITY; 3];
        for a in 0..3 {
            let neg = inv[0][a] < 0.0;
            for v in &inv {
                if (v[a] < 0.0) != neg {
                    return false;
                }
                i_lo[a] = i_lo[a].min(v[a]);
                i_hi[a] = i_hi[a].max(v[a]);
            }
        }
        let o_lo = pres.iter().fold(Vec3::INFINITY, |m, p| m.min(p.origin)).to_array();
        let o_hi = pres.iter().fold(Vec3::NEG_INFINITY, |m, p| m.max(p.origin)).to_array();
        let near: [usize; 3] = std::array::from_fn(|a| a + usize::from(i_lo[a] < 0.0) * 3);
        let far: [usize; 3] = std::array::from_fn(|a| a + usize::from(i_lo[a] >= 0.0) * 3);
        let walk = FanWalk {
            fan: Fan { o_lo, o_hi, i_lo, i_hi },
            rays: RaysSoa {
                origin: std::array::from_fn(|a| std::array::from_fn(|r| pres[r].origin[a])),
                inv_dir: std::array::from_fn(|a| std::array::from_fn(|r| inv[r][a])),
            },
            near,
            far,
        };
        if pres.iter().all(|p| p.origin == pres[0].origin) {
            self.walk_fan::<N, true>(&walk, pres, tris, best, stack);
        } else {
            self.walk_fan::<N, false>(&walk, pres, tris, best, stack);
        }
        true
    }

    /// The traversal of [`Wide::cast_fan`] for one shared origin (`ONE_ORIGIN`) or an origin
    /// interval.
    #[inline(always)]
    fn walk_fan<const N: usize, const ONE_ORIGIN: bool>(
        &self,
        walk: &FanWalk<N>,
        pres: &[RayPre; N],
        tris: &[[Vec3; 3]],
        best: &mut [Option<(u32, f32)>; N],
        stack: &mut Vec<(u32, f32)>,
    ) {
        let FanWalk { fan, rays: soa, near, far } = walk;
        let mut best_t = [0.0f32; N];
        for r in 0..N {
            best_t[r] = best[r].map_or(pres[r].t_max, |s| s.1);
        }
        let mut far_t = best_t.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
        stack.clear();
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            let (t_near, hit) = slab_fan::<W, ONE_ORIGIN>(n, fan, near, far, far_t);
            self.prefetch_leaves(n, hit);
            let (order, m) = nearest_first(&t_near, hit);
            let mut inner = [(0u32, 0.0f32); W];
            let mut q = 0;
            for &(k, t) in &order[..m] {
                if n.count[k] == 0 {
                    inner[q] = (n.child[k], t);
                    q += 1;
                } else {
                    let mut per_ray = slab_rays(n, k, soa, near, far, &best_t);
                    while per_ray != 0 {
                        let r = per_ray.trailing_zeros() as usize;
                        per_ray &= per_ray - 1;
                        self.leaf(tris, &pres[r], n.child[k], n.count[k], &mut best[r], &mut best_t[r]);
                    }
                    far_t = best_t.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
                }
            }
            match next_node(&inner[..q], stack, far_t) {
                Some(c) => node = c,
                None => return,
            }
        }
    }
}

/// A fan of `N` rays set up for [`Wide::cast_fan`]'s traversal: its extent, each ray's slab setup,
/// and the near and far bound of each axis (the same for every ray of the fan).
struct FanWalk<const N: usize> {
    fan: Fan,
    rays: RaysSoa<N>,
    near: [usize; 3],
    far: [usize; 3],
}

/// The rays of a fan, structure-of-arrays: `origin[a][r]` and `inv_dir[a][r]` are axis `a` of
/// ray `r`'s origin and inverse direction (as in its [`RayBox`]).
struct RaysSoa<const N: usize> {
    origin: [[f32; N]; 3],
    inv_dir: [[f32; N]; 3],
}

/// Slab test of child `k` of `n` against every ray of a fan at once (the rays in the lanes): for
/// each ray the operations [`slab`] does for that child, in the same order, so the same decision.
#[inline(always)]
fn slab_rays<const W: usize, const N: usize>(
    n: &Node<W>,
    k: usize,
    rays: &RaysSoa<N>,
    near: &[usize; 3],
    far: &[usize; 3],
    t_max: &[f32; N],
) -> u32 {
    let mut t_near = [0.0f32; N];
    let mut t_far = *t_max;
    for a in 0..3 {
        let (lo, hi) = (n.bounds[near[a]][k], n.bounds[far[a]][k]);
        let (o, i) = (&rays.origin[a], &rays.inv_dir[a]);
        for r in 0..N {
            t_near[r] = t_near[r].max((lo - o[r]) * i[r]);
            t_far[r] = t_far[r].min((hi - o[r]) * i[r]);
        }
    }
    let mut hit = 0u32;
    for r in 0..N {
        hit |= u32::from(t_near[r] <= t_far[r]) << r;
    }
    hit
}

/// The extent of a fan of rays: origins and inverse directions per axis.
struct Fan {
    o_lo: [f32; 3],
    o_hi: [f32; 3],
    i_lo: [f32; 3],
    i_hi: [f32; 3],
}

/// Interval slab test of the `W` children against a fan of rays (one direction sign per axis):
/// the smallest possible entry distance and whether some ray of the fan may meet the child within
/// `[0, t_max]`. `ONE_ORIGIN`: all rays start at `o_lo` (two products per plane instead of four).
#[inline(always)]
fn slab_fan<const W: usize, const ONE_ORIGIN: bool>(
    n: &Node<W>,
    fan: &Fan,
    near: &[usize; 3],
    far: &[usize; 3],
    t_max: f32,
) -> ([f32; W], u32) {
    let mut t_near = [0.0f32; W];
    let mut t_far = [t_max; W];
    for a in 0..3 {
        let lo = &n.bounds[near[a]];
        let hi = &n.bounds[far[a]];
        let (o_lo, o_hi, i_lo, i_hi) = (fan.o_lo[a], fan.o_hi[a], fan.i_lo[a], fan.i_hi[a]);
        if ONE_ORIGIN {
            for k in 0..W {
                let (p, q) = (lo[k] - o_lo, hi[k] - o_lo);
                t_near[k] = t_near[k].max((p * i_lo).min(p * i_hi));
                t_far[k] = t_far[k].min((q * i_lo).max(q * i_hi));
            }
        } else {
            for k in 0..W {
                // (b - o) * i is bilinear in (o, i): its extremes are at the corners.
                let (p0, p1) = (lo[k] - o_hi, lo[k] - o_lo);
                let entry = (p0 * i_lo).min(p0 * i_hi).min((p1 * i_lo).min(p1 * i_hi));
                let (q0, q1) = (hi[k] - o_hi, hi[k] - o_lo);
                let exit = (q0 * i_lo).max(q0 * i_hi).max((q1 * i_lo).max(q1 * i_hi));
                t_near[k] = t_near[k].max(entry);
                t_far[k] = t_far[k].min(exit);
            }
        }
    }
    let mut hit = 0u32;
    for k in 0..W {
        hit |= u32::from(t_near[k] <= t_far[k] && n.count[k] != EMPTY) << k;
    }
    (t_near, hit)
}

/// The children a ray meets (`hit`, bit `k` for child `k`), as `(child, entry distance)` nearest first (an insertion sort:
/// equal distances keep the child order), and how many there are.
#[inline(always)]
fn nearest_first<const W: usize>(t_near: &[f32; W], hit: u32) -> ([(usize, f32); W], usize) {
    let mut order = [(0usize, 0.0f32); W];
    let mut m = 0;
    let mut todo = hit;
    while todo != 0 {
        let k = todo.trailing_zeros() as usize;
        todo &= todo - 1;
        {
            let mut i = m;
            while i > 0 && order[i - 1].1 > t_near[k] {
                order[i] = order[i - 1];
                i -= 1;
            }
            order[i] = (k, t_near[k]);
            m += 1;
        }
    }
    (order, m)
}

/// The next node to visit: the nearest of `inner` (children met, nearest first) whose entry distance
/// is within `limit`, pushing the other such children farthest first; else the next node popped off
/// `stack` within `limit`; `None` when traversal is done.
#[inline(always)]
fn next_node(inner: &[(u32, f32)], stack: &mut Vec<(u32, f32)>, limit: f32) -> Option<u32> {
    let mut next = None;
    for &(c, t) in inner.iter().rev() {
        if t <= limit {
            if let Some(prev) = next {
                stack.push(prev);
            }
            next = Some((c, t));
        }
    }
    if let Some((c, _)) = next {
        return Some(c);
    }
    while let Some((c, t)) = stack.pop() {
        if t <= limit {
            return Some(c);
        }
    }
    None
}
