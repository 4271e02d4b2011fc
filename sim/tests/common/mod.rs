//! Helpers shared by the caster tests: the random scene and rays, and for the GPU backend the
//! caster (skipped without an adapter), its test rays and beams, and the agreement with the CPU.
#![allow(dead_code)] // Each test file uses some of them.

use glam::{Affine3A, Quat, Vec3};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use sim::cast::Ray;
use sim::{SceneMesh, SemanticClass, Surface};

/// Random scene: a bumpy 64 x 64-cell heightfield and 40 random (rotated) boxes.
pub fn random_scene(seed: u64) -> SceneMesh {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut m = SceneMesh::new();
    let bumps: Vec<(f32, f32, f32)> = (0..12)
        .map(|_| (rng.random_range(-30.0..30.0), rng.random_range(-30.0..30.0), rng.random_range(-2.0..3.0)))
        .collect();
    m.push_heightfield(
        (-32.0, -32.0),
        1.0,
        (64, 64),
        |x, y| bumps.iter().map(|&(bx, by, h)| h * (-((x - bx).powi(2) + (y - by).powi(2)) / 40.0).exp()).sum(),
        |_, _| Surface::stuff(SemanticClass::TERRAIN),
    );
    for i in 0..40 {
        let c = Vec3::new(rng.random_range(-28.0..28.0), rng.random_range(-28.0..28.0), rng.random_range(-1.0..2.0));
        let half = Vec3::new(rng.random_range(0.3..4.0), rng.random_range(0.3..4.0), rng.random_range(0.3..3.0));
        let rot =
            Quat::from_rotation_z(rng.random_range(0.0..6.3)) * Quat::from_rotation_x(rng.random_range(-0.3..0.3));
        m.push_oriented_box(
            Affine3A::from_rotation_translation(rot, c),
            -half,
            half,
            Surface::object(SemanticClass::CAR, i + 1),
        );
    }
    m
}

/// Random rays over the random scene, a fifth of them with a finite range.
pub fn random_rays(seed: u64, n: usize) -> Vec<Ray> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let origin =
                Vec3::new(rng.random_range(-40.0..40.0), rng.random_range(-40.0..40.0), rng.random_range(-1.0..12.0));
            let dir = loop {
                let d =
                    Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..0.6));
                if d.length() > 0.1 && d.length() <= 1.0 {
                    break d.normalize();
                }
            };
            let t_max = if rng.random_range(0.0..1.0) < 0.2 { rng.random_range(1.0..30.0) } else { f32::INFINITY };
            Ray { origin, dir, t_max }
        })
        .collect()
}

/// Random rays and a sensor 4 m above the random scene's terrain: 32 rings x 1,024 columns.
pub fn gpu_test_rays() -> Vec<Ray> {
    let mut rays = random_rays(11, 60_000);
    for ring in 0..32 {
        let elevation = (-25.0f32 + ring as f32 * 1.2).to_radians();
        for col in 0..1024 {
            let azimuth = col as f32 * std::f32::consts::TAU / 1024.0;
            let dir = Vec3::new(elevation.cos() * azimuth.cos(), elevation.cos() * azimuth.sin(), elevation.sin());
            rays.push(Ray { origin: Vec3::new(0.3, -0.2, 4.0), dir, t_max: 120.0 });
        }
    }
    rays
}

/// A spinning sensor's beams (32 rings x 1,024 columns, each column's pose blended from the key
/// poses every 8 columns, and one after the last) and the key poses of `frames` frames: each frame
/// drives 1.5 m and turns, each key pose a little further along.
pub fn spinning_beams(frames: usize) -> (sim::cast::BeamSet, Vec<Affine3A>) {
    let (rings, cols) = (32usize, 1024usize);
    let mut beams = Vec::new();
    for ring in 0..rings {
        let elevation = (-25.0f32 + ring as f32 * 1.2).to_radians();
        for col in 0..cols {
            let azimuth = col as f32 * std::f32::consts::TAU / cols as f32;
            let dir = Vec3::new(elevation.cos() * azimuth.cos(), elevation.cos() * azimuth.sin(), elevation.sin());
            beams.push(sim::cast::Beam {
                origin_in_sensor: Vec3::new(0.05, 0.0, 0.0),
                dir_in_sensor: dir,
                t_max_m: 120.0,
                pose: (col / 8) as u32,
                pose_blend: (col % 8) as f32 / 8.0,
                side_offset: 0.0,
            });
        }
    }
    let keys = cols / 8 + 1;
    let poses = (0..frames * keys)
        .map(|i| {
            let s = (i / keys) as f32 + (i % keys) as f32 / (keys - 1) as f32;
            Affine3A::from_translation(Vec3::new(0.3 + 1.5 * s, -0.2 + 0.1 * s, 4.0))
                * Affine3A::from_rotation_z(0.05 * s)
        })
        .collect();
    (sim::cast::BeamSet::new(beams, keys).expect("valid beams"), poses)
}

/// The GPU caster with `options`, or `None` (skipped, with a message) without an adapter unless
/// `GROUNDTRUTH_REQUIRE_GPU=1` (CI, on Mesa's lavapipe) makes that a failure.
#[cfg(feature = "gpu")]
pub fn gpu_caster(mesh: &SceneMesh, options: sim::cast::gpu::GpuOptions) -> Option<sim::cast::gpu::GpuCaster> {
    use sim::cast::gpu::{GpuCaster, GpuError};
    match GpuCaster::with_options(mesh, options) {
        Ok(g) => {
            assert_eq!(g.bvh(), options.bvh);
            Some(g)
        }
        Err(e @ GpuError::NoAdapter(_)) if std::env::var("GROUNDTRUTH_REQUIRE_GPU").as_deref() != Ok("1") => {
            eprintln!("GPU test skipped: {e}");
            None
        }
        Err(e) => panic!("GPU backend: {e}"),
    }
}

/// Asserts the GPU's hits `got` against the CPU's `expected`: hit / miss
/// identical on at least 99.99 % of the rays, distances within 1e-3 m, the same triangle except
/// where the two are tied. Returns (hits, ties, disagreements).
pub fn assert_agrees(
    mesh: &SceneMesh,
    rays: &[Ray],
    expected: &[Option<sim::cast::Hit>],
    got: &[Option<sim::cast::Hit>],
) -> (usize, usize, usize) {
    let (mut disagree, mut hits, mut ties) = (0usize, 0usize, 0usize);
    for (i, (x, y)) in expected.iter().zip(got).enumerate() {
        match (x, y) {
            (Some(x), Some(y)) => {
                hits += 1;
                assert!((x.t - y.t).abs() <= 1e-3, "ray {i}: t {} (cpu) vs {} (gpu)", x.t, y.t);
                if x.triangle != y.triangle {
                    let ty = sim::cast::watertight::intersect_triangle(&rays[i], mesh.triangle(y.triangle as usize));
                    assert!(
                        ty.is_some_and(|t| (t - x.t).abs() <= 1e-3),
                        "ray {i}: gpu triangle {} not tied",
                        y.triangle
                    );
                    ties += 1;
                }
            }
            (None, None) => {}
            _ => disagree += 1,
        }
    }
    let n = rays.len();
    assert_eq!(got.len(), n);
    assert!(hits > n / 3, "{hits} hits of {n}");
    assert!(disagree as f64 <= 1e-4 * n as f64, "{disagree} of {n} rays disagree on hit / miss");
    (hits, ties, disagree)
}
