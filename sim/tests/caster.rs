//! Caster tests: the production BVH backend against the parry reference on a random scene,
//! watertightness on grid edges and vertices, analytic plane distances, and thread-count
//! independence of `cast_all`.

use crate::common;

use glam::Vec3;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use sim::cast::watertight::intersect_triangle;
use sim::cast::{BvhCaster, BvhLayout, BvhOptions, Caster, Hit, ParryCaster, Ray, fixture};
use sim::{SceneMesh, SemanticClass, Surface};

#[cfg(feature = "gpu")]
use common::{assert_agrees, gpu_caster, gpu_test_rays, spinning_beams};
use common::{random_rays, random_scene};

fn compare(mesh: &SceneMesh, rays: &[Ray], a: &[Option<Hit>], b: &[Option<Hit>]) -> (usize, usize) {
    let mut hits = 0;
    let mut ties = 0;
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        match (x, y) {
            (None, None) => {}
            (Some(x), Some(y)) => {
                hits += 1;
                assert!((x.t - y.t).abs() <= 1e-4, "ray {i}: t {} vs {}", x.t, y.t);
                if x.triangle != y.triangle {
                    // Only a genuine tie may pick another triangle: both triangles at the same distance.
                    let tx = intersect_triangle(&rays[i], mesh.triangle(x.triangle as usize)).unwrap();
                    let ty = intersect_triangle(&rays[i], mesh.triangle(y.triangle as usize)).unwrap();
                    assert!((tx - ty).abs() <= 1e-4, "ray {i}: triangles {} and {} not tied", x.triangle, y.triangle);
                    ties += 1;
                }
            }
            _ => panic!("ray {i} {:?}: hit/miss differ: {x:?} vs {y:?}", rays[i]),
        }
    }
    (hits, ties)
}

#[test]
fn bvh_matches_parry_on_random_scene() {
    let mesh = random_scene(7);
    let rays = random_rays(11, 100_000);
    let reference = ParryCaster::new(&mesh);
    let expected: Vec<Option<Hit>> = rays.iter().map(|r| reference.cast(r)).collect();
    for options in [
        BvhOptions::default(),
        BvhOptions { coherent: false, packet_rays: 0, ..BvhOptions::default() },
        BvhOptions { coherent: true, packet_rays: 0, ..BvhOptions::default() },
        BvhOptions { layout: BvhLayout::Binary, ..BvhOptions::default() },
        BvhOptions { layout: BvhLayout::Wide, max_prims_per_leaf: 3, ..BvhOptions::default() },
    ] {
        let bvh = BvhCaster::with_options(&mesh, options);
        let got = bvh.cast_all(&rays);
        let (hits, ties) = compare(&mesh, &rays, &got, &expected);
        assert!(hits > 20_000 && hits < 90_000, "{options:?}: {hits} hits is not a mixed hit/miss set");
        assert!(ties < 100, "{options:?}: {ties} ties");
    }
}

/// A regular grid of 1 m cells on the plane `z = slope_x * x + slope_y * y` (vertices exactly
/// representable for slopes that are short binary fractions).
fn plane_grid(n: usize, slope_x: f32, slope_y: f32) -> SceneMesh {
    let mut m = SceneMesh::new();
    let half = n as f32 / 2.0;
    m.push_heightfield(
        (-half, -half),
        1.0,
        (n, n),
        |x, y| slope_x * x + slope_y * y,
        |_, _| Surface::stuff(SemanticClass::ROAD),
    );
    m
}

/// Rays exactly through grid vertices, edge midpoints (axis-aligned and diagonal edges), and along
/// grid lines (direction inside the vertical plane of a line of edges), from many origins.
fn edge_rays(n: usize, slope_x: f32, slope_y: f32, count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let lim = n as i32 / 2 - 2;
    let mut rays = Vec::with_capacity(count);
    while rays.len() < count {
        let (i, j) = (rng.random_range(-lim..lim) as f32, rng.random_range(-lim..lim) as f32);
        let (tx, ty) = match rng.random_range(0..4) {
            0 => (i, j),
            1 => (i + 0.5, j),
            2 => (i, j + 0.5),
            _ => (i + 0.5, j + 0.5),
        };
        let target = Vec3::new(tx, ty, slope_x * tx + slope_y * ty);
        let h = rng.random_range(0.3..25.0);
        let origin = match rng.random_range(0..4) {
            // Along the grid line y = ty (azimuth exactly 0 or 180 deg).
            0 => Vec3::new(tx + rng.random_range(-30.0..30.0), ty, target.z + h),
            // Along the grid line x = tx.
            1 => Vec3::new(tx, ty + rng.random_range(-30.0..30.0), target.z + h),
            // Along a diagonal line x - y = const (the shared diagonals of the cells).
            2 => {
                let s = rng.random_range(-20.0..20.0f32).round();
                Vec3::new(tx + s, ty + s, target.z + h)
            }
            _ => Vec3::new(tx + rng.random_range(-30.0..30.0), ty + rng.random_range(-30.0..30.0), target.z + h),
        };
        let d = target - origin;
        // Skip rays nearly parallel to the plane (incidence beyond ~84 deg): there the distance is
        // ill-conditioned in f32 (and a LiDAR drops such grazing returns anyway).
        let normal = Vec3::new(-slope_x, -slope_y, 1.0).normalize();
        if d.length() < 1e-3 || d.normalize().dot(normal).abs() < 0.1 {
            continue;
        }
        rays.push(Ray { origin, dir: d.normalize(), t_max: f32::INFINITY });
    }
    rays
}

/// Distance along `ray` to the plane `z = sx x + sy y`.
fn plane_t(ray: &Ray, sx: f32, sy: f32) -> f64 {
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let (sx, sy) = (sx as f64, sy as f64);
    -(o.z - sx * o.x - sy * o.y) / (d.z - sx * d.x - sy * d.y)
}

fn cos_incidence(ray: &Ray, sx: f32, sy: f32) -> f64 {
    ray.dir.as_dvec3().dot(glam::DVec3::new(-sx as f64, -sy as f64, 1.0).normalize()).abs()
}

fn assert_no_leaks(caster: &dyn Caster, rays: &[Ray], sx: f32, sy: f32, name: &str) {
    let hits = caster.cast_all(rays);
    let mut leaks = 0;
    for (r, h) in rays.iter().zip(&hits) {
        let expected = plane_t(r, sx, sy);
        match h {
            // f32 distance error grows as 1 / cos(incidence) (at most 10x here); a leak is metres off.
            Some(h) if (h.t as f64 - expected).abs() <= 1e-4 * expected.max(1.0) / cos_incidence(r, sx, sy) => {}
            _ => {
                leaks += 1;
                eprintln!("{name}: leak {r:?}: {h:?}, expected t = {expected}");
            }
        }
    }
    assert_eq!(leaks, 0, "{name}: {leaks} of {} rays leaked", rays.len());
}

/// Fans of 16 rays sharing an origin above a grid vertex, all inside the vertical plane of a grid
/// line (along x, along y, or along the cells' shared diagonals), at 16 depression angles: every ray
/// of a fan runs exactly over a line of shared edges and vertices (the case `cast_batch` traverses
/// as a fan).
fn edge_fans(n: usize, slope_x: f32, slope_y: f32, fans: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let lim = n as i32 / 4;
    let mut rays = Vec::with_capacity(fans * 16);
    for _ in 0..fans {
        let (i, j) = (rng.random_range(-lim..lim) as f32, rng.random_range(-lim..lim) as f32);
        let origin = Vec3::new(i, j, slope_x * i + slope_y * j + rng.random_range(0.5..10.0));
        let (dx, dy) =
            [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (1.0, 1.0), (-1.0, -1.0)][rng.random_range(0..6)];
        let normal = Vec3::new(-slope_x, -slope_y, 1.0).normalize();
        for k in 0..16 {
            let dir = Vec3::new(dx, dy, -0.15 - 0.1 * k as f32).normalize();
            let ray = Ray { origin, dir, t_max: f32::INFINITY };
            let p = origin + plane_t(&ray, slope_x, slope_y) as f32 * dir;
            let inside = p.x.abs().max(p.y.abs()) < n as f32 / 2.0 - 1.0;
            if inside && dir.dot(normal).abs() >= 0.1 {
                rays.push(ray);
            }
        }
    }
    rays
}

#[test]
fn grid_edges_and_vertices_never_leak() {
    for (sx, sy) in [(0.0, 0.0), (0.25, -0.125)] {
        let mesh = plane_grid(96, sx, sy);
        let rays = edge_rays(96, sx, sy, 150_000, 5);
        assert_no_leaks(&BvhCaster::new(&mesh), &rays, sx, sy, "bvh");
        let wide = BvhOptions { layout: BvhLayout::Wide, max_prims_per_leaf: 3, ..BvhOptions::default() };
        assert_no_leaks(&BvhCaster::with_options(&mesh, wide), &rays, sx, sy, "bvh-wide");
        assert_no_leaks(&ParryCaster::new(&mesh), &rays[..50_000], sx, sy, "parry");
        let fans = edge_fans(96, sx, sy, 4000, 9);
        assert!(fans.len() > 20_000, "{} fan rays", fans.len());
        assert_no_leaks(&BvhCaster::new(&mesh), &fans, sx, sy, "bvh-fans");
        assert_no_leaks(&ParryCaster::new(&mesh), &fans[..10_000], sx, sy, "parry-fans");
    }
}

#[test]
fn ideal_rays_hit_the_analytic_point_on_a_plane() {
    let (sx, sy) = (0.1, 0.05);
    let mesh = plane_grid(64, sx, sy);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let rays: Vec<Ray> = (0..20_000)
        .map(|_| {
            let target = Vec3::new(rng.random_range(-30.0..30.0), rng.random_range(-30.0..30.0), 0.0);
            let target = Vec3::new(target.x, target.y, sx * target.x + sy * target.y);
            let origin = Vec3::new(rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0), 6.0);
            Ray { origin, dir: (target - origin).normalize(), t_max: 200.0 }
        })
        .collect();
    for caster in [&BvhCaster::new(&mesh) as &dyn Caster, &ParryCaster::new(&mesh)] {
        for (r, h) in rays.iter().zip(caster.cast_all(&rays)) {
            let h = h.expect("ray hits the plane");
            let p = (r.origin + h.t * r.dir).as_dvec3();
            let on_plane = sx as f64 * p.x + sy as f64 * p.y;
            assert!((p.z - on_plane).abs() < 1e-4, "hit {p} off the plane by {}", p.z - on_plane);
            assert!((h.t as f64 - plane_t(r, sx, sy)).abs() < 1e-4);
        }
    }
    // Beyond t_max: no hit.
    let far = Ray { origin: Vec3::new(0.0, 0.0, 6.0), dir: Vec3::new(1.0, 0.0, -0.1).normalize(), t_max: 10.0 };
    assert_eq!(BvhCaster::new(&mesh).cast(&far), None);
    assert_eq!(ParryCaster::new(&mesh).cast(&far), None);
}

/// Spinning-LiDAR rays (fans of beams sharing an origin, the coherent case `cast_batch` traverses
/// as fans) from a few origins: `rows x cols` per origin, row-major.
/// `offset_m` > 0 gives every beam its own origin within a few centimetres (per-laser offsets).
fn lidar_rays(origins: &[Vec3], row_step: usize, col_step: usize, t_max: f32, offset_m: f32) -> Vec<Ray> {
    let mut rays = Vec::new();
    for &origin in origins {
        for r in (0..fixture::LIDAR_ROWS).step_by(row_step) {
            for c in (0..fixture::LIDAR_COLS).step_by(col_step) {
                let dir = fixture::beam_dir(r, c);
                let jitter = offset_m * Vec3::new(dir.y, -dir.x, ((r * 7 + c * 3) % 5) as f32 - 2.0);
                rays.push(Ray { origin: origin + jitter, dir, t_max });
            }
        }
    }
    rays
}

#[test]
fn bvh_fans_match_parry_on_lidar_rays() {
    let mesh = random_scene(8);
    let origins = [Vec3::new(0.5, 0.25, 3.0), Vec3::new(-10.0, 7.0, 1.0)];
    let mut rays = lidar_rays(&origins, 4, 2, f32::INFINITY, 0.0);
    rays.extend(lidar_rays(&origins[..1], 8, 2, 60.0, 0.03));
    let reference = ParryCaster::new(&mesh);
    let expected: Vec<Option<Hit>> = rays.iter().map(|r| reference.cast(r)).collect();
    for (packet_rays, coherent) in [(0, true), (4, false), (8, true), (16, false), (16, true), (32, false)] {
        let bvh = BvhCaster::with_options(&mesh, BvhOptions { packet_rays, coherent, ..BvhOptions::default() });
        let (hits, ties) = compare(&mesh, &rays, &bvh.cast_all(&rays), &expected);
        assert!(hits > 25_000 && hits < 80_000, "packet_rays {packet_rays}: {hits} hits of {}", rays.len());
        assert!(ties < 100, "{ties} ties");
    }
}

/// The closest hit by testing every triangle: the smallest `t`, of equal `t` the lowest mesh index.
fn brute_force(mesh: &SceneMesh, ray: &Ray) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for i in 0..mesh.len() {
        if let Some(t) = intersect_triangle(ray, mesh.triangle(i))
            && best.is_none_or(|b| t < b.t)
        {
            best = Some(Hit { t, triangle: i as u32 });
        }
    }
    best
}

/// Every traversal of the 4-wide tree (fans of 4 to 32 rays, one ray at a time, with and without the
/// previous hit as a seed) reports exactly the hit of the brute-force loop over all triangles, `t`
/// bit for bit and the same triangle, on coherent LiDAR fans (one origin and per-laser origins) and on
/// random rays: the leaves' four-triangle tests and the fans' interval tests change nothing.
#[test]
fn bvh_hits_equal_brute_force_bit_for_bit() {
    let mesh = random_scene(31);
    let mut rays = lidar_rays(&[Vec3::new(0.5, 0.25, 3.0)], 8, 8, f32::INFINITY, 0.0);
    rays.extend(lidar_rays(&[Vec3::new(-6.0, 4.0, 1.5)], 16, 8, 40.0, 0.03));
    rays.extend(random_rays(12, 2_000));
    let expected: Vec<Option<(u32, u32)>> =
        rays.iter().map(|r| brute_force(&mesh, r).map(|h| (h.t.to_bits(), h.triangle))).collect();
    let hits = expected.iter().filter(|h| h.is_some()).count();
    assert!(hits > 2_000 && hits < rays.len() - 500, "{hits} hits of {}: not a mixed set", rays.len());
    for (layout, packet_rays, coherent) in [
        (BvhLayout::Eight, 0, false),
        (BvhLayout::Eight, 0, true),
        (BvhLayout::Eight, 4, false),
        (BvhLayout::Eight, 8, true),
        (BvhLayout::Eight, 16, false),
        (BvhLayout::Eight, 32, false),
        (BvhLayout::Four, 0, false),
        (BvhLayout::Four, 16, false),
    ] {
        let bvh = BvhCaster::with_options(&mesh, BvhOptions { layout, packet_rays, coherent, ..BvhOptions::default() });
        let bits = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.triangle));
        let batch: Vec<_> = bvh.cast_all(&rays).into_iter().map(bits).collect();
        let single: Vec<_> = rays.iter().map(|r| bits(bvh.cast(r))).collect();
        for (i, want) in expected.iter().enumerate() {
            assert_eq!(
                batch[i], *want,
                "{layout:?}, packet_rays {packet_rays}, coherent {coherent}: ray {i} {:?}",
                rays[i]
            );
            assert_eq!(single[i], *want, "one ray at a time: ray {i} {:?}", rays[i]);
        }
    }
}

/// Small meshes, where the root is a leaf (one triangle: obvhs does not collapse trees this small)
/// or has few children: every layout and fan size gives the brute-force loop's hits, bit for bit.
#[test]
fn small_meshes_hit_as_the_brute_force_loop() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    for count in [1usize, 2, 3, 5, 8, 9, 12, 17, 40, 100] {
        let mut mesh = SceneMesh::new();
        for _ in 0..count {
            let c = Vec3::new(rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0), rng.random_range(-1.0..1.0));
            let half = Vec3::splat(rng.random_range(0.3..2.0));
            mesh.push_oriented_box(
                glam::Affine3A::from_translation(c),
                -half,
                half,
                Surface::object(SemanticClass::CAR, 1),
            );
        }
        // Boxes have 12 triangles; keep the first `count`.
        let mut small = SceneMesh::new();
        for i in 0..count {
            let corners = mesh.triangle(i).map(|p| small.push_vertex(p));
            small.push_triangle(corners, Surface::object(SemanticClass::CAR, 1));
        }
        let mut rays = lidar_rays(&[Vec3::new(0.2, 0.1, 0.5)], 8, 16, f32::INFINITY, 0.0);
        rays.extend(random_rays(count as u64, 500).into_iter().map(|r| Ray { origin: r.origin * 0.15, ..r }));
        // Aimed at each triangle's centre, and at its corners (shared with its box's neighbours).
        for i in 0..count {
            let [a, b, c] = small.triangle(i);
            for target in [(a + b + c) / 3.0, a, (a + b) * 0.5] {
                let origin = Vec3::new(rng.random_range(-9.0..9.0), rng.random_range(-9.0..9.0), 5.0);
                rays.push(Ray { origin, dir: (target - origin).normalize(), t_max: f32::INFINITY });
            }
        }
        let expected: Vec<Option<(u32, u32)>> =
            rays.iter().map(|r| brute_force(&small, r).map(|h| (h.t.to_bits(), h.triangle))).collect();
        assert!(expected.iter().any(Option::is_some), "{count} triangles: no ray hits");
        for layout in [BvhLayout::Eight, BvhLayout::Four] {
            for packet_rays in [0, 16] {
                let bvh = BvhCaster::with_options(&small, BvhOptions { layout, packet_rays, ..BvhOptions::default() });
                let got: Vec<_> =
                    bvh.cast_all(&rays).into_iter().map(|h| h.map(|h| (h.t.to_bits(), h.triangle))).collect();
                assert_eq!(got, expected, "{count} triangles, {layout:?}, packet_rays {packet_rays}");
            }
        }
    }
}

#[test]
fn cast_all_is_identical_on_one_and_two_threads() {
    let mesh = random_scene(21);
    // A spinning-LiDAR pattern (coherent rays, where cast_batch reuses the previous hit).
    let mut rays = lidar_rays(&[Vec3::new(0.5, 0.25, 3.0)], 4, 4, 80.0, 0.02);
    rays.extend(random_rays(4, 10_000));
    let caster = BvhCaster::new(&mesh);
    let run = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap().install(|| caster.cast_all(&rays));
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    let hits = one.iter().filter(|h| h.is_some()).count();
    assert!(hits > 10_000, "{hits} hits");
    // And the batched (coherent) results equal the one-ray-at-a-time results.
    let single: Vec<Option<Hit>> = rays.iter().map(|r| caster.cast(r)).collect();
    let (_, ties) = compare(&mesh, &rays, &one, &single);
    assert!(ties < 50, "{ties} ties");
}

#[test]
fn empty_scene_never_hits() {
    let mesh = SceneMesh::new();
    let r = Ray { origin: Vec3::ZERO, dir: Vec3::X, t_max: f32::INFINITY };
    assert_eq!(BvhCaster::new(&mesh).cast(&r), None);
    assert_eq!(ParryCaster::new(&mesh).cast(&r), None);
    assert_eq!(BvhCaster::new(&mesh).cast_all(&[r; 3]), vec![None; 3]);
}

/// The wgpu backend against the production BVH on the random scene and on a spinning sensor's
/// rays (skipped without an adapter, see [`gpu_caster`]).
#[cfg(feature = "gpu")]
#[test]
fn gpu_matches_bvh() {
    use sim::cast::gpu::GpuOptions;
    let mesh = random_scene(7);
    let Some(gpu) = gpu_caster(&mesh, GpuOptions::default()) else { return };
    eprintln!("adapter: {}", gpu.adapter());
    let rays = gpu_test_rays();
    let expected = BvhCaster::new(&mesh).cast_all(&rays);
    let got = gpu.cast_all(&rays);
    let (hits, ties, disagree) = assert_agrees(&mesh, &rays, &expected, &got);
    let stats = gpu.stats();
    eprintln!(
        "{} rays: {hits} hits, {ties} ties, {disagree} hit/miss disagreements, {} CPU fallbacks, {stats:?}",
        rays.len(),
        gpu.cpu_fallbacks()
    );
    assert_eq!(
        (stats.rays, stats.upload_bytes, stats.readback_bytes),
        (rays.len() as u64, 32 * rays.len() as u64, 8 * rays.len() as u64)
    );
    // Buffers are kept: a second call gives the same hits.
    assert_eq!(gpu.cast_all(&rays), got);
    // Single rays and an empty scene.
    assert_eq!(gpu.cast(&rays[0]).map(|h| h.triangle), expected[0].map(|h| h.triangle));
    let empty = gpu_caster(&SceneMesh::new(), GpuOptions::default()).expect("an adapter");
    assert_eq!(empty.cast_all(&rays[..10]), vec![None; 10]);
}

/// A device with a small storage-binding limit: the scene split over 2 node and 2 to 4 triangle
/// bindings and the rays over many batches, two in flight, give the same hits as one binding.
#[cfg(feature = "gpu")]
#[test]
fn gpu_splits_scene_and_rays_over_bindings() {
    use sim::cast::gpu::{GpuBvh, GpuOptions};
    let mesh = random_scene(7);
    // The BVH2: the CWBVH's nodes are too few to split while its triangles fit (`gpu_cwbvh.rs`).
    let bvh2 = GpuOptions { bvh: GpuBvh::Bvh2, ..Default::default() };
    let Some(whole) = gpu_caster(&mesh, bvh2) else { return };
    let (node_bytes, tri_bytes) = whole.scene_bytes();
    // Bindings of a power of two of nodes that holds half of them or more: exactly 2 node bindings.
    let limit = (node_bytes / 2).next_power_of_two().max(tri_bytes.div_ceil(4).next_power_of_two() * 3 / 2);
    let split = gpu_caster(&mesh, GpuOptions { max_binding_bytes: Some(limit), ..bvh2 }).expect("an adapter");
    let (nodes, tris) = split.bindings_used();
    eprintln!("limit {limit} B: scene {node_bytes} + {tri_bytes} B in {nodes} node and {tris} triangle bindings");
    assert!(nodes == 2 && (2..=4).contains(&tris), "{nodes} node and {tris} triangle bindings");
    let rays = gpu_test_rays();
    let got = split.cast_all(&rays);
    let batches = split.stats().batches;
    assert!(batches >= (rays.len() as u64 * 32).div_ceil(limit), "{batches} batches");
    assert_eq!(got, whole.cast_all(&rays));
    let expected = BvhCaster::new(&mesh).cast_all(&rays);
    assert_agrees(&mesh, &rays, &expected, &got);
    // A scene that needs more bindings than the shader has is refused with the sizes.
    let err = sim::cast::gpu::GpuCaster::with_options(
        &mesh,
        GpuOptions { max_binding_bytes: Some(256), ..Default::default() },
    )
    .err()
    .expect("too large");
    assert!(err.to_string().contains("bytes"), "{err}");
}

/// Rays cast under a resident key are uploaded once: later calls with the key copy them on the
/// device and give the same hits; another key uploads again.
#[cfg(feature = "gpu")]
#[test]
fn gpu_keeps_resident_rays_on_the_device() {
    use sim::cast::gpu::GpuOptions;
    let mesh = random_scene(7);
    let Some(gpu) = gpu_caster(&mesh, GpuOptions::default()) else { return };
    let rays = gpu_test_rays();
    let plain = gpu.cast_all(&rays);
    let up0 = gpu.stats().upload_bytes;
    let key = sim::cast::new_ray_set_key();
    for _ in 0..3 {
        assert_eq!(gpu.cast_all_resident(key, &rays), plain);
    }
    let s = gpu.stats();
    assert_eq!((s.resident_uploads, s.upload_bytes - up0), (1, 32 * rays.len() as u64));
    assert_eq!(gpu.cast_all_resident(sim::cast::new_ray_set_key(), &rays[..1000]), plain[..1000].to_vec());
    assert_eq!(gpu.stats().resident_uploads, 2);
    // CPU backends ignore the key.
    let cpu = BvhCaster::new(&mesh);
    assert_eq!(cpu.cast_all_resident(key, &rays[..1000]), cpu.cast_all(&rays[..1000]));
}

/// A spinning sensor's beams (32 rings x 1,024 columns, each column's pose blended from the key
/// poses every 8 columns) cast from poses with the rays made on the device: the same hits as the host making the rays
/// ([`BeamSet::rays`]) within the agreement of [`assert_agrees`]; the beams go up once, then only
/// poses; a small binding limit splits the frames into chunks with the same hits.
#[cfg(feature = "gpu")]
#[test]
fn gpu_makes_rays_from_beams_and_poses() {
    use sim::cast::gpu::GpuOptions;
    let mesh = random_scene(7);
    let Some(gpu) = gpu_caster(&mesh, GpuOptions::default()) else { return };
    let frames = 5;
    let (set, poses) = spinning_beams(frames);
    let (beams, keys) = (set.beams().len(), set.poses_per_frame());
    let rays = set.rays(&poses);
    assert_eq!(rays.len(), frames * 32 * 1024);
    let expected = BvhCaster::new(&mesh).cast_all(&rays);
    let up0 = gpu.stats().upload_bytes;
    let got = gpu.cast_beams(&set, &poses);
    let (hits, ties, disagree) = assert_agrees(&mesh, &rays, &expected, &got);
    let up1 = gpu.stats().upload_bytes - up0;
    eprintln!("{} rays from beams: {hits} hits, {ties} ties, {disagree} disagreements, {up1} B up", rays.len());
    // The beams (48 B each) once and the poses (48 B each), not 32 B per ray.
    assert_eq!(up1, 48 * beams as u64 + 48 * poses.len() as u64);
    // Again: only the poses go up.
    assert_eq!(gpu.cast_beams(&set, &poses), got);
    assert_eq!(gpu.stats().upload_bytes - up0 - up1, 48 * poses.len() as u64);
    // Bindings that hold the beams and one or two frames' poses: the frames go in chunks.
    let limit = 48 * beams as u64 + 48 * keys as u64 * 3 / 2;
    let small =
        gpu_caster(&mesh, GpuOptions { max_binding_bytes: Some(limit), ..Default::default() }).expect("an adapter");
    assert_eq!(small.cast_beams(&set, &poses), got);
    // Bindings too small for the beams: the rays are made on the host instead, same hits.
    let tiny = gpu_caster(&mesh, GpuOptions { max_binding_bytes: Some(32 * beams as u64), ..Default::default() });
    let tiny = tiny.expect("an adapter");
    let on_host = tiny.cast_beams(&set, &poses);
    assert_agrees(&mesh, &rays, &expected, &on_host);
}
