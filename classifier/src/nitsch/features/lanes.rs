//! Eq. 1-3 lane-wise: `L` cells' neighbour offsets in, their unit normals and `n_rho` out (plain
//! IEEE operations: the same bits on every CPU).

#![allow(clippy::needless_range_loop)]

use super::L;

/// Neighbour offsets of `L` cells, lane-wise: `dx[k][l]` is `d_(k+1)` of lane `l` (0 where missing in
/// the general path; `ok` 0 marks a dropped neighbour).
#[derive(Default)]
pub(super) struct Lanes {
    pub(super) dx: [[f32; L]; 8],
    pub(super) dy: [[f32; L]; 8],
    pub(super) dz: [[f32; L]; 8],
    pub(super) ok: [[f32; L]; 8],
    /// `|d|` per lane (0 where missing in the general path; any finite value where `ok` is 0).
    pub(super) len: [[f32; L]; 8],
}

impl Lanes {
    /// Sets neighbour `k` of lane `l` from its offset `d`: zeros where it is not kept (`ok` 0).
    #[inline(always)]
    pub(super) fn set(&mut self, k: usize, l: usize, d: [f32; 3], keep: bool) {
        let d = if keep { d } else { [0.0; 3] };
        (self.dx[k][l], self.dy[k][l], self.dz[k][l]) = (d[0], d[1], d[2]);
        self.ok[k][l] = if keep { 1.0 } else { 0.0 };
        self.len[k][l] = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    }
}

/// Per-lane sums over a cell's pairs: Eq. 2's weighted normal sum, the sum of the unit pair normals
/// (Eq. 3) and the number of pairs.
#[derive(Default)]
pub(super) struct Acc {
    pub(super) s: [[f32; L]; 3],
    pub(super) e: [[f32; L]; 3],
    pub(super) pairs: [f32; L],
}

impl Acc {
    /// Adds pair normal `n` with `1 / |n|` factor `iv` and Eq. 2 weight `w` (both 0 for a
    /// missing pair) to lane `l`; `valid` is 1 for a pair that exists.
    #[inline(always)]
    pub(super) fn add(&mut self, l: usize, n: [f32; 3], iv: f32, w: f32, valid: f32) {
        for a in 0..3 {
            self.e[a][l] += n[a] * iv;
            self.s[a][l] += n[a] * w;
        }
        self.pairs[l] += valid;
    }
}

/// Eq. 1-3 for `L` cells from their neighbour offsets into `out`: the unit normal and `n_rho`
/// per lane, zeros where a cell has too few pairs or a degenerate sum.
///
/// Every lane does the operations of the per-cell definition in its order (sums over `k` from
/// `d1` to `d8`), with `1 / |n_i|` and `1 / |n|` from [`rsqrt`] (a square root and a division):
/// - a pair normal `n_i = d_i x d_(i-1)` exists when both neighbours do and it is not degenerate
///   (`|n_i|^2 > 1e-24 |d_i|^2 |d_(i-1)|^2`);
/// - Eq. 2 weight `1 / (|d_i| + |d_(i-1)|)`, Eq. 3 term `(n . n_i) / |n_i|` averaged over pairs.
#[inline(always)]
pub(super) fn lane_features(d: &Lanes, min_pairs: f32, out: &mut Cells) {
    let (dx, dy, dz, ok, len) = (&d.dx, &d.dy, &d.dz, &d.ok, &d.len);
    let mut acc = Acc::default();
    for k in 0..8 {
        // The previous neighbour of d1 is d8 (Eq. 1's d_(i-1)).
        let p = (k + 7) % 8;
        for l in 0..L {
            let x = dy[k][l] * dz[p][l] - dz[k][l] * dy[p][l];
            let y = dz[k][l] * dx[p][l] - dx[k][l] * dz[p][l];
            let z = dx[k][l] * dy[p][l] - dy[k][l] * dx[p][l];
            let nl2 = x * x + y * y + z * z;
            // `|n_i| > 1e-12 |d_i| |d_(i-1)|`, squared (no square root).
            let (lk, lp) = (len[k][l], len[p][l]);
            let t = lk * lp;
            // 1 where the pair exists, else 0 (a select, not a conversion).
            let valid = if nl2 > 1e-24 * t * t { ok[k][l] * ok[p][l] } else { 0.0 };
            let iv = valid * rsqrt(nl2.max(f32::MIN_POSITIVE));
            acc.add(l, [x, y, z], iv, valid / (lk + lp).max(f32::MIN_POSITIVE), valid);
        }
    }
    acc.finish(min_pairs, out);
}

/// Features of `L` cells, lane-wise: the unit normal and `n_rho`.
#[derive(Default)]
pub(super) struct Cells {
    pub(super) n: [[f32; L]; 3],
    pub(super) rho: [f32; L],
}

impl Acc {
    /// Eq. 2-3 from the sums into `out`: the unit normal and `n_rho` per lane, zeros where a
    /// cell has fewer than `min_pairs` pairs or a degenerate sum.
    #[inline(always)]
    pub(super) fn finish(&self, min_pairs: f32, out: &mut Cells) {
        let ([sx, sy, sz], [ex, ey, ez], pairs) = (&self.s, &self.e, &self.pairs);
        let (mut ux, mut uy, mut uz, mut good) = ([0f32; L], [0f32; L], [0f32; L], [false; L]);
        for l in 0..L {
            let sum2 = sx[l] * sx[l] + sy[l] * sy[l] + sz[l] * sz[l];
            good[l] = (pairs[l] >= min_pairs) & (sum2 > 0.0) & sum2.is_finite();
            let inv_len = rsqrt(sum2.max(f32::MIN_POSITIVE));
            (ux[l], uy[l], uz[l]) = (sx[l] * inv_len, sy[l] * inv_len, sz[l] * inv_len);
        }
        // Eq. 3: mean cosine similarity between n and its generating normals.
        let ([ox, oy, oz], rho) = (&mut out.n, &mut out.rho);
        for l in 0..L {
            let q = (ux[l] * ex[l] + uy[l] * ey[l] + uz[l] * ez[l]) / pairs[l];
            (ox[l], oy[l], oz[l], rho[l]) = if good[l] { (ux[l], uy[l], uz[l], q) } else { (0.0, 0.0, 0.0, 0.0) };
        }
    }
}

/// `1 / sqrt(x)` as an IEEE square root and division, both correctly rounded, so the same bits on
/// every CPU and code path. This replaced an exponent-halving estimate with two Newton steps (plain
/// multiplications and adds, 5e-6 relative error): on AMD Zen 3 the square root and division units
/// run beside the multipliers the rest of the features keep busy, and KITTI frames' features took
/// 3.13 instead of 3.47 ms (min of 4 x 20, side by side), besides being exact.
#[inline(always)]
pub(super) fn rsqrt(x: f32) -> f32 {
    1.0 / x.sqrt()
}
