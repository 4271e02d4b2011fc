//! The cells whose neighbours are not all their direct grid neighbours: the grid's first and last
//! rows and blocks, and cells next to a missing return, whose neighbours come from the general
//! search ([`crate::nitsch::row_returns`]) and whose pair normals are their own cross products.

#![allow(clippy::needless_range_loop)]

use super::*;

/// The `m` cells of row `r` from column `c0` on, by the general neighbour search.
#[inline(always)]
pub(super) fn general_block(
    plane: &Plane<'_>,
    r: usize,
    c0: usize,
    m: usize,
    lanes: &mut Lanes,
    out: &mut Outputs<'_>,
) {
    let i0 = r * plane.view.cols + c0;
    if !plane.valid[i0..i0 + m].iter().any(|&v| v) {
        // No return in these cells (sky): no features.
        out.zero(i0, m);
        return;
    }
    let direct = direct_lanes(plane, r, c0, m, lanes);
    let mut cell_ok = [false; L];
    for l in 0..m {
        cell_ok[l] = direct[l] || fill_one(plane, r, c0 + l, l, lanes);
    }
    let mut f = Cells::default();
    lane_features(lanes, plane.min_pairs, &mut f);
    out.write(i0, m, &cell_ok, &f);
}

/// Fills the lanes of those of the `m` cells from `(r, c0)` on whose neighbours are their direct
/// grid neighbours, lane-wise, and says which: cells off the first and last column whose row, and
/// the rows above and below where the grid has them, hold returns in the cell's column and the
/// columns either side. [`GridView::neighbours`] then finds exactly those (a missing row above or
/// below has no neighbours), so the lanes get the values [`fill_one`] would give them.
#[inline(always)]
fn direct_lanes(plane: &Plane<'_>, r: usize, c0: usize, m: usize, lanes: &mut Lanes) -> [bool; L] {
    let (rows, cols) = (plane.view.rows, plane.view.cols);
    // Rows r - 1, r, r + 1 over columns c0 - 1 ..= c0 + L: x, y, z, range and return flags.
    let mut win = [[[0f32; L + 2]; 3]; 4];
    let mut has = [[false; L + 2]; 3];
    let exists = [r > 0, true, r + 1 < rows];
    let (lo, hi) = (c0.max(1) - 1, (c0 + L + 1).min(cols));
    let w = lo + 1 - c0..hi + 1 - c0;
    for dr in 0..3 {
        if exists[dr] {
            let row = (r + dr - 1) * cols;
            let src = row + lo..row + hi;
            for (a, plane_a) in [plane.x, plane.y, plane.z, plane.view.ranges].into_iter().enumerate() {
                win[a][dr][w.clone()].copy_from_slice(&plane_a[src.clone()]);
            }
            has[dr][w.clone()].copy_from_slice(&plane.valid[src]);
        }
    }
    let mut direct = [false; L];
    for l in 0..m.min(L) {
        let c = c0 + l;
        let rows_ok = (0..3).all(|dr| !exists[dr] || (has[dr][l] & has[dr][l + 1] & has[dr][l + 2]));
        direct[l] = c > 0 && c + 1 < cols && rows_ok;
    }
    let lane = |a: usize, dr: usize, off: usize| -> [f32; L] { win[a][dr][off..off + L].try_into().expect("L lanes") };
    let (px, py, pz, pr) = (lane(0, 1, 1), lane(1, 1, 1), lane(2, 1, 1), lane(3, 1, 1));
    for (k, &(dr, dc)) in OFFSETS.iter().enumerate() {
        let (wr, off) = ((1 + dr) as usize, (1 + dc) as usize);
        let (qx, qy, qz, qr) = (lane(0, wr, off), lane(1, wr, off), lane(2, wr, off), lane(3, wr, off));
        for l in 0..L {
            // The operations of `fill_one`: a dropped or missing neighbour gets zeros.
            let d = [qx[l] - px[l], qy[l] - py[l], qz[l] - pz[l]];
            let keep = exists[wr] & plane.tests.keep(k, d[0] * d[0] + d[1] * d[1] + d[2] * d[2], qr[l], pr[l]);
            lanes.set(k, l, d, keep);
        }
    }
    direct
}

/// Offsets of cell `(r, c)` into lane `l` by the general neighbour search; false if it has no return.
///
/// Without branches per neighbour: a missing neighbour is the cell itself, whose offset (zero)
/// fails the neighbour test as a missing one would, and a cell without a return fails it for
/// every neighbour (NaN offsets): both give the zeros of a missing neighbour.
#[inline]
pub(super) fn fill_one(plane: &Plane<'_>, r: usize, c: usize, l: usize, lanes: &mut Lanes) -> bool {
    let (view, tests, ranges) = (plane.view, &plane.tests, plane.view.ranges);
    let i = r * view.cols + c;
    let nb = plane.search.neighbours_or(view, r, c, i);
    let (px, py, pz, pr) = (plane.x[i], plane.y[i], plane.z[i], ranges[i]);
    for (k, j) in nb.into_iter().enumerate() {
        let d = [plane.x[j] - px, plane.y[j] - py, plane.z[j] - pz];
        let keep = tests.keep(k, d[0] * d[0] + d[1] * d[1] + d[2] * d[2], ranges[j], pr);
        lanes.set(k, l, d, keep);
    }
    plane.valid[i]
}

/// Cells of the fast path that lack a direct neighbour, gathered from many blocks so that their
/// features ([`lane_features`]) run `L` at a time instead of once per block for a few lanes (real
/// recordings leave empty cells scattered over every ring: half the blocks have one).
///
/// A queued cell keeps only its neighbours' indices; the offsets and tests run lane-wise when the
/// queue is computed ([`gather_lanes`]), with the operations of [`fill_one`] but selects instead of
/// branches per neighbour (measured on KITTI frames: features 4.0 -> 3.7 ms, min of 6 x 20 side by side).
pub(super) struct GeneralQueue {
    lanes: Lanes,
    /// Neighbour cell indices per neighbour and lane (the cell itself where missing).
    nb: [[u32; L]; 8],
    /// Cell index per queued lane.
    cell: [u32; L],
    len: usize,
}

impl GeneralQueue {
    pub(super) fn new() -> Self {
        Self { lanes: Lanes::default(), nb: [[0; L]; 8], cell: [0; L], len: 0 }
    }

    /// Queues cell `(r, c)`; computes and writes the queue when it is full.
    #[inline(always)]
    pub(super) fn push(&mut self, plane: &Plane<'_>, r: usize, c: usize, out: &mut Outputs<'_>) {
        let i = r * plane.view.cols + c;
        let nb = plane.search.neighbours_or(plane.view, r, c, i);
        for k in 0..8 {
            self.nb[k][self.len] = nb[k] as u32;
        }
        self.cell[self.len] = i as u32;
        self.len += 1;
        if self.len == L {
            self.flush(plane, out);
        }
    }

    /// Computes the queued cells' features and writes them (stale lanes past `len` are computed
    /// from the indices left there, which are cells of the plane, and ignored).
    #[inline(always)]
    pub(super) fn flush(&mut self, plane: &Plane<'_>, out: &mut Outputs<'_>) {
        if self.len == 0 {
            return;
        }
        gather_lanes(plane, &self.cell, &self.nb, &mut self.lanes);
        let mut g = Cells::default();
        lane_features(&self.lanes, plane.min_pairs, &mut g);
        for (l, &i) in self.cell[..self.len].iter().enumerate() {
            let i = i as usize;
            out.write_one(i, plane.valid[i], &g, l);
        }
        self.len = 0;
    }
}

/// [`fill_one`]'s lanes for the cells `cell` with neighbours `nb` (per neighbour and lane),
/// lane-wise: the same operations, with selects for the tests.
#[inline(always)]
fn gather_lanes(plane: &Plane<'_>, cell: &[u32; L], nb: &[[u32; L]; 8], lanes: &mut Lanes) {
    // Every index is a cell of the plane: the clamp to the last cell changes none of them and
    // lets the loads go without bounds checks (the gathers then vectorize).
    let last = plane.x.len() - 1;
    let (x, y, z, ranges) = (&plane.x[..=last], &plane.y[..=last], &plane.z[..=last], &plane.view.ranges[..=last]);
    let (mut px, mut py, mut pz, mut pr) = ([0f32; L], [0f32; L], [0f32; L], [0f32; L]);
    for l in 0..L {
        let i = (cell[l] as usize).min(last);
        (px[l], py[l], pz[l], pr[l]) = (x[i], y[i], z[i], ranges[i]);
    }
    for k in 0..8 {
        let (mut qx, mut qy, mut qz, mut qr) = ([0f32; L], [0f32; L], [0f32; L], [0f32; L]);
        for l in 0..L {
            let j = (nb[k][l] as usize).min(last);
            (qx[l], qy[l], qz[l], qr[l]) = (x[j], y[j], z[j], ranges[j]);
        }
        for l in 0..L {
            let d = [qx[l] - px[l], qy[l] - py[l], qz[l] - pz[l]];
            let keep = plane.tests.keep(k, d[0] * d[0] + d[1] * d[1] + d[2] * d[2], qr[l], pr[l]);
            lanes.set(k, l, d, keep);
        }
    }
}
