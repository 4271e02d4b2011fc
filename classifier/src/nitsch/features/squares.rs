//! The fast path of the features: per-edge and per-triangle quantities computed once per grid
//! square and shared by the cells that use them.
//!
//! Every pair normal `n_i = d_i x d_(i-1)` of a cell is the cross product of a triangle of the cell
//! and two neighbours that are themselves grid neighbours, that is half of one of the 4 grid squares
//! around the cell. Each square `(s, c)` with corners `a = (s, c)`, `b = (s, c + 1)`,
//! `u = (s + 1, c)`, `v = (s + 1, c + 1)` holds 4 such triangles, and each of them is a pair normal
//! of exactly 2 cells (the two ends of the diagonal it lies on, where the cross product is the same
//! vector: cyclic vertex orders give the same cross product):
//!
//! | triangle | cross product | pair of `a` / `b` | pair of `u` / `v` |
//! |---|---|---|---|
//! | `T0 = (a, v, u)` | `(v - a) x (u - a)` | `d2 x d1` of `a` | `d7 x d6` of `v` |
//! | `T1 = (a, b, v)` | `(b - a) x (v - a)` | `d3 x d2` of `a` | `d6 x d5` of `v` |
//! | `T2 = (b, v, u)` | `(v - b) x (u - b)` | `d1 x d8` of `b` | `d4 x d3` of `u` |
//! | `T3 = (b, u, a)` | `(u - b) x (a - b)` | `d8 x d7` of `b` | `d5 x d4` of `u` |
//!
//! So a row of squares computes 4 cross products, their squared lengths and reciprocal lengths,
//! and the lengths of the vertical, diagonal and anti-diagonal edges once, instead of 8 pair
//! normals and 8 neighbour distances per cell. Edge lengths are the same bits as a per-cell
//! computation (`q - p` is exactly `-(p - q)`); a triangle's cross product computed from its other
//! corner differs in rounding only (the per-cell reference test bounds the features within 1e-5).

// Lane arrays are indexed by field and lane on purpose (vectorized across columns).
#![allow(clippy::needless_range_loop)]

use super::{Acc, L, TILE, Tests, rsqrt};

/// Floats stored per triangle: the cross product `x, y, z`, its squared length and `1 / |n|`.
const TRI: usize = 5;
/// Fields of a square: 4 triangles, then the edge lengths.
pub(super) const SQUARE_FIELDS: usize = 4 * TRI + 3;
/// Length of the vertical edge `|u - a|`.
const VERTICAL: usize = 4 * TRI;
/// Length of the diagonal edge `|v - a|`.
const DIAGONAL: usize = 4 * TRI + 1;
/// Length of the anti-diagonal edge `|u - b|`.
const ANTI: usize = 4 * TRI + 2;

/// Lanes of a [`SquareRow`] before its first chunk; the last of them holds the square left of the
/// tile, so that chunk `jj`'s squares start at the aligned lane `LEAD + jj L`.
const LEAD: usize = L;

/// The squares of one square row over a tile's chunks, every field as a row of lanes: lane
/// `LEAD + jj L + l` is column `j L + l` of the tile's chunk `jj` (`j` = tile start + `jj`), and lane
/// `LEAD - 1` the square left of the tile. The fast path reads the squares at `c` and at `c - 1` of
/// `L` cells as plain loads (no shuffles).
///
/// Each field's row is 64-byte aligned and a whole number of cache lines long, so the `L` lanes a
/// chunk stores per field are one aligned store (one cache line with `L` = 16), not a store split
/// over two lines: the layout with the left square at lane 0 of `L + 1` lanes per chunk split
/// every store and most loads. One array for all fields, not one slice per field: the compiler
/// vectorizes stores into one array, while 23 separate slices might overlap as far as it can tell,
/// and it then writes lane by lane, 10 times slower.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub(super) struct SquareRow([[f32; LEAD + TILE * L]; SQUARE_FIELDS]);

impl Default for SquareRow {
    fn default() -> Self {
        Self([[0.0; LEAD + TILE * L]; SQUARE_FIELDS])
    }
}

/// The plane's coordinates as the square and edge rows read them: `x`, `y`, `z`, each row-major in
/// rows of `cols`.
#[derive(Clone, Copy)]
pub(super) struct Coords<'a> {
    /// `x`, `y` and `z` of every cell.
    pub(super) xyz: [&'a [f32]; 3],
    /// Cells per row.
    pub(super) cols: usize,
}

/// `L` consecutive values of `a` from `i` on.
#[inline(always)]
fn at(a: &[f32], i: usize) -> [f32; L] {
    a[i..i + L].try_into().expect("L cells")
}

/// `q - p` in lane `l`.
#[inline(always)]
fn sub(q: &[[f32; L]; 3], p: &[[f32; L]; 3], l: usize) -> [f32; 3] {
    [q[0][l] - p[0][l], q[1][l] - p[1][l], q[2][l] - p[2][l]]
}

/// `|d|` as glam's `length`: `sqrt((x * x + y * y) + z * z)`.
#[inline(always)]
fn length(d: [f32; 3]) -> f32 {
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// Square chunks whose 16 cells are clear of both grid edges (`j L + L < cols`): the fast path
/// runs on chunks `1..` this (and reads the squares of chunk 0 through lane 0 of chunk 1).
pub(super) fn inner_chunks(cols: usize) -> usize {
    (cols - 1) / L
}

/// Fills `out` with the triangles and edge lengths of the squares between rows `s` and `s + 1` of
/// the plane (`coords`) over the chunks `chunks` (at most
/// [`TILE`]). `edge` holds the last square of the chunk before `chunks` (lane `LEAD - 1`) and gets
/// the last square of `chunks`. Squares with a corner without a return get meaningless values; the
/// fast path never reads them. Needs `chunks.end <= inner_chunks(cols)` and `s + 1` a row of the
/// plane.
#[inline(always)]
pub(super) fn square_row(
    coords: Coords<'_>,
    s: usize,
    chunks: std::ops::Range<usize>,
    edge: &mut [f32; SQUARE_FIELDS],
    out: &mut SquareRow,
) {
    let Coords { xyz: [xs, ys, zs], cols } = coords;
    assert!(chunks.len() <= TILE, "a tile has at most TILE chunks");
    let o = &mut out.0;
    for (jj, j) in chunks.clone().enumerate() {
        let (ia, iu) = (s * cols + j * L, (s + 1) * cols + j * L);
        let load = |i: usize| [at(xs, i), at(ys, i), at(zs, i)];
        let (a, b, u, v) = (load(ia), load(ia + 1), load(iu), load(iu + 1));
        let base = LEAD + (jj % TILE) * L;
        // The chunk's fields in a local block first, lane index in range by construction, then
        // copied: stores into `o` at `base + l` kept a bounds check per lane and a scalar loop
        // (AVX2 build: a third of the features' time in these lanes' square roots and divisions).
        let mut fields = [[0f32; L]; SQUARE_FIELDS];
        for l in 0..L {
            let (ua, va, ba) = (sub(&u, &a, l), sub(&v, &a, l), sub(&b, &a, l));
            let (vb, ub, ab) = (sub(&v, &b, l), sub(&u, &b, l), sub(&a, &b, l));
            for (t, (p, q)) in [(va, ua), (ba, va), (vb, ub), (ub, ab)].into_iter().enumerate() {
                let x = p[1] * q[2] - p[2] * q[1];
                let y = p[2] * q[0] - p[0] * q[2];
                let z = p[0] * q[1] - p[1] * q[0];
                let nl2 = x * x + y * y + z * z;
                fields[t * TRI][l] = x;
                fields[t * TRI + 1][l] = y;
                fields[t * TRI + 2][l] = z;
                fields[t * TRI + 3][l] = nl2;
                fields[t * TRI + 4][l] = rsqrt(nl2.max(f32::MIN_POSITIVE));
            }
            fields[VERTICAL][l] = length(ua);
            fields[DIAGONAL][l] = length(va);
            fields[ANTI][l] = length(ub);
        }
        for (row, field) in o.iter_mut().zip(&fields) {
            row[base..base + L].copy_from_slice(field);
        }
    }
    // Lane `LEAD - 1`: the previous chunk's last square; then this tile's last square for the next.
    let last = LEAD + chunks.len() * L - 1;
    for (f, e) in edge.iter_mut().enumerate() {
        o[f][LEAD - 1] = *e;
        *e = o[f][last];
    }
}

/// Sets `out[c]` to the length of the horizontal edge `|P(r, c + 1) - P(r, c)|` of row `r` for the
/// columns `c` of `range` (`range.end < cols`).
#[inline(always)]
pub(super) fn horizontal_row(coords: Coords<'_>, r: usize, range: std::ops::Range<usize>, out: &mut [f32]) {
    let Coords { xyz: [xs, ys, zs], cols } = coords;
    let row = r * cols..(r + 1) * cols;
    let (x, y, z) = (&xs[row.clone()], &ys[row.clone()], &zs[row]);
    for c in range {
        out[c] = length([x[c + 1] - x[c], y[c + 1] - y[c], z[c + 1] - z[c]]);
    }
}

/// Where cell `(r, c)` finds its pair `k` (`d_(k+1) x d_k`, `d_0` = `d_8`) in the square rows below
/// (`false`) or above (`true`) it: triangle index and column offset (module table).
const PAIR_TRIANGLE: [(bool, usize, usize); 8] = [
    (true, 2, 1),  // d1 x d8: T2 of square (r, c - 1)
    (true, 0, 0),  // d2 x d1: T0 of square (r, c)
    (true, 1, 0),  // d3 x d2: T1 of square (r, c)
    (false, 2, 0), // d4 x d3: T2 of square (r - 1, c)
    (false, 3, 0), // d5 x d4: T3 of square (r - 1, c)
    (false, 1, 1), // d6 x d5: T1 of square (r - 1, c - 1)
    (false, 0, 1), // d7 x d6: T0 of square (r - 1, c - 1)
    (true, 3, 1),  // d8 x d7: T3 of square (r, c - 1)
];

/// Field `f` of the `L` squares from column `j L - back` on (`back` 0 or 1), `j` the tile's chunk `jj`.
#[inline(always)]
fn window(row: &SquareRow, f: usize, jj: usize, back: usize) -> [f32; L] {
    let start = LEAD + (jj % TILE) * L - back;
    row.0[f][start..start + L].try_into().expect("L lanes")
}

/// Accumulates Eq. 2 and the sum of unit pair normals for the `L` cells from `(r, c0)` on
/// (`c0 = j L`, `1 <= j < inner_chunks(cols)`), all with their 8 direct neighbours present, from
/// chunk `j` of the square rows `below` (`r - 1`) and `above` (`r`) and the horizontal edge lengths
/// `horizontal` of row `r` (indexed by column).
/// The same operations per pair as [`super::lane_features`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn dense_block<const WIDE: bool>(
    ranges: &[f32],
    below: &SquareRow,
    above: &SquareRow,
    horizontal: &[f32],
    r: usize,
    j: usize,
    jj: usize,
    cols: usize,
    tests: &Tests,
) -> Acc {
    let c0 = j * L;
    // |d_k| for d1..d8, from the squares and row edges that hold them.
    let len = [
        window(above, VERTICAL, jj, 0),
        window(above, DIAGONAL, jj, 0),
        at(horizontal, c0),
        window(below, ANTI, jj, 0),
        window(below, VERTICAL, jj, 0),
        window(below, DIAGONAL, jj, 1),
        at(horizontal, c0 - 1),
        window(above, ANTI, jj, 1),
    ];
    let i0 = r * cols + c0;
    let pr = at(ranges, i0);
    let mut ok = [[0f32; L]; 8];
    for (k, &(dr, dc)) in super::OFFSETS.iter().enumerate() {
        let qr = at(ranges, (i0 as isize + dr * cols as isize + dc) as usize);
        for l in 0..L {
            ok[k][l] = if tests.keep_len(k, len[k][l], qr[l], pr[l]) { 1.0 } else { 0.0 };
        }
    }
    let mut acc = Acc::default();
    let chunk = ChunkPairs { below, above, jj, len: &len, ok: &ok };
    if WIDE {
        // All lanes at once (AVX-512: the 7 sums of 16 lanes stay in 7 of its 32 registers).
        pairs::<0, L>(chunk, &mut acc);
    } else {
        // Half the lanes at a time: the half's sums stay in registers over the 8 pairs (AVX2's 16
        // registers do not hold the sums of all 16 lanes).
        pairs::<0, { L / 2 }>(chunk, &mut acc);
        pairs::<{ L / 2 }, { L / 2 }>(chunk, &mut acc);
    }
    acc
}

/// What the pairs of [`dense_block`] read: the square rows `below` and `above` the cells, the
/// chunk's index `jj` in them, and per neighbour `k` its distance `len[k]` and whether it passes the
/// tests (`ok[k]`, 1 or 0).
#[derive(Clone, Copy)]
struct ChunkPairs<'a> {
    below: &'a SquareRow,
    above: &'a SquareRow,
    jj: usize,
    len: &'a [[f32; L]; 8],
    ok: &'a [[f32; L]; 8],
}

/// The 8 pairs of [`dense_block`], in order, for the lanes `H .. H + W`.
#[inline(always)]
fn pairs<const H: usize, const W: usize>(chunk: ChunkPairs<'_>, acc: &mut Acc) {
    pair::<0, H, W>(chunk, acc);
    pair::<1, H, W>(chunk, acc);
    pair::<2, H, W>(chunk, acc);
    pair::<3, H, W>(chunk, acc);
    pair::<4, H, W>(chunk, acc);
    pair::<5, H, W>(chunk, acc);
    pair::<6, H, W>(chunk, acc);
    pair::<7, H, W>(chunk, acc);
}

/// Pair `K` of [`dense_block`] for the lanes `H .. H + W` (constants, so the triangle's fields
/// are constant offsets).
#[inline(always)]
fn pair<const K: usize, const H: usize, const W: usize>(chunk: ChunkPairs<'_>, acc: &mut Acc) {
    let ChunkPairs { below, above, jj, len, ok } = chunk;
    let (up, t, back) = PAIR_TRIANGLE[K];
    let chunk = if up { above } else { below };
    let field = |f: usize| window(chunk, f, jj, back);
    let (x, y, z) = (field(t * TRI), field(t * TRI + 1), field(t * TRI + 2));
    let (nl2, inv) = (field(t * TRI + 3), field(t * TRI + 4));
    let p = (K + 7) % 8;
    for l in H..H + W {
        let (lk, lp) = (len[K][l], len[p][l]);
        let tt = lk * lp;
        let valid = if nl2[l] > 1e-24 * tt * tt { ok[K][l] * ok[p][l] } else { 0.0 };
        acc.add(l, [x[l], y[l], z[l]], valid * inv[l], valid / (lk + lp).max(f32::MIN_POSITIVE), valid);
    }
}
