//! Ring boundaries of a cloud in scan order (the rules are in the parent module's docs).
//!
//! The rules look at two things per point: whether it lies in the cut window, and whether its
//! progress drops from its predecessor's. Both are computed for every point in one pass that the
//! compiler vectorizes (one flag byte a point), and the rules then visit only the points where a
//! flag is set: about 2 % of a KITTI frame (the window) plus the drops, instead of a branchy walk
//! over every point.

use std::f32::consts::{PI, TAU};

use super::super::beam_table::{TableRows, wrap_into};
use super::{MEDIAN_SAMPLES, UnfoldParams, median, sampled_median, wrap_once};

/// Flag of a point in the cut window.
const IN_WINDOW: u8 = 1;
/// Flag of a point whose progress drops from its predecessor's (never set on point 0).
const DROP: u8 = 2;

/// Points flagged per block of the flag pass.
const BLOCK: usize = 64;

/// `a` wrapped into `(-pi, pi]` (`a` within a turn of it), as selects.
#[inline(always)]
fn wrap_pi(a: f32) -> f32 {
    let b = if a > PI { a - TAU } else { a };
    if a <= -PI { a + TAU } else { b }
}

/// The azimuth turned from point to point, summed: `wrap_pi` of every step, added in 8 lanes
/// (lane `l` takes the steps `l`, `l + 8`, ...) and then lane 0 to 7, a fixed order on every
/// machine. Only its sign and size are used (the direction of the turn, the number of turns).
#[inline(always)]
fn turned(az: &[f32]) -> f32 {
    let mut acc = [0f32; 8];
    let (next, prev) = (&az[1..], &az[..az.len() - 1]);
    let mut chunks = next.chunks_exact(8).zip(prev.chunks_exact(8));
    for (b, a) in &mut chunks {
        for l in 0..8 {
            acc[l] += wrap_pi(b[l] - a[l]);
        }
    }
    let done = next.len() / 8 * 8;
    for (l, (b, a)) in next[done..].iter().zip(&prev[done..]).enumerate() {
        acc[l] += wrap_pi(b - a);
    }
    acc.iter().sum()
}

/// A point's progress through its laser's turn: its azimuth from the cut in the direction `dir`,
/// in `[0, 2 pi)`.
#[inline(always)]
fn progress(a: f32, dir: f32, cut: f32) -> f32 {
    wrap_into(dir * (a - cut), TAU)
}

/// The flags of every point ([`IN_WINDOW`], [`DROP`]): the same comparisons, in the same float
/// operations, as the rules state them per point.
#[inline(always)]
fn flags(az: &[f32], dist: &[f32], dir: f32, params: &UnfoldParams) -> Vec<u8> {
    let n = az.len();
    let (cut, w) = (params.cut_azimuth_rad, params.cut_window_rad);
    let (back, parallax) = (params.backward_step_rad, params.parallax_m);
    let mut out = vec![0u8; n];
    // One point's flags from its progress and distance and its predecessor's.
    let flag = |q: f32, d: f32, q_prev: f32, d_prev: f32| -> u8 {
        let window = (q < w) | (q > TAU - w);
        let drop = q < q_prev - back - parallax / d_prev.min(d).max(1e-3);
        u8::from(window) | (u8::from(drop) << 1)
    };
    let (mut q_prev, mut d_prev) = (progress(az[0], dir, cut), dist[0]);
    let blocks = az.chunks_exact(BLOCK).zip(dist.chunks_exact(BLOCK)).zip(out.chunks_exact_mut(BLOCK));
    for ((a, d), o) in blocks {
        // Progress by one wrap (the common case: |azimuth - cut| within a turn), checked.
        let (mut q, mut outside) = ([0f32; BLOCK], 0u32);
        for l in 0..BLOCK {
            let x = dir * (a[l] - cut);
            outside += u32::from(!(-TAU..2.0 * TAU).contains(&x));
            q[l] = wrap_once(x, TAU);
        }
        if outside > 0 {
            for l in 0..BLOCK {
                q[l] = progress(a[l], dir, cut);
            }
        }
        let (mut qp, mut dp) = ([0f32; BLOCK], [0f32; BLOCK]);
        (qp[0], dp[0]) = (q_prev, d_prev);
        qp[1..].copy_from_slice(&q[..BLOCK - 1]);
        dp[1..].copy_from_slice(&d[..BLOCK - 1]);
        for l in 0..BLOCK {
            o[l] = flag(q[l], d[l], qp[l], dp[l]);
        }
        (q_prev, d_prev) = (q[BLOCK - 1], d[BLOCK - 1]);
    }
    let done = n / BLOCK * BLOCK;
    for j in done..n {
        let q = progress(az[j], dir, cut);
        out[j] = flag(q, dist[j], q_prev, d_prev);
        (q_prev, d_prev) = (q, dist[j]);
    }
    // Point 0 has no predecessor.
    out[0] &= !DROP;
    out
}

/// The first point at or after `j` with a flag set (`flags.len()` if none).
#[inline]
fn next_flagged(flags: &[u8], mut j: usize) -> usize {
    while let Some(eight) = flags.get(j..j + 8) {
        if u64::from_le_bytes(eight.try_into().expect("8 bytes")) != 0 {
            break;
        }
        j += 8;
    }
    while j < flags.len() && flags[j] == 0 {
        j += 1;
    }
    j
}

crate::cpu::dispatch_by_isa! {
    /// Splits the usable points (file order; `az` their azimuths, `fine` their `tan(elevation)` from
    /// their nearest beam's origin) into rings; returns the start of each ring, or why the order does
    /// not unfold, with the direction of the turn (+1 counter-clockwise).
    pub(crate) fn ring_starts(
        az: &[f32],
        dist: &[f32],
        fine: &[f32],
        rows: &TableRows,
        params: &UnfoldParams,
    ) -> Result<(Vec<usize>, f32), String>;
    body: ring_starts_body, avx2: "avx2" if std::arch::is_x86_feature_detected!("avx2")
}

/// The body of [`ring_starts`], inlined into each instruction-set variant.
#[inline(always)]
fn ring_starts_body(
    az: &[f32],
    dist: &[f32],
    fine: &[f32],
    rows: &TableRows,
    params: &UnfoldParams,
) -> Result<(Vec<usize>, f32), String> {
    let n = az.len();
    if n < 2 {
        return Err(format!("{n} usable points"));
    }
    let total = turned(az);
    let dir = if total >= 0.0 { 1.0 } else { -1.0 };
    let turns = total.abs() / TAU;
    if turns > rows.len() as f32 + 1.0 {
        return Err(format!("the azimuth turns {turns:.0} times, more than the table's {} rows", rows.len()));
    }
    let flags = flags(az, dist, dir, params);
    let in_window = |j: usize| flags[j] & IN_WINDOW != 0;
    // Whether progress drops from point j - 1 to point j.
    let drop = |j: usize| flags[j] & DROP != 0;
    // Which way the rings go in elevation: compare the first and last 1/8 of the points.
    let m = (n / 8).max(1);
    let mut scratch = Vec::with_capacity(MEDIAN_SAMPLES);
    let down = sampled_median(&fine[..m], &mut scratch) >= sampled_median(&fine[n - m..], &mut scratch);
    let min_gap = rows.tan_elevation.windows(2).map(|w| w[1] - w[0]).fold(f32::INFINITY, f32::min);
    let mut starts = vec![0usize];
    // The file's first points are the first ring's, window or not.
    let mut j = 1;
    while j < n && in_window(j - 1) && in_window(j) {
        j += 1;
    }
    loop {
        // Points with neither flag start nothing.
        j = next_flagged(&flags, j);
        if j >= n {
            break;
        }
        if in_window(j) {
            // The run a..b of window points; a boundary if progress drops across prev..=b.
            let a = j;
            let mut b = j;
            while b < n && in_window(b) {
                b += 1;
            }
            let hi = b.min(n - 1);
            if (a..=hi).any(drop) {
                let mut best = (0.1 * min_gap, None);
                for s in a..=hi {
                    let step = if down { fine[s - 1] - fine[s] } else { fine[s] - fine[s - 1] };
                    if step > best.0 {
                        best = (step, Some(s));
                    }
                }
                let restart = || (a..=hi).find(|&k| progress(az[k], dir, params.cut_azimuth_rad) < PI);
                starts.push(best.1.or_else(restart).unwrap_or(hi));
            }
            j = b + 1;
            continue;
        }
        if !in_window(j - 1) && drop(j) {
            starts.push(j);
        }
        j += 1;
    }
    starts.dedup();
    merge_tiny_rings(&mut starts, fine, rows, min_gap);
    let max_per_ring = rows.cols + rows.cols / 20 + 1;
    let mut bounds = starts.clone();
    bounds.push(n);
    if let Some(w) = bounds.windows(2).find(|w| w[1] - w[0] > max_per_ring) {
        return Err(format!("a ring would hold {} points, more than a turn's {}", w[1] - w[0], rows.cols));
    }
    if starts.len() > rows.len() {
        return Err(format!("{} rings, more than the table's {} rows", starts.len(), rows.len()));
    }
    if starts.len() < 2 {
        return Err("fewer than 2 rings".into());
    }
    Ok((starts, dir))
}

/// A tiny ring (fewer than 1 % of a turn's points) next to a ring at the same elevation is a
/// laser's few points on the wrong side of a boundary: merged into it.
fn merge_tiny_rings(starts: &mut Vec<usize>, fine: &[f32], rows: &TableRows, min_gap: f32) {
    let n = fine.len();
    let tiny = (rows.cols / 100).max(2);
    let mut k = 0;
    while starts.len() > 1 && k < starts.len() {
        let end = starts.get(k + 1).copied().unwrap_or(n);
        if end - starts[k] < tiny {
            let med = |a: usize, b: usize| median(&mut fine[a..b].to_vec());
            let own = med(starts[k], end);
            let prev = (k > 0).then(|| (med(starts[k - 1], starts[k]) - own).abs());
            let next = starts.get(k + 1).map(|&s1| (med(s1, starts.get(k + 2).copied().unwrap_or(n)) - own).abs());
            match (prev, next) {
                (Some(p), nx) if p < 0.5 * min_gap && nx.is_none_or(|x| p <= x) => {
                    starts.remove(k);
                    continue;
                }
                (_, Some(x)) if x < 0.5 * min_gap => {
                    starts.remove(k + 1);
                    continue;
                }
                _ => {}
            }
        }
        k += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The per-point rules as first written: a walk over every point with its own comparisons.
    fn flags_by_point(az: &[f32], dist: &[f32], dir: f32, params: &UnfoldParams) -> Vec<u8> {
        let q: Vec<f32> = az.iter().map(|&a| wrap_into(dir * (a - params.cut_azimuth_rad), TAU)).collect();
        let w = params.cut_window_rad;
        (0..az.len())
            .map(|j| {
                let window = q[j] < w || q[j] > TAU - w;
                let drop = j > 0
                    && q[j]
                        < q[j - 1] - params.backward_step_rad - params.parallax_m / dist[j - 1].min(dist[j]).max(1e-3);
                u8::from(window) | (u8::from(drop) << 1)
            })
            .collect()
    }

    #[test]
    fn flags_equal_the_per_point_rules() {
        // Azimuths over several turns, both ways, with jitter and cuts far from the azimuths (the
        // wrap then takes more than one turn).
        let az: Vec<f32> = (0..5_000).map(|i| wrap_pi(i as f32 * 0.0031 + ((i * 7919) % 13) as f32 * 1e-3)).collect();
        let dist: Vec<f32> = (0..5_000).map(|i| 0.5 + ((i * 31) % 97) as f32 * 0.3).collect();
        for cut in [0.0, 1.0, -3.0, 9.5, -20.0] {
            for dir in [1.0, -1.0] {
                let params = UnfoldParams { cut_azimuth_rad: cut, ..UnfoldParams::default() };
                for len in [1, 63, 64, 65, 5_000] {
                    assert_eq!(
                        flags(&az[..len], &dist[..len], dir, &params),
                        flags_by_point(&az[..len], &dist[..len], dir, &params),
                        "cut {cut}, dir {dir}, {len} points"
                    );
                }
            }
        }
    }

    #[test]
    fn next_flagged_skips_unflagged_points() {
        let mut f = vec![0u8; 100];
        f[3] = 1;
        f[40] = 2;
        assert_eq!(next_flagged(&f, 0), 3);
        assert_eq!(next_flagged(&f, 3), 3);
        assert_eq!(next_flagged(&f, 4), 40);
        assert_eq!(next_flagged(&f, 41), 100);
        assert_eq!(next_flagged(&f[..5], 4), 5);
    }

    #[test]
    fn the_turn_is_summed_over_every_step() {
        // Two counter-clockwise turns in 1,000 steps, then 10 steps back.
        let mut az: Vec<f32> = (0..=1_000).map(|i| wrap_pi(i as f32 * 2.0 * TAU / 1_000.0)).collect();
        az.extend((1..=10).map(|i| wrap_pi(-(i as f32) * 0.01)));
        let total = turned(&az);
        assert!((total - (2.0 * TAU - 0.1)).abs() < 1e-3, "{total}");
        assert!((turned(&az[..3]) - 2.0 * 2.0 * TAU / 1_000.0).abs() < 1e-6);
    }
}
