//! Local features of Nitsch et al. (Sec. III-A) per cell of one echo plane: the inverse-distance
//! weighted surface normal `n` (Eq. 1-2), the normal quality `n_rho` (Eq. 3) and the ground quality
//! `g_rho = n . z * n_rho` (Eq. 4).
//!
//! Decisions where the paper is silent (tested below):
//! - A pair normal `n_i = d_i x d_(i-1)` exists only where both neighbours exist (see
//!   [`crate::nitsch::neighbours`] for what counts as a neighbour) and the cross product is not degenerate.
//! - `n_rho` averages the cosine similarity over the pairs that exist rather than always dividing by
//!   8 (identical when all 8 neighbours exist); otherwise the lowest ring, which always lacks the
//!   three neighbours below it, could never exceed `n_rho = 0.5` and never be ground.
//! - A cell with fewer than `min_valid_pairs` pair normals (isolated returns, a corner of the grid)
//!   gets `n = 0`, `n_rho = 0` and `g_rho = 0`: it is never a ground candidate.
//! - Cells without a return get the same zeros.
//! - The pair normals enter Eq. 2 as the paper writes them, `d_i x d_(i-1)` (not unit vectors).
//!   Unit pair normals were tried (the text's aim is to "rely more on physically closer points")
//!   and rejected: nearly collinear pairs of far neighbours then get a full vote, which lost a
//!   quarter of the far-side terrain in the basin test.
//! - Occlusion (tested): a neighbour whose measured range is less than `1 - ratio` times the
//!   cell's is an occluder in front of it (a car's bumper above ground seen under the car) and is
//!   left out. This is a ratio of ranges, so unlike the fixed distance threshold the paper rejects
//!   it does not depend on the mounting height, the pitch or the range. Only the neighbours in the
//!   row above (`d8`, `d1`, `d2`) are tested by default (`upper_occlusion_ratio` 0.05): on ground
//!   they are farther than the cell, on a wall below the horizon nearer by well under 5 %, so an
//!   upper neighbour nearer than that is an occluder (measured: ground seen under cars on `city`
//!   with `lux-roof-4`). The same test on all neighbours (`occlusion_ratio`, 0 = off, the default)
//!   drops the lower neighbours of far ground, which are naturally nearer by about
//!   `range * beam gap / height`.
//! - Lateral occlusion (tested): the same test on the neighbours in the cell's own row (`d3`, `d7`;
//!   `lateral_occlusion_ratio` 0.1). Along a row the range of a surface changes by about
//!   `column step * tan(incidence)` per column, a few percent even on a wall seen at 85 degrees, so
//!   a same-row neighbour more than 10 % nearer lies in front of the cell across a range jump: the
//!   shoulder in front of a ditch whose near bank is in the beam's shadow, a bush in front of the
//!   field behind it. Measured with `lux-roof-4`, 5 frames: `rural` accuracy 0.925 -> 0.933,
//!   `city` 0.977 -> 0.981 (0.05 gives the same, 0.2 and 0.3 slightly less).

// Lane arrays are indexed by neighbour and lane on purpose (vectorized across cells).
#![allow(clippy::needless_range_loop)]

mod general;
mod lanes;
mod squares;

use glam::Vec3;

use crate::error::{ClassifyError, Result};
use crate::nitsch::neighbours::GridView;
use crate::nitsch::row_returns::RowReturns;
use general::{GeneralQueue, general_block};
use lanes::{Acc, Cells, Lanes, lane_features, rsqrt};

/// Parameters of the feature computation besides the neighbourhood.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeatureParams {
    /// Fewest pair normals a cell needs to get features (>= 1).
    pub min_valid_pairs: usize,
    /// Neighbours farther than this are missing, metres (infinity: the paper's choice).
    pub max_neighbour_distance_m: f32,
    /// A neighbour whose range is below `(1 - occlusion_ratio)` times the cell's range occludes
    /// it and is missing (0 = off).
    pub occlusion_ratio: f32,
    /// The same for the neighbours in the row above (`d8`, `d1`, `d2`), which on any surface the
    /// beam does not graze from below are never nearer than the cell by more than a few percent.
    pub upper_occlusion_ratio: f32,
    /// The same for the neighbours in the cell's own row (`d3`, `d7`), whose range along a surface
    /// changes by only a few percent per column (0 = off).
    pub lateral_occlusion_ratio: f32,
}

impl Default for FeatureParams {
    fn default() -> Self {
        Self {
            min_valid_pairs: 2,
            max_neighbour_distance_m: f32::INFINITY,
            occlusion_ratio: 0.0,
            upper_occlusion_ratio: 0.05,
            lateral_occlusion_ratio: 0.1,
        }
    }
}

impl FeatureParams {
    /// Refuses values outside their ranges.
    pub fn validate(&self) -> Result<()> {
        if !(1..=8).contains(&self.min_valid_pairs) {
            return Err(ClassifyError::invalid("min_valid_pairs", self.min_valid_pairs, "1 ..= 8"));
        }
        if self.max_neighbour_distance_m.is_nan() || self.max_neighbour_distance_m <= 0.0 {
            return Err(ClassifyError::invalid("max_neighbour_distance_m", self.max_neighbour_distance_m, "> 0"));
        }
        if !(self.occlusion_ratio.is_finite() && (0.0..1.0).contains(&self.occlusion_ratio)) {
            return Err(ClassifyError::invalid("occlusion_ratio", self.occlusion_ratio, "0 ..< 1"));
        }
        if !(self.upper_occlusion_ratio.is_finite() && (0.0..1.0).contains(&self.upper_occlusion_ratio)) {
            return Err(ClassifyError::invalid("upper_occlusion_ratio", self.upper_occlusion_ratio, "0 ..< 1"));
        }
        if !(self.lateral_occlusion_ratio.is_finite() && (0.0..1.0).contains(&self.lateral_occlusion_ratio)) {
            return Err(ClassifyError::invalid("lateral_occlusion_ratio", self.lateral_occlusion_ratio, "0 ..< 1"));
        }
        Ok(())
    }
}

/// Per-cell features of one echo plane (row-major, `rows * cols`). Buffers are reused between frames.
#[derive(Clone, Debug, Default)]
pub struct Features {
    /// Unit surface normal `n` (Eq. 2); zero where the cell has no features.
    pub normal: Vec<Vec3>,
    /// Normal quality `n_rho` (Eq. 3), in `[-1, 1]`; 0 where the cell has no features.
    pub n_rho: Vec<f32>,
    /// Ground quality `g_rho` (Eq. 4), in `[-1, 1]`; 0 where the cell has no features.
    pub g_rho: Vec<f32>,
    /// Structure-of-arrays copy of the plane's points (reused between frames).
    soa: Soa,
}

/// The plane's coordinates as separate arrays and a validity flag per cell.
#[derive(Clone, Debug, Default)]
struct Soa {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    valid: Vec<bool>,
    /// Per cell of the rows with a row on either side: 1 where the cell and the cells above and
    /// below it hold returns, else 0 (0 on the first and last rows).
    column3: Vec<u8>,
    /// The tile's two square rows around the row being processed ([`squares::square_row`]), by parity.
    squares: [squares::SquareRow; 2],
    /// Per square row: the last square left of the tile (lane 0 of the tile's first chunk).
    edge: Vec<[f32; squares::SQUARE_FIELDS]>,
    /// Horizontal edge lengths of the row being processed, by column.
    horizontal: Vec<f32>,
    /// The tables of the general neighbour search.
    search: RowReturns,
}

impl Features {
    /// Whether each cell of the last computed plane holds a return (all three coordinates finite).
    pub fn valid(&self) -> &[bool] {
        &self.soa.valid[..self.g_rho.len()]
    }

    /// The neighbour-search tables of the last computed plane's returns (for the clustering).
    pub(crate) fn search(&self) -> &RowReturns {
        &self.soa.search
    }

    /// Resizes the buffers to `n` cells (no reallocation when the size is unchanged).
    fn resize(&mut self, n: usize) {
        self.normal.resize(n, Vec3::ZERO);
        self.n_rho.resize(n, 0.0);
        self.g_rho.resize(n, 0.0);
    }
}

/// Cells processed together: the arithmetic runs lane-wise over `L` consecutive cells of a row,
/// so it vectorizes across cells (16: one AVX-512 register, two AVX2 registers).
const L: usize = 16;

/// Grid offsets `(row, col)` of `d1..d8` (see [`crate::nitsch::neighbours`]).
const OFFSETS: [(isize, isize); 8] = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)];

/// What the per-neighbour test needs besides the points.
#[derive(Clone, Copy)]
struct Tests {
    max_d2: f32,
    max_d: f32,
    keep: [f32; 8],
}

impl Tests {
    /// Whether neighbour `k` with offset `d` and range `range_j` counts for a cell of range `range`.
    // `!(a < b)` rather than `partial_cmp`: it vectorizes, and a NaN range keeps the neighbour.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    #[inline(always)]
    fn keep(&self, k: usize, l2: f32, range_j: f32, range: f32) -> bool {
        // Neighbours nearer than `keep[k] * range` occlude the cell (NaN ranges compare false: kept).
        // `&` rather than `&&`: no branch per lane, so the lanes vectorize.
        (l2 <= self.max_d2) & (l2 > 0.0) & !(range_j < self.keep[k] * range)
    }

    /// [`Tests::keep`] from the neighbour's distance `len` rather than its square.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    #[inline(always)]
    fn keep_len(&self, k: usize, len: f32, range_j: f32, range: f32) -> bool {
        (len <= self.max_d) & (len > 0.0) & !(range_j < self.keep[k] * range)
    }
}

/// Computes the features of every cell of `view` into `out`.
///
/// Cells whose 8 direct neighbours all hold returns (the common case) take their pair normals and
/// neighbour distances from the grid squares around them, `L` cells at a time: each square's 4
/// triangles and 3 edges are computed once and shared by the two cells that use each ([`squares`]).
/// The others use [`GridView::neighbours`] and their own cross products. Either way every cell gets
/// the result of the per-cell definition within 2e-6 (tested against it: [`rsqrt`] computes
/// `1 / |n|` as `1 / sqrt(|n|^2)`, and a shared triangle's cross product is rounded as computed
/// from one of its corners). Every instruction-set variant gives the same bits
/// (plain IEEE operations, no fused multiply-add).
pub fn compute_features(view: &GridView<'_>, params: &FeatureParams, out: &mut Features) {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::avx512() {
        // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ, AVX2, BMI1 and BMI2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return compute_features_avx512(view, params, out);
        }
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return compute_features_avx2(view, params, out);
        }
    }
    compute_features_body::<false>(view, params, out);
}

/// [`compute_features_body`] compiled for AVX2 (8 lanes per instruction). Only plain IEEE
/// operations are used (no fused multiply-add), so the results are the same bits as without AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn compute_features_avx2(view: &GridView<'_>, params: &FeatureParams, out: &mut Features) {
    compute_features_body::<false>(view, params, out);
}

/// [`compute_features_body`] compiled for AVX-512 (16 lanes per instruction; same operations),
/// with the pair sums of all 16 lanes at once (`WIDE`): AVX-512's 32 registers hold them.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
fn compute_features_avx512(view: &GridView<'_>, params: &FeatureParams, out: &mut Features) {
    compute_features_body::<true>(view, params, out);
}

/// Square chunks per tile of the fast path: the tile's two square rows (about 25 kB) stay in the
/// level-1 cache while the tile's cells go up the rows, instead of a whole row's squares (400 kB)
/// passing through the level-2 cache for every row.
const TILE: usize = 8;

/// The plane as the blocks read it.
#[derive(Clone, Copy)]
struct Plane<'a> {
    view: &'a GridView<'a>,
    x: &'a [f32],
    y: &'a [f32],
    z: &'a [f32],
    valid: &'a [bool],
    column3: &'a [u8],
    search: &'a RowReturns,
    tests: Tests,
    min_pairs: f32,
}

/// The per-cell outputs of [`Features`], as slices.
struct Outputs<'a> {
    normal: &'a mut [Vec3],
    n_rho: &'a mut [f32],
    g_rho: &'a mut [f32],
}

impl Outputs<'_> {
    /// Writes the `m` cells from `i0` on: the features of the lanes with `cell_ok`, zeros elsewhere
    /// (selects, not branches: the lanes vectorize).
    #[inline(always)]
    fn write(&mut self, i0: usize, m: usize, cell_ok: &[bool; L], f: &Cells) {
        let ([nx, ny, nz], rho) = (&f.n, &f.rho);
        let (mut ox, mut oy, mut oz, mut orho, mut og) = ([0f32; L], [0f32; L], [0f32; L], [0f32; L], [0f32; L]);
        for l in 0..L {
            let keep = cell_ok[l];
            (ox[l], oy[l]) = (if keep { nx[l] } else { 0.0 }, if keep { ny[l] } else { 0.0 });
            (oz[l], orho[l]) = (if keep { nz[l] } else { 0.0 }, if keep { rho[l] } else { 0.0 });
            og[l] = oz[l] * orho[l];
        }
        for (l, n) in self.normal[i0..i0 + m].iter_mut().enumerate() {
            *n = Vec3::new(ox[l], oy[l], oz[l]);
        }
        self.n_rho[i0..i0 + m].copy_from_slice(&orho[..m]);
        self.g_rho[i0..i0 + m].copy_from_slice(&og[..m]);
    }

    /// Writes cell `i` from lane `l` of `f`: its features where `ok`, zeros elsewhere (the values
    /// [`Outputs::write`] gives a lane).
    #[inline(always)]
    fn write_one(&mut self, i: usize, ok: bool, f: &Cells, l: usize) {
        let (n, rho) = if ok { (Vec3::new(f.n[0][l], f.n[1][l], f.n[2][l]), f.rho[l]) } else { (Vec3::ZERO, 0.0) };
        self.normal[i] = n;
        self.n_rho[i] = rho;
        self.g_rho[i] = n.z * rho;
    }

    /// Zeros for the `m` cells from `i0` on.
    #[inline(always)]
    fn zero(&mut self, i0: usize, m: usize) {
        self.normal[i0..i0 + m].fill(Vec3::ZERO);
        self.n_rho[i0..i0 + m].fill(0.0);
        self.g_rho[i0..i0 + m].fill(0.0);
    }
}

/// The body of [`compute_features`], inlined into each instruction-set variant.
///
/// Blocks of `L` cells of a row clear of the grid's edges take the fast path ([`squares`]), in
/// tiles of [`TILE`] blocks going up the rows; the others (first and last rows and blocks, grids
/// too small) take the general search.
#[inline(always)]
fn compute_features_body<const WIDE: bool>(view: &GridView<'_>, params: &FeatureParams, out: &mut Features) {
    let (rows, cols) = (view.rows, view.cols);
    let n = rows * cols;
    out.resize(n);
    let Features { normal, n_rho, g_rho, soa } = out;
    let mut outputs = Outputs { normal: &mut normal[..n], n_rho: &mut n_rho[..n], g_rho: &mut g_rho[..n] };
    for a in [&mut soa.x, &mut soa.y, &mut soa.z] {
        a.resize(n, f32::NAN);
    }
    soa.valid.resize(n, false);
    let (xs, ys, zs, valid) = (&mut soa.x[..n], &mut soa.y[..n], &mut soa.z[..n], &mut soa.valid[..n]);
    for (i, p) in view.points[..n].iter().enumerate() {
        // `is_valid` without short-circuit branches, so that the loop vectorizes.
        (xs[i], ys[i], zs[i], valid[i]) = (p.x, p.y, p.z, p.x.is_finite() & p.y.is_finite() & p.z.is_finite());
    }
    soa.search.build(view, &soa.valid[..n]);
    column_triples(&soa.valid[..n], cols, &mut soa.column3);
    // Ratio 0 switches the test off (keep every neighbour: factor 0).
    let factor = |ratio: f32| if ratio > 0.0 { 1.0 - ratio } else { 0.0 };
    let (up, other) = (factor(params.upper_occlusion_ratio), factor(params.occlusion_ratio));
    let lat = factor(params.lateral_occlusion_ratio);
    let tests = Tests {
        max_d2: params.max_neighbour_distance_m * params.max_neighbour_distance_m,
        max_d: params.max_neighbour_distance_m,
        keep: [up, up, lat, other, other, other, lat, up],
    };
    let plane = Plane {
        view,
        x: &soa.x[..n],
        y: &soa.y[..n],
        z: &soa.z[..n],
        valid: &soa.valid[..n],
        column3: &soa.column3[..n],
        search: &soa.search,
        tests,
        min_pairs: params.min_valid_pairs as f32,
    };
    let mut lanes = Lanes::default();
    // The fast path needs a row on either side and blocks clear of both edges.
    let inner = if rows >= 3 && cols > L { squares::inner_chunks(cols) } else { 0 };
    // The chunks of row `r` that the fast path below takes; every other block here.
    let fast_chunks = |r: usize| if r == 0 || r + 1 == rows || inner < 2 { 0..0 } else { 1..inner };
    for r in 0..rows {
        let fast = fast_chunks(r);
        let mut c0 = 0;
        while c0 < cols {
            if fast.contains(&(c0 / L)) {
                c0 = fast.end * L;
                continue;
            }
            let m = (cols - c0).min(L);
            general_block(&plane, r, c0, m, &mut lanes, &mut outputs);
            c0 += m;
        }
    }
    if inner < 2 {
        return;
    }
    let mut queue = GeneralQueue::new();
    soa.horizontal.resize(cols, 0.0);
    soa.edge.resize(rows - 1, [0.0; squares::SQUARE_FIELDS]);
    let (horizontal, edge, ring) = (&mut soa.horizontal, &mut soa.edge, &mut soa.squares);
    let coords = squares::Coords { xyz: [plane.x, plane.y, plane.z], cols };
    for t0 in (0..inner).step_by(TILE) {
        let tile = t0..(t0 + TILE).min(inner);
        squares::square_row(coords, 0, tile.clone(), &mut edge[0], &mut ring[0]);
        for r in 1..rows - 1 {
            squares::square_row(coords, r, tile.clone(), &mut edge[r], &mut ring[r % 2]);
            squares::horizontal_row(coords, r, tile.start.max(1) * L - 1..tile.end * L, horizontal);
            let (below, above) = (&ring[(r - 1) % 2], &ring[r % 2]);
            for j in tile.start.max(1)..tile.end {
                fast_block::<WIDE>(&plane, below, above, horizontal, r, j, j - tile.start, &mut queue, &mut outputs);
            }
        }
    }
    queue.flush(&plane, &mut outputs);
}

/// Sets `out` (one flag per cell of `valid`, rows of `cols`) to 1 where a cell and the cells above
/// and below it hold returns, 0 elsewhere and on the first and last rows (byte operations over
/// whole rows, which vectorize).
fn column_triples(valid: &[bool], cols: usize, out: &mut Vec<u8>) {
    out.clear();
    out.resize(valid.len(), 0);
    if cols == 0 || valid.len() < 3 * cols {
        return;
    }
    let (below, rest) = (valid.chunks_exact(cols), valid[cols..].chunks_exact(cols));
    let above = valid[2 * cols..].chunks_exact(cols);
    for (((o, b), a), u) in out[cols..].chunks_exact_mut(cols).zip(below).zip(rest).zip(above) {
        for (((o, &b), &a), &u) in o.iter_mut().zip(b).zip(a).zip(u) {
            *o = u8::from(b & a & u);
        }
    }
}

/// The `L` cells of row `r` in chunk `j` (the tile's chunk `jj`; clear of the grid's edges) from the squares of the chunk
/// below and above the row; cells that lack a direct neighbour go to `queue` (the general search).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn fast_block<const WIDE: bool>(
    plane: &Plane<'_>,
    below: &squares::SquareRow,
    above: &squares::SquareRow,
    horizontal: &[f32],
    r: usize,
    j: usize,
    jj: usize,
    queue: &mut GeneralQueue,
    out: &mut Outputs<'_>,
) {
    let cols = plane.view.cols;
    let (c0, i0) = (j * L, r * cols + j * L);
    // Columns c0 - 1 ..= c0 + L with returns in the rows below, at and above: 18 flag bytes, all
    // 1 in a dense block (two wide compares rather than 18 byte loads and ands).
    let cv: &[u8; L + 2] = plane.column3[i0 - 1..i0 + L + 1].try_into().expect("L + 2 flags");
    let (head, tail) = cv.split_at(L);
    let dense =
        u128::from_ne_bytes(head.try_into().expect("16 flags")) == u128::from_ne_bytes([1; 16]) && tail == [1, 1];
    if !dense && !plane.valid[i0..i0 + L].iter().any(|&v| v) {
        out.zero(i0, L);
        return;
    }
    let acc = squares::dense_block::<WIDE>(plane.view.ranges, below, above, horizontal, r, j, jj, cols, &plane.tests);
    let mut f = Cells::default();
    acc.finish(plane.min_pairs, &mut f);
    out.write(i0, L, &[true; L], &f);
    if !dense {
        // Some cells lack a direct neighbour: those again by the general search (their lanes above
        // are overwritten when the queue is computed), but for the cells without a return (the
        // holes themselves, a third of them on a KITTI frame), whose features are zeros.
        let valid = &plane.valid[i0..i0 + L];
        for l in 0..L {
            if cv[l] & cv[l + 1] & cv[l + 2] == 0 {
                if valid[l] {
                    queue.push(plane, r, c0 + l, out);
                } else {
                    out.zero(i0 + l, 1);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
