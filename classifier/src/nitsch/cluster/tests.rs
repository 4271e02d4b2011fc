//! The grid-order clustering against the per-cell definition it replaced (kept here as the
//! reference: every candidate links to its 4 forward direct neighbours, or to all neighbours
//! the search finds where a direct one is missing), on damaged synthetic frames.

use super::rules::floor_isize;
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
            // The portable variant too (the dispatcher above may have picked AVX-512 or AVX2), and the
            // rules of both.
            let mut portable = ClusterWorkspace::default();
            let inputs = Inputs {
                view: &view,
                valid: None,
                search: None,
                candidate: &candidate,
                normal: &nitsch.features.normal,
            };
            cluster_body(inputs, &params.clustering, &mut portable);
            assert_eq!(portable.parent, fast.parent);
            // And the AVX2 variant where the dispatcher picked AVX-512.
            #[cfg(target_arch = "x86_64")]
            if crate::cpu::avx2_bmi() {
                let mut avx2 = ClusterWorkspace::default();
                // SAFETY: the CPU supports AVX2, BMI1 and BMI2 (checked just above).
                #[allow(unsafe_code)]
                unsafe {
                    super::cluster_avx2(inputs, &params.clustering, &mut avx2)
                };
                assert_eq!(avx2.parent, fast.parent);
            }
            // With the features' own search tables, as the classifier runs it.
            let mut searched = ClusterWorkspace::default();
            let (valid, search) = (nitsch.features.valid(), nitsch.features.search());
            let normal = &nitsch.features.normal;
            cluster_candidates_searched(&view, valid, search, &candidate, normal, &params.clustering, &mut searched);
            assert_eq!(searched.parent, fast.parent);
            let (mut ground, mut ground_portable) = (vec![false; cloud.len()], vec![false; cloud.len()]);
            fast.decide(view.points, fast.returns(), &params.clustering, &mut ground);
            portable.decide_body(view.points, portable.returns(), &params.clustering, &mut ground_portable);
            assert_eq!(ground, ground_portable);
        }
    }
    // Damaged frames split into many clusters: the comparison is not between two single blobs.
    assert!(clusters_seen > 100, "{clusters_seen}");
}
