//! The lane-wise computation against the per-cell definition it replaced (kept here verbatim
//! as the reference), within a tolerance, on damaged synthetic frames.

use super::*;
use crate::error::is_valid;
use crate::nitsch::neighbours::detect_wrap;

/// The per-cell definition: neighbours by [`GridView::neighbours`], then Eq. 1-3.
fn reference(view: &GridView<'_>, params: &FeatureParams) -> Vec<(Vec3, f32, f32)> {
    let max_d2 = params.max_neighbour_distance_m * params.max_neighbour_distance_m;
    let factor = |ratio: f32| if ratio > 0.0 { 1.0 - ratio } else { 0.0 };
    let (up, other) = (factor(params.upper_occlusion_ratio), factor(params.occlusion_ratio));
    let lat = factor(params.lateral_occlusion_ratio);
    let keep = [up, up, lat, other, other, other, lat, up];
    let mut out = Vec::new();
    for r in 0..view.rows {
        for c in 0..view.cols {
            let i = r * view.cols + c;
            let p = view.points[i];
            let (n, n_rho) = if is_valid(p) {
                cell_features(view, i, p, view.neighbours(r, c), max_d2, keep, params.min_valid_pairs)
            } else {
                (Vec3::ZERO, 0.0)
            };
            out.push((n, n_rho, n.z * n_rho));
        }
    }
    out
}

/// Eq. 1-3 for one cell at `p` with neighbour cells `nb` (order `d1..d8`).
///
/// Written branch-free over 8 lanes (`[f32; 8]` per coordinate) so the compiler vectorizes it:
/// missing neighbours and degenerate pairs get weight 0 instead of a branch.
#[inline]
fn cell_features(
    view: &GridView<'_>,
    i: usize,
    p: Vec3,
    nb: [Option<usize>; 8],
    max_d2: f32,
    keep: [f32; 8],
    min_pairs: usize,
) -> (Vec3, f32) {
    let (mut dx, mut dy, mut dz, mut ok) = ([0f32; 8], [0f32; 8], [0f32; 8], [0f32; 8]);
    // Neighbours nearer than `keep[k] * range` occlude the cell (NaN ranges compare false: kept).
    let range = view.ranges[i];
    for k in 0..8 {
        if let Some(j) = nb[k] {
            let d = view.points[j] - p;
            let l2 = d.length_squared();
            if l2 <= max_d2
                && l2 > 0.0
                && view.ranges[j].partial_cmp(&(keep[k] * range)) != Some(std::cmp::Ordering::Less)
            {
                (dx[k], dy[k], dz[k], ok[k]) = (d.x, d.y, d.z, 1.0);
            }
        }
    }
    pair_features(&dx, &dy, &dz, &ok, min_pairs)
}

/// Eq. 1-3 from the neighbour offsets (lane k = `d_(k+1)`; `ok` 1 where the neighbour exists).
#[inline]
fn pair_features(dx: &[f32; 8], dy: &[f32; 8], dz: &[f32; 8], ok: &[f32; 8], min_pairs: usize) -> (Vec3, f32) {
    // The previous neighbour of lane k is lane k - 1 (lane 7 for lane 0): Eq. 1's d_(i-1) and d_8.
    let prev = |a: &[f32; 8]| [a[7], a[0], a[1], a[2], a[3], a[4], a[5], a[6]];
    let (px, py, pz, pok) = (prev(dx), prev(dy), prev(dz), prev(ok));
    let mut len = [0f32; 8];
    for k in 0..8 {
        len[k] = (dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k]).sqrt();
    }
    let plen = prev(&len);
    let (mut nx, mut ny, mut nz, mut w, mut inv) = ([0f32; 8], [0f32; 8], [0f32; 8], [0f32; 8], [0f32; 8]);
    for k in 0..8 {
        // Eq. 1: n_i = d_i x d_(i-1).
        nx[k] = dy[k] * pz[k] - dz[k] * py[k];
        ny[k] = dz[k] * px[k] - dx[k] * pz[k];
        nz[k] = dx[k] * py[k] - dy[k] * px[k];
        let nl = (nx[k] * nx[k] + ny[k] * ny[k] + nz[k] * nz[k]).sqrt();
        // A pair exists when both neighbours do and the cross product is not degenerate.
        let valid = ok[k] * pok[k] * f32::from(u8::from(nl > 1e-12 * len[k] * plen[k]));
        // Eq. 2 weight 1 / (|d_i| + |d_(i-1)|); Eq. 3 needs 1 / |n_i|.
        inv[k] = valid / nl.max(f32::MIN_POSITIVE);
        w[k] = valid / (len[k] + plen[k]).max(f32::MIN_POSITIVE);
    }
    let (mut sx, mut sy, mut sz, mut pairs) = (0f32, 0f32, 0f32, 0f32);
    for k in 0..8 {
        sx += nx[k] * w[k];
        sy += ny[k] * w[k];
        sz += nz[k] * w[k];
        pairs += f32::from(u8::from(inv[k] > 0.0));
    }
    let sum_len = (sx * sx + sy * sy + sz * sz).sqrt();
    if (pairs as usize) < min_pairs || !(sum_len > 0.0 && sum_len.is_finite()) {
        return (Vec3::ZERO, 0.0);
    }
    let n = Vec3::new(sx, sy, sz) / sum_len;
    // Eq. 3: mean cosine similarity between n and its generating normals.
    let mut cos_sum = 0.0;
    for k in 0..8 {
        cos_sum += (n.x * nx[k] + n.y * ny[k] + n.z * nz[k]) * inv[k];
    }
    (n, cos_sum / pairs)
}

fn frame(drop: f32, seed: u64, spinning: bool) -> sim::OrderedCloud {
    crate::synthetic::noisy_cars_frame(drop, seed, spinning, 0.03)
}

#[test]
fn small_and_odd_grids_equal_the_per_cell_definition() {
    // Corners of the spinning frame cut to sizes around the fast path's limits (3 rows, a
    // chunk clear of both edges, tiles of 8 chunks), wrapping and not.
    let cloud = frame(0.1, 5, true);
    let (mut cells, mut featured) = (0, 0);
    for (rows, cols) in [(1, 1), (1, 40), (2, 33), (3, 17), (3, 18), (3, 33), (4, 47), (5, 150), (7, 161)] {
        let (mut points, mut ranges) = (Vec::new(), Vec::new());
        for r in 0..rows {
            let row = (r + 10) * cloud.cols;
            points.extend_from_slice(&cloud.point_in_vehicle[row..row + cols]);
            ranges.extend_from_slice(&cloud.range_m[row..row + cols]);
        }
        for wrap in [false, true] {
            let view = GridView { points: &points, ranges: &ranges, rows, cols, wrap, max_col_gap: 2 };
            let params = FeatureParams::default();
            let mut got = Features::default();
            compute_features(&view, &params, &mut got);
            for (i, &(n, n_rho, g_rho)) in reference(&view, &params).iter().enumerate() {
                assert!((got.normal[i] - n).abs().max_element() <= 2e-6, "{rows} x {cols}, cell {i}");
                assert!((got.n_rho[i] - n_rho).abs() <= 2e-6, "{rows} x {cols}, cell {i}");
                assert!((got.g_rho[i] - g_rho).abs() <= 2e-6, "{rows} x {cols}, cell {i}");
                featured += usize::from(n_rho > 0.5);
            }
            cells += rows * cols;
        }
    }
    // Most of the cut cells have features: the comparison is not between zeros.
    assert!(featured * 2 > cells, "{featured} of {cells}");
}

#[test]
fn lane_wise_features_equal_the_per_cell_definition() {
    /// Largest difference allowed in a feature (all lie in [-1, 1]).
    const TOL: f32 = 2e-6;
    let (mut checked, mut worst) = (0, 0f32);
    for (drop, seed, spinning) in [(0.0, 1, true), (0.1, 2, true), (0.4, 3, true), (0.2, 4, false)] {
        let cloud = frame(drop, seed, spinning);
        assert_eq!(detect_wrap(&cloud.point_in_vehicle, cloud.rows, cloud.cols), spinning);
        for (gap, params) in [
            (2, FeatureParams::default()),
            (
                3,
                FeatureParams {
                    min_valid_pairs: 3,
                    max_neighbour_distance_m: 2.0,
                    occlusion_ratio: 0.1,
                    upper_occlusion_ratio: 0.05,
                    lateral_occlusion_ratio: 0.2,
                },
            ),
            (1, FeatureParams { upper_occlusion_ratio: 0.0, ..FeatureParams::default() }),
        ] {
            let mut nitsch = crate::NitschParams::default();
            nitsch.neighbours.max_col_gap = gap;
            let classifier = crate::Nitsch::new(nitsch).expect("valid parameters");
            let view = classifier.view(&cloud);
            let (mut fast, mut generic) = (Features::default(), Features::default());
            compute_features(&view, &params, &mut fast);
            // The portable variant too (the dispatcher above may have picked AVX-512 or AVX2).
            compute_features_body::<false>(&view, &params, &mut generic);
            assert_eq!(
                fast.g_rho.iter().map(|g| g.to_bits()).collect::<Vec<_>>(),
                generic.g_rho.iter().map(|g| g.to_bits()).collect::<Vec<_>>()
            );
            // The pair sums of all 16 lanes at once (the AVX-512 variant's) and by halves: the same bits.
            let mut wide = Features::default();
            compute_features_body::<true>(&view, &params, &mut wide);
            assert_eq!(
                wide.g_rho.iter().map(|g| g.to_bits()).collect::<Vec<_>>(),
                generic.g_rho.iter().map(|g| g.to_bits()).collect::<Vec<_>>()
            );
            assert_eq!(wide.normal, generic.normal);
            // And the AVX2 variant where the dispatcher picked AVX-512.
            #[cfg(target_arch = "x86_64")]
            if crate::cpu::avx2_bmi() {
                let mut avx2 = Features::default();
                // SAFETY: the CPU supports AVX2 (checked just above).
                #[allow(unsafe_code)]
                unsafe {
                    super::compute_features_avx2(&view, &params, &mut avx2)
                };
                assert_eq!(
                    avx2.g_rho.iter().map(|g| g.to_bits()).collect::<Vec<_>>(),
                    generic.g_rho.iter().map(|g| g.to_bits()).collect::<Vec<_>>()
                );
            }
            let want = reference(&view, &params);
            for (i, &(n, n_rho, g_rho)) in want.iter().enumerate() {
                let got = (fast.normal[i], fast.n_rho[i], fast.g_rho[i]);
                // Shared triangles rounded as computed from one corner: the same features
                // within `TOL` (largest seen 6e-7), and the same cells with and without features.
                assert!(
                    (got.0 - n).abs().max_element() <= TOL,
                    "normal of cell {i}: {} vs {n} (drop {drop}, gap {gap})",
                    got.0
                );
                assert!((got.1 - n_rho).abs() <= TOL, "n_rho of cell {i}: {} vs {n_rho}", got.1);
                assert!((got.2 - g_rho).abs() <= TOL, "g_rho of cell {i}: {} vs {g_rho}", got.2);
                assert_eq!(got.1 == 0.0, n_rho == 0.0, "features of cell {i}");
                worst = worst.max((got.2 - g_rho).abs());
                checked += usize::from(n_rho > 0.5);
            }
        }
    }
    // Most cells are real ground with features, not trivially equal zeros.
    assert!(checked > 20_000, "{checked}");
    eprintln!("largest g_rho difference {worst:e}");
}
