//! Conditional Euclidean clustering of ground candidates on the grid, and the cluster rules of
//! Nitsch et al. Sec. III-B that decide which clusters are ground.
//!
//! Clustering (decision): PCL's conditional Euclidean clustering joins two points when they are
//! within a radius and a condition holds. Here the radius search uses the grid's own adjacency
//! (the 8-neighbourhood of [`crate::nitsch::neighbours`]) instead of a k-d tree: two candidates join when
//! they are grid neighbours and their distance is at most `link_tolerance_m + link_tolerance_rel *
//! max(|p_a|, |p_b|)` (distances from the vehicle origin). The range-proportional part defaults to
//! 0 (a fixed 0.5 m radius, as PCL uses): the tangent-plane link below already joins far rings,
//! and a radius growing with range joined low objects to the ground (`city`, `lux-roof-4`, 2
//! frames: FPR 0.0095 with 0.05 per metre, 0.0060 with 0). The condition is that both are
//! candidates (`g_rho >= threshold`). On a surface sampled by the grid, every pair of candidates
//! within the radius is connected through a chain of grid neighbours, so the partition equals the
//! k-d tree's (tested against a brute-force radius clustering); the two differ only across gaps of
//! empty cells wider than the neighbour search, where the grid version does not join.
//!
//! Far from the sensor, rings on the ground lie metres apart (spacing grows with the square of
//! the range), more than any radius that still separates a car roof from the ground behind it.
//! So grid neighbours also join when each lies within `max_plane_offset_m` of the other's tangent
//! plane (`|n_a . (p_b - p_a)|` and `|n_b . (p_a - p_b)|`): far rings of one flat surface join,
//! a roof 1.5 m above the ground behind it does not, however far apart they are. This link exists
//! only between grid neighbours (0 switches it off, which gives the pure radius clustering). The
//! default offset is 0.15 m, the paper's 15 cm ground tolerance (0.25 m joined low vegetation to
//! the terrain: `rural`, `lux-roof-4`, 5 frames, FPR 0.109 -> 0.071 with 0.15 m).
//!
//! Links that grow with range were measured and rejected (`rural` and `city`, `lux-roof-4`, 5
//! frames, after the row-skipping neighbours and the lateral occlusion test): a radius growing by
//! 0.01 or 0.02 m per metre of range (`link_tolerance_rel`) gave `rural` accuracy 0.934 / 0.934
//! against 0.933 but FPR 0.051 / 0.055 against 0.047, and `city` FPR 0.003 / 0.004 against 0.002;
//! a tangent-plane offset growing with the link length (`max(0.15 m, |d| sin a)` with a = 1, 2, 3
//! degrees) gave `rural` accuracy 0.925, 0.905, 0.894 with FPR 0.11 to 0.17: far rings of the field
//! lie as far from each other as from the bushes on it, so a looser link joins the bushes to the
//! terrain. Far terrain is recovered by the extent rule (rule 4) instead.
//!
//! Rules (Sec. III-B), in order:
//! 1. clusters with fewer than `min_cluster_points` points are noise: not ground;
//! 2. the largest cluster is ground;
//! 3. a cluster inside the ground cluster's area is not ground (a car roof) when it lies more than
//!    `max_step_m` above the ground cluster there; one at the ground's height is ground (a patch cut
//!    off by an occluder or a kerb). The area is the set of `area_cell_m` squares in the x-y plane
//!    that hold ground-cluster points; a point is inside when one of the 3 x 3 squares around it
//!    does, and a cluster is inside when at least a tenth of its points (and `min_cluster_points`)
//!    are: a car roof cluster that reaches past the ground's edge into the occluded area behind the
//!    car is still judged by its height where it overlaps the ground (measured on `city`);
//! 4. a cluster outside the area is ground when it is large (at least `min_large_points` points, or
//!    `min_large_fraction` of the plane's returns if that is more: terrain beyond a basin, another
//!    floor), or when it spreads over at least `min_large_extent_m` (the diagonal of its x-y
//!    bounding box) and lies no higher than `max_step_m` above the ground cluster's mean height:
//!    far away, where rings lie metres apart, a large surface has few points (measured on
//!    `rural`: terrain below the road), while object tops are a few metres across or stand above
//!    the ground (rows of parked cars on `city`) (0 = off);
//! 5. (our addition, measured on `rural`) a smaller cluster outside the area is also ground when it
//!    lies no higher than `max_step_m` above the nearest square of the ground area within
//!    `near_search_m` (its outside points' mean height against that square's mean): a flat
//!    surface level with or below the ground next to it is ground (fields below the street, the
//!    lowered surfaces of Fig. 1), while flat object tops (car roofs, bushes) lie above it.
//!    Off by default (`near_search_m = 0`): on `rural` with `lux-roof-4` it also accepted low
//!    vegetation next to the road (FPR 0.06 -> 0.15 over 5 frames), so it stays an option;
//! 6. every other cluster is not ground (very small clusters are noise).

// Parallel per-cell arrays are indexed by cell on purpose (structure of arrays).
#![allow(clippy::needless_range_loop)]

use glam::Vec3;

use crate::error::{ClassifyError, Result};
use crate::nitsch::neighbours::GridView;
use crate::nitsch::return_bits::{self, ReturnBits};

/// Parameters of clustering and of the cluster rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterParams {
    /// Fixed part of the link radius, metres.
    pub link_tolerance_m: f32,
    /// Range-proportional part of the link radius (per metre of range).
    pub link_tolerance_rel: f32,
    /// Largest offset of a grid neighbour from a candidate's tangent plane for a link, metres (0 = off).
    pub max_plane_offset_m: f32,
    /// Clusters smaller than this are noise.
    pub min_cluster_points: usize,
    /// Clusters outside the ground area with at least this many points are ground. (Measured on
    /// `highway` with `hdl64e-roof`: guard-rail posts cut the terrain below the embankment into
    /// strips of 100-350 points; 100 points / 0.1 % keeps most of them, F1 0.957 -> 0.976, while
    /// on `city` with `lux-roof-4` 50 points let isolated car roofs through.)
    pub min_large_points: usize,
    /// ... or at least this fraction of the returns, whichever is more.
    pub min_large_fraction: f32,
    /// ... or spread over at least this x-y diagonal, metres (0 = off). 6 m by default: more than
    /// the x-y diagonal of any object top that the scene library sets at ground level (a bush crown
    /// at most 3.6 m across: 5.1 m; a car body of 4.5 m x 1.8 m: 4.85 m). Measured on `rural` with
    /// `lux-roof-4`, 5 frames: accuracy 0.933 with 10 m, 0.938 with 7, 6 and 5 m, FPR 0.047 in all;
    /// `city` the same with all four.
    pub min_large_extent_m: f32,
    /// Side of the squares of the ground area, metres.
    pub area_cell_m: f32,
    /// Height above the local ground cluster beyond which an inside cluster is an object, metres.
    pub max_step_m: f32,
    /// How far from a small outside cluster to look for the ground area (rule 5), metres (0 = off).
    pub near_search_m: f32,
}

impl Default for ClusterParams {
    fn default() -> Self {
        Self {
            link_tolerance_m: 0.5,
            link_tolerance_rel: 0.0,
            max_plane_offset_m: 0.15,
            min_cluster_points: 5,
            min_large_points: 100,
            min_large_fraction: 0.001,
            min_large_extent_m: 6.0,
            area_cell_m: 2.0,
            max_step_m: 0.5,
            near_search_m: 0.0,
        }
    }
}

impl ClusterParams {
    /// Refuses values outside their ranges.
    pub fn validate(&self) -> Result<()> {
        let pos = |v: f32| v.is_finite() && v > 0.0;
        if !pos(self.link_tolerance_m) {
            return Err(ClassifyError::invalid("link_tolerance_m", self.link_tolerance_m, "finite, > 0"));
        }
        if !(self.link_tolerance_rel.is_finite() && self.link_tolerance_rel >= 0.0) {
            return Err(ClassifyError::invalid("link_tolerance_rel", self.link_tolerance_rel, "finite, >= 0"));
        }
        if !(self.max_plane_offset_m.is_finite() && self.max_plane_offset_m >= 0.0) {
            return Err(ClassifyError::invalid("max_plane_offset_m", self.max_plane_offset_m, "finite, >= 0"));
        }
        if !(self.min_large_fraction.is_finite() && (0.0..=1.0).contains(&self.min_large_fraction)) {
            return Err(ClassifyError::invalid("min_large_fraction", self.min_large_fraction, "0 ..= 1"));
        }
        if !(self.min_large_extent_m.is_finite() && self.min_large_extent_m >= 0.0) {
            return Err(ClassifyError::invalid("min_large_extent_m", self.min_large_extent_m, "finite, >= 0"));
        }
        if !pos(self.area_cell_m) {
            return Err(ClassifyError::invalid("area_cell_m", self.area_cell_m, "finite, > 0"));
        }
        if !(self.near_search_m.is_finite() && (0.0..=1000.0).contains(&self.near_search_m)) {
            return Err(ClassifyError::invalid("near_search_m", self.near_search_m, "0 ..= 1000"));
        }
        if !(self.max_step_m.is_finite() && self.max_step_m >= 0.0) {
            return Err(ClassifyError::invalid("max_step_m", self.max_step_m, "finite, >= 0"));
        }
        Ok(())
    }
}

/// Reusable buffers of the clustering (no allocation per frame once warm).
#[derive(Clone, Debug, Default)]
pub struct ClusterWorkspace {
    /// Union-find parent per cell (`u32::MAX` for non-candidates).
    parent: Vec<u32>,
    /// Cluster size per root.
    size: Vec<u32>,
    /// Per-cluster accumulators of the area test, indexed by root.
    inside: Vec<u32>,
    height_sum: Vec<f32>,
    /// Sum of the points outside the ground area, per root.
    outside_sum: Vec<Vec3>,
    /// x-y bounding box per root.
    bbox: Vec<(glam::Vec2, glam::Vec2)>,
    /// Candidate cells (cells with a cluster) in increasing order.
    members: Vec<u32>,
    /// Ground-area squares: (sum z, count) per square in a bounding box.
    area: Vec<(f32, u32)>,
    /// Per area square, with a border of one square around the area: the mean height of the
    /// ground-area points in the 3 x 3 squares around it and their count (`NOT_YET` until needed).
    near: Vec<(f32, u32)>,
    /// Decision per root.
    root_ground: Vec<bool>,
    /// Whether each cell holds a return.
    valid: Vec<bool>,
    /// Per column of the row being clustered: returns in the rows below, at and above.
    column_valid: Vec<bool>,
    /// `valid` as bits, for the neighbour search of cells that lack a direct neighbour.
    bits: ReturnBits,
    /// Cluster roots in increasing order (the per-root arrays are only read and reset there).
    roots: Vec<u32>,
    /// Returns of the plane of the last clustering.
    returns: usize,
}

const NONE: u32 = u32::MAX;

/// 8 flags as the bytes of a word (flag `k` in byte `k`, 0 or 1).
#[inline(always)]
fn bytes8(flags: &[bool]) -> u64 {
    flags[..8].iter().enumerate().fold(0, |w, (k, &f)| w | (u64::from(f) << (8 * k)))
}

/// The bytes (each 0 or 1) of `w` as the 8 low bits: byte `k` to bit `k`. The multiplication
/// moves byte `k` to bit `56 + k` (each byte meets one power of two there, the other products
/// fall below bit 56 or past bit 63, on distinct bits: no carries).
#[inline(always)]
fn pack8(w: u64) -> u64 {
    w.wrapping_mul(0x0102_0408_1020_4080) >> 56
}

/// A count of [`ClusterWorkspace`]'s `near` squares not computed yet.
const NOT_YET: u32 = u32::MAX;

/// The mean height of the ground-area points in the 3 x 3 squares around square `(x, y)` of the
/// `nx` x `ny` area (sums of height and count per square), and their count (mean 0 without any).
#[inline]
fn near_mean(area: &[(f32, u32)], nx: usize, ny: usize, x: isize, y: isize) -> (f32, u32) {
    let (mut zs, mut cnt) = (0.0f32, 0u32);
    for dy in -1..=1 {
        for dx in -1..=1 {
            let (xx, yy) = (x + dx, y + dy);
            if xx >= 0 && yy >= 0 && (xx as usize) < nx && (yy as usize) < ny {
                let e = area[yy as usize * nx + xx as usize];
                zs += e.0;
                cnt += e.1;
            }
        }
    }
    (if cnt > 0 { zs / cnt as f32 } else { 0.0 }, cnt)
}

/// `v.floor() as isize`, bit for bit (saturating, NaN to 0), without a call to `floorf` (the
/// baseline x86-64 target has no rounding instruction): truncation toward zero, one less where
/// that rounded a negative value up (a subtraction, not a branch: points on either side of the
/// area's corner would mispredict it).
#[inline]
fn floor_isize(v: f32) -> isize {
    let t = v as isize;
    if (t as f32) > v { t.saturating_sub(1) } else { t }
}

#[inline]
fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let g = parent[parent[i as usize] as usize];
        parent[i as usize] = g;
        i = g;
    }
    i
}

/// Whether two candidate grid neighbours at `pa`, `pb` with unit normals `na`, `nb` join (module docs).
#[inline]
pub fn linked(pa: Vec3, pb: Vec3, na: Vec3, nb: Vec3, params: &ClusterParams) -> bool {
    let d = pb - pa;
    // The tangent-plane test first: it needs no square root and joins most ground links.
    let off = params.max_plane_offset_m;
    if off > 0.0 && na.dot(d).abs() <= off && nb.dot(d).abs() <= off {
        return true;
    }
    let tol = params.link_tolerance_m + params.link_tolerance_rel * pa.length_squared().max(pb.length_squared()).sqrt();
    d.length_squared() <= tol * tol
}

/// Clusters the candidate cells (`candidate[i]`, unit normals `normal[i]`) of `view` by conditional
/// Euclidean clustering on the grid. Afterwards [`ClusterWorkspace::cluster_of`] gives each candidate's cluster root and
/// [`ClusterWorkspace::cluster_size`] its size.
///
/// Every cluster's root is its smallest cell index (unions keep the smaller root), so the result
/// does not depend on the order in which links are found. Cells are visited in grid order; a cell
/// whose 8 direct neighbours all hold returns links to the 4 neighbours already visited (`d4`..`d7`:
/// down-right, down, down-left, left). The relation is symmetric (see [`GridView::direct_neighbours`]),
/// so together with the other cells, which link to all their neighbours, this finds every link of
/// the per-cell definition (tested against it).
pub fn cluster_candidates(
    view: &GridView<'_>,
    candidate: &[bool],
    normal: &[Vec3],
    params: &ClusterParams,
    ws: &mut ClusterWorkspace,
) {
    cluster_candidates_with(view, None, candidate, normal, params, ws);
}

/// [`cluster_candidates`] with the cells that hold a return given (`valid`, as
/// [`crate::nitsch::features::Features::valid`] has them) rather than found again from the points.
///
/// Runs as code compiled for AVX2 and BMI where the CPU has them (measured: 5-8 % faster than the
/// baseline x86-64 build); the results are the same, as every float operation is a plain IEEE one
/// (tested against the portable build).
pub fn cluster_candidates_with(
    view: &GridView<'_>,
    valid: Option<&[bool]>,
    candidate: &[bool],
    normal: &[Vec3],
    params: &ClusterParams,
    ws: &mut ClusterWorkspace,
) {
    #[cfg(target_arch = "x86_64")]
    if avx2_bmi() {
        // SAFETY: the CPU supports AVX2, BMI1 and BMI2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return cluster_avx2(view, valid, candidate, normal, params, ws);
        }
    }
    cluster_body(view, valid, candidate, normal, params, ws);
}

/// Whether the CPU runs the code compiled for AVX2, BMI1 and BMI2.
#[cfg(target_arch = "x86_64")]
fn avx2_bmi() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
}

/// [`cluster_body`] compiled for AVX2, BMI1 and BMI2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,bmi1,bmi2")]
fn cluster_avx2(
    view: &GridView<'_>,
    valid: Option<&[bool]>,
    candidate: &[bool],
    normal: &[Vec3],
    params: &ClusterParams,
    ws: &mut ClusterWorkspace,
) {
    cluster_body(view, valid, candidate, normal, params, ws);
}

/// The body of [`cluster_candidates_with`], inlined into each instruction-set variant.
#[inline(always)]
fn cluster_body(
    view: &GridView<'_>,
    valid: Option<&[bool]>,
    candidate: &[bool],
    normal: &[Vec3],
    params: &ClusterParams,
    ws: &mut ClusterWorkspace,
) {
    let (rows, cols) = (view.rows, view.cols);
    let n = rows * cols;
    let points = &view.points[..n];
    let normal = &normal[..n];
    // Sizes are non-zero only at the last clustering's roots: reset those (no pass over all cells).
    if ws.size.len() == n {
        for &root in &ws.roots {
            ws.size[root as usize] = 0;
        }
    } else {
        ws.size.clear();
        ws.size.resize(n, 0);
    }
    ws.valid.resize(n, false);
    match valid {
        Some(valid) => ws.valid.copy_from_slice(&valid[..n]),
        None => {
            for (v, p) in ws.valid.iter_mut().zip(points) {
                // `is_valid` without short-circuit branches, so that it vectorizes.
                *v = p.x.is_finite() & p.y.is_finite() & p.z.is_finite();
            }
        }
    }
    ws.returns = ws.valid.iter().map(|&v| usize::from(v)).sum();
    ws.bits.pack(&ws.valid[..n], rows, cols);
    // Only cells with a return can be candidates: the members, each its own root to begin with.
    ws.parent.clear();
    ws.parent.resize(n, NONE);
    // The member list (in increasing order): the passes below visit only the members. Per 64
    // cells a bit mask (8 cells per multiplication, [`pack8`]), whose set bits are then listed:
    // a step per member, none per cell.
    ws.members.clear();
    for (k, (cand, valid)) in candidate[..n].chunks(64).zip(ws.valid[..n].chunks(64)).enumerate() {
        let mut mask = 0u64;
        if cand.len() == 64 {
            for (b, (c, v)) in cand.chunks_exact(8).zip(valid.chunks_exact(8)).enumerate() {
                mask |= pack8(bytes8(c) & bytes8(v)) << (8 * b);
            }
        } else {
            for (b, (&c, &v)) in cand.iter().zip(valid).enumerate() {
                mask |= u64::from(c & v) << b;
            }
        }
        while mask != 0 {
            let i = (k * 64) as u32 + mask.trailing_zeros();
            ws.members.push(i);
            ws.parent[i as usize] = i;
            mask &= mask - 1;
        }
    }
    // Per column of the current row: returns in the rows below, at and above.
    ws.column_valid.clear();
    ws.column_valid.resize(cols, false);
    let parent = &mut ws.parent;
    // Index of the next member to visit.
    let mut next = 0;
    for r in 0..rows {
        let row = r * cols..(r + 1) * cols;
        let interior_row = r > 0 && r + 1 < rows;
        if interior_row {
            let (below, at, above) = (&ws.valid[row.start - cols..], &ws.valid[row.clone()], &ws.valid[row.end..]);
            for (c, v) in ws.column_valid.iter_mut().enumerate() {
                *v = below[c] & at[c] & above[c];
            }
        }
        // The previous member and its cluster's root.
        let (mut prev, mut prev_root) = (usize::MAX, NONE);
        while next < ws.members.len() && (ws.members[next] as usize) < row.end {
            let i = ws.members[next] as usize;
            next += 1;
            let c = i - row.start;
            // The left neighbour's root when it is a member (NONE otherwise).
            let left_root = if prev.wrapping_add(1) == i { prev_root } else { NONE };
            let (p, np) = (points[i], normal[i]);
            let dense = interior_row
                && c > 0
                && c + 1 < cols
                && ws.column_valid[c - 1] & ws.column_valid[c] & ws.column_valid[c + 1];
            // Root of this cell's cluster, kept up to date through the unions below.
            let mut ri = if parent[i] == i as u32 { i as u32 } else { find(parent, i as u32) };
            // A link only matters between different clusters, so the roots are compared before
            // the (pure) link test: the partition is the same, with far fewer tests.
            let join = |parent: &mut [u32], j: usize, rj: u32, ri: &mut u32| {
                if rj != *ri && j != i && linked(p, points[j], np, normal[j], params) {
                    // Union by index: every root is its cluster's smallest cell.
                    let (lo, hi) = if *ri < rj { (*ri, rj) } else { (rj, *ri) };
                    parent[hi as usize] = lo;
                    *ri = lo;
                }
            };
            if dense {
                if left_root != NONE {
                    join(parent, i - 1, left_root, &mut ri);
                }
                for j in [i - cols - 1, i - cols, i - cols + 1] {
                    // A parent equal to this cell's root (a root) means the same cluster already:
                    // no search (the common case inside a surface).
                    let pj = parent[j];
                    if pj != NONE && pj != ri {
                        let rj = find(parent, j as u32);
                        join(parent, j, rj, &mut ri);
                    }
                }
            } else {
                for j in return_bits::neighbours(view, &ws.bits, r, c).into_iter().flatten() {
                    if parent[j] != NONE {
                        // The unions above may have moved this cell's root.
                        ri = find(parent, ri);
                        let rj = find(parent, j as u32);
                        join(parent, j, rj, &mut ri);
                    }
                }
            }
            (prev, prev_root) = (i, ri);
        }
    }
    // Path compression, cluster sizes, the member list and each cluster's x-y bounding box in one
    // pass. A root is its cluster's smallest cell, so it is the first member met: its box starts there.
    ws.roots.clear();
    ws.bbox.resize(n, (glam::Vec2::ZERO, glam::Vec2::ZERO));
    // Consecutive members mostly share a root: its size and box stay in registers for the run
    // (no read-modify-write chain through memory per cell), and are stored when the root changes.
    let (mut run, mut count, mut lo, mut hi) = (NONE, 0u32, glam::Vec2::ZERO, glam::Vec2::ZERO);
    for &i in &ws.members {
        let i = i as usize;
        let p = parent[i];
        // Parents come before their children, so going up the cells the parent's own parent
        // is usually the root already.
        let pp = parent[p as usize];
        let root = if parent[pp as usize] == pp { pp } else { find(parent, i as u32) };
        parent[i] = root;
        let xy = points[i].truncate();
        if root != run {
            if run != NONE {
                (ws.size[run as usize], ws.bbox[run as usize]) = (count, (lo, hi));
            }
            run = root;
            if root == i as u32 {
                ws.roots.push(root);
                (count, lo, hi) = (0, xy, xy);
            } else {
                (count, (lo, hi)) = (ws.size[root as usize], ws.bbox[root as usize]);
            }
        }
        count += 1;
        (lo, hi) = (lo.min(xy), hi.max(xy));
    }
    if run != NONE {
        (ws.size[run as usize], ws.bbox[run as usize]) = (count, (lo, hi));
    }
}

impl ClusterWorkspace {
    /// Cluster root of cell `i` after [`cluster_candidates`], `None` for non-candidates.
    pub fn cluster_of(&self, i: usize) -> Option<usize> {
        let mut r = self.parent[i];
        if r == NONE {
            return None;
        }
        while self.parent[r as usize] != r {
            r = self.parent[r as usize];
        }
        Some(r as usize)
    }

    /// Number of returns (cells with a point) of the plane of the last [`cluster_candidates`].
    pub fn returns(&self) -> usize {
        self.returns
    }

    /// Number of points in the cluster with root `root`.
    pub fn cluster_size(&self, root: usize) -> usize {
        self.size[root] as usize
    }

    /// After [`ClusterWorkspace::decide`]: `(size, points inside the ground area, their mean height
    /// above the local ground, decision)` of the cluster with root `root` (diagnostics).
    pub fn cluster_summary(&self, root: usize) -> (usize, usize, f32, bool) {
        let inside = self.inside.get(root).copied().unwrap_or(0) as usize;
        let h = if inside > 0 { self.height_sum[root] / inside as f32 } else { f32::NAN };
        (self.size[root] as usize, inside, h, self.root_ground.get(root).copied().unwrap_or(false))
    }

    /// Number of clusters.
    pub fn cluster_count(&self) -> usize {
        self.size.iter().filter(|&&s| s > 0).count()
    }

    /// Applies the cluster rules (module docs) and writes the ground decision of every cell of the
    /// plane into `ground` (non-candidates false). `points` are the points of the last
    /// [`cluster_candidates`] (whose pass also found each cluster's bounding box) and `returns` the
    /// number of returns of the plane. (Compiled for AVX2 and BMI where the CPU has them, as
    /// [`cluster_candidates_with`].)
    pub fn decide(&mut self, points: &[Vec3], returns: usize, params: &ClusterParams, ground: &mut [bool]) {
        #[cfg(target_arch = "x86_64")]
        if avx2_bmi() {
            // SAFETY: the CPU supports AVX2, BMI1 and BMI2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.decide_avx2(points, returns, params, ground);
            }
        }
        self.decide_body(points, returns, params, ground);
    }

    /// [`ClusterWorkspace::decide_body`] compiled for AVX2, BMI1 and BMI2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2")]
    fn decide_avx2(&mut self, points: &[Vec3], returns: usize, params: &ClusterParams, ground: &mut [bool]) {
        self.decide_body(points, returns, params, ground);
    }

    /// The body of [`ClusterWorkspace::decide`], inlined into each instruction-set variant.
    #[inline(always)]
    fn decide_body(&mut self, points: &[Vec3], returns: usize, params: &ClusterParams, ground: &mut [bool]) {
        let n = self.parent.len();
        // Every candidate's parent is its root already ([`cluster_candidates`] compresses the paths).
        let size = &self.size;
        let Some(largest) = self.roots.iter().map(|&r| r as usize).max_by_key(|&r| (size[r], std::cmp::Reverse(r)))
        else {
            ground[..n].fill(false);
            return;
        };
        // Ground area: squares holding points of the largest cluster, over its bounding box.
        let cell = params.area_cell_m;
        let (lo, hi) = self.bbox[largest];
        let nx = (((hi.x - lo.x) / cell).floor() as usize).saturating_add(1).min(4096);
        let ny = (((hi.y - lo.y) / cell).floor() as usize).saturating_add(1).min(4096);
        self.area.clear();
        self.area.resize(nx * ny, (0.0, 0));
        // A multiplication rather than a division per coordinate (exactly the quotient for the
        // default 2 m squares, and for any power of two).
        let per_cell = 1.0 / cell;
        let square = |p: Vec3| -> (isize, isize) {
            (floor_isize((p.x - lo.x) * per_cell), floor_isize((p.y - lo.y) * per_cell))
        };
        // Consecutive points mostly fall in one square: its sums stay in registers for the run
        // (the same additions in the same order, without a chain through memory per point).
        let (parent, area) = (&self.parent[..], &mut self.area[..]);
        let (mut run, mut acc) = (usize::MAX, (0f32, 0u32));
        for &i in &self.members {
            if parent[i as usize] == largest as u32 {
                let p = points[i as usize];
                // The largest cluster's points lie inside its box: `p - lo >= 0`, whose truncation
                // is its floor (one conversion, no correction; `nx`, `ny` <= 4096).
                let x = (((p.x - lo.x) * per_cell) as i32).clamp(0, nx as i32 - 1) as usize;
                let y = (((p.y - lo.y) * per_cell) as i32).clamp(0, ny as i32 - 1) as usize;
                let k = y * nx + x;
                if k != run {
                    if run != usize::MAX {
                        area[run] = acc;
                    }
                    (run, acc) = (k, area[k]);
                }
                acc = (acc.0 + p.z, acc.1 + 1);
            }
        }
        if run != usize::MAX {
            area[run] = acc;
        }
        // Area test per cluster: count inside points and their height above the local ground.
        // Per-root arrays: sized once, reset at the roots only (they are read nowhere else).
        self.inside.resize(n, 0);
        self.height_sum.resize(n, 0.0);
        self.outside_sum.resize(n, Vec3::ZERO);
        self.root_ground.resize(n, false);
        for &root in &self.roots {
            let r = root as usize;
            (self.inside[r], self.height_sum[r], self.outside_sum[r]) = (0, 0.0, Vec3::ZERO);
            self.root_ground[r] = false;
        }
        // The 3 x 3 sums around a square are found once per square, when a point first needs
        // them (most points of a cluster share squares), not once per point.
        let wx = nx + 2;
        self.near.clear();
        self.near.resize(wx * (ny + 2), (0.0, NOT_YET));
        // Consecutive members mostly share a root: its sums stay in registers for the run.
        // A cluster whose box lies beyond the area's border has all its points outside: those
        // only add up (most of the terrain beside a road on `rural`).
        let beyond = |(lo, hi): (glam::Vec2, glam::Vec2)| {
            let ((x0, y0), (x1, y1)) = (square(lo.extend(0.0)), square(hi.extend(0.0)));
            x1 < -1 || y1 < -1 || x0 > nx as isize || y0 > ny as isize
        };
        let (mut run, mut far, mut inside, mut height, mut outside) = (NONE, false, 0u32, 0f32, Vec3::ZERO);
        for &i in &self.members {
            let root = self.parent[i as usize];
            if root == largest as u32 || (self.size[root as usize] as usize) < params.min_cluster_points {
                continue;
            }
            if root != run {
                if run != NONE {
                    let r = run as usize;
                    (self.inside[r], self.height_sum[r], self.outside_sum[r]) = (inside, height, outside);
                }
                run = root;
                let r = root as usize;
                (inside, height, outside) = (self.inside[r], self.height_sum[r], self.outside_sum[r]);
                far = beyond(self.bbox[r]);
            }
            let p = points[i as usize];
            if far {
                outside += p;
                continue;
            }
            let (x, y) = square(p);
            // Squares beyond the border have no area square around them.
            let (mean, cnt) = if (-1..=nx as isize).contains(&x) && (-1..=ny as isize).contains(&y) {
                let k = (y + 1) as usize * wx + (x + 1) as usize;
                if self.near[k].1 == NOT_YET {
                    self.near[k] = near_mean(&self.area, nx, ny, x, y);
                }
                self.near[k]
            } else {
                (0.0, 0)
            };
            if cnt > 0 {
                inside += 1;
                height += p.z - mean;
            } else {
                outside += p;
            }
        }
        if run != NONE {
            let r = run as usize;
            (self.inside[r], self.height_sum[r], self.outside_sum[r]) = (inside, height, outside);
        }
        let (zsum, zcount) = self.area.iter().fold((0f64, 0u64), |(a, b), e| (a + f64::from(e.0), b + u64::from(e.1)));
        let ground_mean_z = (zsum / zcount.max(1) as f64) as f32;
        let min_large = params.min_large_points.max((params.min_large_fraction * returns as f32).ceil() as usize);
        for ri in 0..self.roots.len() {
            let root = self.roots[ri] as usize;
            let size = self.size[root] as usize;
            self.root_ground[root] = if root == largest {
                true
            } else if size < params.min_cluster_points {
                false
            } else if 10 * self.inside[root] as usize >= size && self.inside[root] as usize >= params.min_cluster_points
            {
                self.height_sum[root] / (self.inside[root] as f32) <= params.max_step_m
            } else if size >= min_large
                || (params.min_large_extent_m > 0.0
                    && (self.bbox[root].1 - self.bbox[root].0).length() >= params.min_large_extent_m
                    && self.outside_sum[root].z / (size - self.inside[root] as usize).max(1) as f32
                        <= ground_mean_z + params.max_step_m)
            {
                true
            } else {
                // Rule 5: level with or below the nearest ground-area square.
                let outside = size - self.inside[root] as usize;
                let c = self.outside_sum[root] / outside.max(1) as f32;
                let (cx, cy) = square(c);
                let reach = (params.near_search_m / cell).ceil() as isize;
                let mut best: Option<(isize, f32)> = None;
                for y in (cy - reach).max(0)..=(cy + reach).min(ny as isize - 1) {
                    for x in (cx - reach).max(0)..=(cx + reach).min(nx as isize - 1) {
                        let e = self.area[y as usize * nx + x as usize];
                        let d2 = (x - cx).pow(2) + (y - cy).pow(2);
                        if e.1 > 0 && d2 <= reach * reach && best.is_none_or(|(bd, _)| d2 < bd) {
                            best = Some((d2, e.0 / e.1 as f32));
                        }
                    }
                }
                best.is_some_and(|(_, z)| c.z - z <= params.max_step_m)
            };
        }
        // Members are the cells with a return and a cluster; every other cell is not ground.
        ground[..n].fill(false);
        for &i in &self.members {
            ground[i as usize] = self.root_ground[self.parent[i as usize] as usize];
        }
    }
}

#[cfg(test)]
mod tests {
    //! The grid-order clustering against the per-cell definition it replaced (kept here as the
    //! reference: every candidate links to its 4 forward direct neighbours, or to all neighbours
    //! the search finds where a direct one is missing), on damaged synthetic frames.

    use super::*;
    use crate::{Nitsch, NitschParams};
    use rand::{RngExt, SeedableRng};

    /// The clustering of the per-cell definition; the cluster root of every cell.
    fn reference(
        view: &GridView<'_>,
        candidate: &[bool],
        normal: &[Vec3],
        params: &ClusterParams,
        ws: &mut ClusterWorkspace,
    ) -> Vec<Option<usize>> {
        let n = view.rows * view.cols;
        ws.parent.clear();
        ws.parent.extend((0..n as u32).map(|i| if candidate[i as usize] { i } else { NONE }));
        ws.size.clear();
        ws.size.resize(n, 0);
        for r in 0..view.rows {
            for c in 0..view.cols {
                let i = r * view.cols + c;
                if ws.parent[i] == NONE {
                    continue;
                }
                let p = view.points[i];
                // Interior cells with all direct neighbours: the relation is symmetric, so the four
                // forward neighbours (d1, d2, d3 and d8: up, up-right, right, up-left) cover every link.
                // Elsewhere all found neighbours are linked (unions are idempotent).
                let nbs = match view.direct_neighbours(r, c) {
                    Some(d) => [Some(d[0]), Some(d[1]), Some(d[2]), Some(d[7]), None, None, None, None],
                    None => view.neighbours(r, c),
                };
                for j in nbs.into_iter().flatten() {
                    if ws.parent[j] == NONE || j == i {
                        continue;
                    }
                    if linked(p, view.points[j], normal[i], normal[j], params) {
                        let (ri, rj) = (find(&mut ws.parent, i as u32), find(&mut ws.parent, j as u32));
                        if ri != rj {
                            // Union by index keeps the result independent of visiting order details.
                            let (lo, hi) = if ri < rj { (ri, rj) } else { (rj, ri) };
                            ws.parent[hi as usize] = lo;
                        }
                    }
                }
            }
        }
        for i in 0..n {
            if ws.parent[i] != NONE {
                let root = find(&mut ws.parent, i as u32);
                ws.size[root as usize] += 1;
            }
        }
        (0..n).map(|i| ws.cluster_of(i)).collect()
    }

    fn frame(drop: f32, seed: u64, spinning: bool) -> sim::OrderedCloud {
        crate::synthetic::noisy_cars_frame(drop, seed, spinning, 0.05)
    }

    #[test]
    fn pack8_moves_byte_k_to_bit_k() {
        for bits in 0..=255u64 {
            let flags: Vec<bool> = (0..8).map(|k| bits >> k & 1 == 1).collect();
            assert_eq!(pack8(bytes8(&flags)), bits);
        }
    }

    #[test]
    fn floor_isize_equals_floor() {
        let mut values = vec![0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.999, -2.999, 1e7, -1e7, 16_777_217.0, -8_388_609.5];
        values.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, f32::MIN, 9.3e18, -9.3e18, -9.2e18]);
        values.extend([f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1e-30, -1e-30]);
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
        values.extend((0..10_000).map(|_| (rng.random::<f32>() - 0.5) * 2000.0));
        for v in values {
            assert_eq!(floor_isize(v), v.floor() as isize, "{v}");
        }
    }

    #[test]
    fn grid_order_clustering_equals_the_per_cell_definition() {
        let mut clusters_seen = 0;
        for (drop, seed, spinning) in [(0.0, 1, true), (0.1, 2, true), (0.4, 3, true), (0.2, 4, false)] {
            let cloud = frame(drop, seed, spinning);
            let mut variants = vec![NitschParams::default()];
            let mut p = NitschParams::default();
            p.clustering.max_plane_offset_m = 0.0;
            p.clustering.link_tolerance_m = 0.3;
            p.clustering.link_tolerance_rel = 0.02;
            p.neighbours.max_col_gap = 4;
            variants.push(p);
            let mut p = NitschParams::default();
            p.neighbours.max_col_gap = 1;
            p.threshold = 0.3;
            variants.push(p);
            for params in variants {
                let mut nitsch = Nitsch::new(params).expect("valid parameters");
                nitsch.classify(&cloud).expect("classifies");
                let view = nitsch.view(&cloud);
                let mut candidate: Vec<bool> =
                    nitsch.features.g_rho.iter().map(|&g| g >= params.threshold && g > 0.0).collect();
                if params.threshold < 0.5 {
                    // A random half of the candidates: every kind of link then decides clusters.
                    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed + 100);
                    for c in candidate.iter_mut() {
                        *c &= rng.random::<f32>() < 0.5;
                    }
                }
                let mut ws = ClusterWorkspace::default();
                let want = reference(&view, &candidate, &nitsch.features.normal, &params.clustering, &mut ws);
                let mut fast = ClusterWorkspace::default();
                cluster_candidates(&view, &candidate, &nitsch.features.normal, &params.clustering, &mut fast);
                for (i, &root) in want.iter().enumerate() {
                    assert_eq!(fast.cluster_of(i), root, "cell {i}, drop {drop}, {params:?}");
                    if let Some(root) = root {
                        assert_eq!(fast.cluster_size(root), ws.cluster_size(root));
                    }
                }
                assert_eq!(fast.cluster_count(), ws.cluster_count());
                clusters_seen += ws.cluster_count();
                // The portable variant too (the dispatcher above may have picked AVX2), and the
                // rules of both.
                let mut portable = ClusterWorkspace::default();
                cluster_body(&view, None, &candidate, &nitsch.features.normal, &params.clustering, &mut portable);
                assert_eq!(portable.parent, fast.parent);
                let (mut ground, mut ground_portable) = (vec![false; cloud.len()], vec![false; cloud.len()]);
                fast.decide(view.points, fast.returns(), &params.clustering, &mut ground);
                portable.decide_body(view.points, portable.returns(), &params.clustering, &mut ground_portable);
                assert_eq!(ground, ground_portable);
            }
        }
        // Damaged frames split into many clusters: the comparison is not between two single blobs.
        assert!(clusters_seen > 100, "{clusters_seen}");
    }
}
