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
use crate::nitsch::row_returns::RowReturns;
use box_xy::BoxXy;

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
    /// The members outside the largest cluster, in increasing order (the cluster rules').
    others: Vec<u32>,
    /// Ground-area squares: (sum z, count) per square in a bounding box.
    area: Vec<(f32, u32)>,
    /// Per area square, with a border of one square around the area: the mean height of the
    /// ground-area points in the 3 x 3 squares around it and their count (`NOT_YET` until needed).
    near: Vec<(f32, u32)>,
    /// Decision per root.
    root_ground: Vec<bool>,
    /// Whether each cell holds a return, where the caller does not give the flags.
    valid: Vec<bool>,
    /// Per column of the row being clustered: returns in the rows below, at and above.
    column_valid: Vec<bool>,
    /// Per column of the row being clustered: the column and the columns either side of it are
    /// `column_valid`, so a cell there has all its direct neighbours (false in the first and last
    /// columns).
    dense: Vec<bool>,
    /// The tables of the neighbour search of cells that lack a direct neighbour.
    search: RowReturns,
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
/// whose direct neighbours all hold returns (8 of them; 5 on the first and last rows, which have no
/// row below or above) links to the neighbours already visited (`d4`..`d7`: down-right, down,
/// down-left, left; on the first row only left). The relation is symmetric (see [`GridView::direct_neighbours`]),
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
/// Runs as code compiled for AVX-512 or AVX2 and BMI where the CPU has them (measured: AVX2 5-8 %
/// faster than the baseline x86-64 build, AVX-512 a further 3-5 % on an AVX-512 Xeon); the results are the same, as every float operation is a plain IEEE one
/// (tested against the portable build).
pub fn cluster_candidates_with(
    view: &GridView<'_>,
    valid: Option<&[bool]>,
    candidate: &[bool],
    normal: &[Vec3],
    params: &ClusterParams,
    ws: &mut ClusterWorkspace,
) {
    cluster_dispatch(Inputs { view, valid, search: None, candidate, normal }, params, ws);
}

/// [`cluster_candidates_with`] with the neighbour-search tables of `valid` already built (the
/// features' own: same grid, same returns), so that they are not built twice per frame.
pub(crate) fn cluster_candidates_searched(
    view: &GridView<'_>,
    valid: &[bool],
    search: &RowReturns,
    candidate: &[bool],
    normal: &[Vec3],
    params: &ClusterParams,
    ws: &mut ClusterWorkspace,
) {
    cluster_dispatch(Inputs { view, valid: Some(valid), search: Some(search), candidate, normal }, params, ws);
}

/// What the clustering reads: the grid, which cells hold returns (found from the points where
/// `None`), the neighbour-search tables of those returns (built here where `None`), the
/// candidates and their normals.
#[derive(Clone, Copy)]
struct Inputs<'a> {
    view: &'a GridView<'a>,
    valid: Option<&'a [bool]>,
    search: Option<&'a RowReturns>,
    candidate: &'a [bool],
    normal: &'a [Vec3],
}

/// Runs [`cluster_body`] as the AVX2 build where the CPU has it.
fn cluster_dispatch(inputs: Inputs<'_>, params: &ClusterParams, ws: &mut ClusterWorkspace) {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::avx512() {
        // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ, AVX2, BMI1 and BMI2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return cluster_avx512(inputs, params, ws);
        }
    }
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::avx2_bmi() {
        // SAFETY: the CPU supports AVX2, BMI1 and BMI2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return cluster_avx2(inputs, params, ws);
        }
    }
    cluster_body(inputs, params, ws);
}

/// [`cluster_body`] compiled for AVX2, BMI1 and BMI2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,bmi1,bmi2")]
fn cluster_avx2(inputs: Inputs<'_>, params: &ClusterParams, ws: &mut ClusterWorkspace) {
    cluster_body(inputs, params, ws);
}

/// [`cluster_body`] compiled for AVX-512 ([`crate::cpu::avx512`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
fn cluster_avx512(inputs: Inputs<'_>, params: &ClusterParams, ws: &mut ClusterWorkspace) {
    cluster_body(inputs, params, ws);
}

/// The body of [`cluster_candidates_with`], inlined into each instruction-set variant.
#[inline(always)]
fn cluster_body(inputs: Inputs<'_>, params: &ClusterParams, ws: &mut ClusterWorkspace) {
    let Inputs { view, valid, search, candidate, normal } = inputs;
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
    // The caller's flags where it has them (no copy), else found from the points.
    let valid = match valid {
        Some(valid) => &valid[..n],
        None => {
            ws.valid.resize(n, false);
            for (v, p) in ws.valid.iter_mut().zip(points) {
                // `is_valid` without short-circuit branches, so that it vectorizes.
                *v = p.x.is_finite() & p.y.is_finite() & p.z.is_finite();
            }
            &ws.valid[..n]
        }
    };
    ws.returns = valid.iter().map(|&v| usize::from(v)).sum();
    let search = match search {
        Some(search) => search,
        None => {
            ws.search.build(view, valid);
            &ws.search
        }
    };
    // Only cells with a return can be candidates: the members, each its own root to begin with,
    // in one pass that vectorizes (no fill followed by a write per member).
    ws.parent.clear();
    ws.parent
        .extend(candidate[..n].iter().zip(valid).enumerate().map(|(i, (&c, &v))| if c & v { i as u32 } else { NONE }));
    // The member list (in increasing order): the passes below visit only the members. Per 64
    // cells a bit mask (8 cells per multiplication, [`pack8`]), whose set bits are then listed:
    // a step per member, none per cell.
    ws.members.clear();
    for (k, (cand, valid)) in candidate[..n].chunks(64).zip(valid.chunks(64)).enumerate() {
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
            mask &= mask - 1;
        }
    }
    // Per column of the current row: returns in the rows below, at and above.
    ws.column_valid.clear();
    ws.column_valid.resize(cols, false);
    ws.dense.clear();
    ws.dense.resize(cols, false);
    // Slices of the grid's length, so that an index checked against `n` once needs no further
    // bounds checks (the loop below runs about 100 instructions per candidate).
    let parent = &mut ws.parent[..n];
    let column_valid = &mut ws.column_valid[..cols];
    let dense_column = &mut ws.dense[..cols];
    // Index of the next member to visit.
    let mut next = 0;
    for r in 0..rows {
        let row = r * cols..(r + 1) * cols;
        // The first and last rows have no row below or above: their direct neighbours are those
        // of the rows the grid has (the search finds nothing beyond them either).
        let at = &valid[row.clone()];
        let below = if r > 0 { &valid[row.start - cols..row.start] } else { at };
        let above = if r + 1 < rows { &valid[row.end..row.end + cols] } else { at };
        for (((v, &b), &a), &u) in column_valid.iter_mut().zip(below).zip(at).zip(above) {
            *v = b & a & u;
        }
        // Columns 0 and `cols - 1` stay false (their neighbours across the edge are not direct).
        if cols >= 3 {
            let (left, centre, right) = (&column_valid[..cols - 2], &column_valid[1..cols - 1], &column_valid[2..]);
            for (((d, &l), &m), &r) in dense_column[1..cols - 1].iter_mut().zip(left).zip(centre).zip(right) {
                *d = l & m & r;
            }
        }
        // The previous member, its cluster's root, point and normal.
        let (mut prev, mut prev_root, mut prev_p, mut prev_np) = (usize::MAX, NONE, Vec3::ZERO, Vec3::ZERO);
        while next < ws.members.len() && (ws.members[next] as usize) < row.end {
            let i = ws.members[next] as usize;
            if i >= n {
                // Never: members are cells of the plane.
                break;
            }
            next += 1;
            let c = i - row.start;
            // The left neighbour's root when it is a member (NONE otherwise).
            let left_root = if prev.wrapping_add(1) == i { prev_root } else { NONE };
            let (p, np) = (points[i], normal[i]);
            let dense = dense_column[c];
            // Root of this cell's cluster, kept up to date through the unions below.
            let mut ri = if parent[i] == i as u32 { i as u32 } else { find(parent, i as u32) };
            // A link only matters between different clusters, so the roots are compared before
            // the (pure) link test: the partition is the same, with far fewer tests. (The cell
            // itself, a missing neighbour of the search, has this cell's root: never linked.)
            let join = |parent: &mut [u32], q: Vec3, nq: Vec3, rj: u32, ri: &mut u32| {
                if rj != *ri && linked(p, q, np, nq, params) {
                    // Union by index: every root is its cluster's smallest cell.
                    let (lo, hi) = if *ri < rj { (*ri, rj) } else { (rj, *ri) };
                    parent[hi as usize] = lo;
                    *ri = lo;
                }
            };
            if dense {
                if left_root != NONE {
                    // The left neighbour is the previous member: its point and normal are at hand.
                    join(parent, prev_p, prev_np, left_root, &mut ri);
                }
                // The row below (the first row has none).
                if r > 0 {
                    for j in [i - cols - 1, i - cols, i - cols + 1] {
                        // A parent equal to this cell's root (a root) means the same cluster
                        // already: no search (the common case inside a surface).
                        let pj = parent[j];
                        if pj != NONE && pj != ri {
                            let rj = find(parent, j as u32);
                            join(parent, points[j], normal[j], rj, &mut ri);
                        }
                    }
                }
            } else {
                // A missing neighbour is the cell itself, which never links to itself.
                for j in search.neighbours_or(view, r, c, i) {
                    // `ri` stays this cell's root through the unions (`join` moves it to the
                    // union's root), so a parent equal to it means the same cluster, as above.
                    let pj = parent[j];
                    if pj != NONE && pj != ri {
                        let rj = find(parent, j as u32);
                        join(parent, points[j], normal[j], rj, &mut ri);
                    }
                }
            }
            (prev, prev_root, prev_p, prev_np) = (i, ri, p, np);
        }
    }
    // Path compression, cluster sizes, the member list and each cluster's x-y bounding box in one
    // pass. A root is its cluster's smallest cell, so it is the first member met: its box starts there.
    ws.roots.clear();
    ws.bbox.resize(n, (glam::Vec2::ZERO, glam::Vec2::ZERO));
    // Consecutive members mostly share a root: its size and box stay in registers for the run
    // (no read-modify-write chain through memory per cell), and are stored when the root changes.
    let (mut run, mut count, mut bounds) = (NONE, 0u32, BoxXy::new(glam::Vec2::ZERO));
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
                (ws.size[run as usize], ws.bbox[run as usize]) = (count, bounds.corners());
            }
            run = root;
            if root == i as u32 {
                ws.roots.push(root);
                (count, bounds) = (0, BoxXy::new(xy));
            } else {
                (count, bounds) = (ws.size[root as usize], BoxXy::from_corners(ws.bbox[root as usize]));
            }
        }
        count += 1;
        // Two independent `minps` / `maxps` chains ([`box_xy`]).
        bounds.grow(xy);
    }
    if run != NONE {
        (ws.size[run as usize], ws.bbox[run as usize]) = (count, bounds.corners());
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
}

mod box_xy;
mod rules;
#[cfg(test)]
mod tests;
