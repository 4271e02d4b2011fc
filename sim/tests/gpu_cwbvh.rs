//! The GPU backend's compressed 8-wide BVH ([`GpuBvh::Cwbvh`]): its hits against the CPU's
//! production BVH on random rays, a spinning sensor and a flat grid's edges and vertices, the
//! scene split over two node bindings, rays made on the device, and the layout chosen through
//! `GROUNDTRUTH_GPU_BVH`. Without a Vulkan / Metal / DX12 adapter the tests are skipped with a
//! message, unless `GROUNDTRUTH_REQUIRE_GPU=1` (CI, on Mesa's lavapipe) makes that a failure.
#![cfg(feature = "gpu")]

use crate::common;

use glam::Vec3;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use sim::cast::gpu::{GpuBvh, GpuCaster, GpuError, GpuOptions};
use sim::cast::{BvhCaster, Caster, Hit, Ray};
use sim::{SceneMesh, SemanticClass, Surface};

use common::{assert_agrees, gpu_test_rays, random_scene, spinning_beams};

/// The caster in layout `bvh`, or `None` (skipped, with a message) without an adapter unless
/// `GROUNDTRUTH_REQUIRE_GPU=1`.
fn gpu_caster(mesh: &SceneMesh, bvh: GpuBvh, max_binding_bytes: Option<u64>) -> Option<GpuCaster> {
    common::gpu_caster(mesh, GpuOptions { bvh, max_binding_bytes, ..GpuOptions::default() })
}

/// The CWBVH (and the BVH2) against the CPU's BVH on random rays and a spinning sensor's, single
/// rays, scenes of two triangles and of one (a root whose only child is a leaf) and an empty scene.
#[test]
fn cwbvh_matches_bvh() {
    let mesh = random_scene(7);
    let Some(gpu) = gpu_caster(&mesh, GpuBvh::Cwbvh, None) else { return };
    eprintln!("adapter: {}, scene {:?} B", gpu.adapter(), gpu.scene_bytes());
    let rays = gpu_test_rays();
    let expected = BvhCaster::new(&mesh).cast_all(&rays);
    let got = gpu.cast_all(&rays);
    let (hits, ties, disagree) = assert_agrees(&mesh, &rays, &expected, &got);
    eprintln!("{} rays: {hits} hits, {ties} ties, {disagree} disagreements, {:?}", rays.len(), gpu.stats());
    assert_eq!(gpu.cpu_fallbacks(), 0);
    // The BVH2 too (the default is the CWBVH: `caster.rs` casts on it).
    let bvh2 = gpu_caster(&mesh, GpuBvh::Bvh2, None).expect("an adapter");
    assert_agrees(&mesh, &rays, &expected, &bvh2.cast_all(&rays));
    // Buffers are kept: a second call gives the same hits; single rays as in a batch.
    assert_eq!(gpu.cast_all(&rays), got);
    for i in [0, 1, 60_000, 70_000] {
        assert_eq!(gpu.cast(&rays[i]), got[i], "ray {i}");
    }
    // One triangle.
    let mut one = SceneMesh::new();
    one.push_quad(
        [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0)],
        Surface::stuff(SemanticClass::ROAD),
    );
    let down = |x: f32, y: f32| Ray { origin: Vec3::new(x, y, 2.0), dir: Vec3::NEG_Z, t_max: f32::INFINITY };
    let probes = [down(0.2, 0.3), down(-0.5, 0.6), down(3.0, 0.0)];
    let gpu_one = gpu_caster(&one, GpuBvh::Cwbvh, None).expect("an adapter");
    let got_one = gpu_one.cast_all(&probes);
    assert_eq!(got_one, BvhCaster::new(&one).cast_all(&probes));
    assert_eq!(got_one.iter().map(|h| h.map(|h| h.t)).collect::<Vec<_>>(), [Some(2.0), Some(2.0), None]);
    let mut single = SceneMesh::new();
    let v =
        [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)].map(|p| single.push_vertex(p));
    single.push_triangle(v, Surface::stuff(SemanticClass::ROAD));
    let gpu_single = gpu_caster(&single, GpuBvh::Cwbvh, None).expect("an adapter");
    assert_eq!(gpu_single.cast(&down(0.2, 0.2)), Some(Hit { t: 2.0, triangle: 0 }));
    assert_eq!(gpu_single.cast(&down(0.8, 0.8)), None);
    let empty = gpu_caster(&SceneMesh::new(), GpuBvh::Cwbvh, None).expect("an adapter");
    assert_eq!(empty.cast_all(&rays[..10]), vec![None; 10]);
}

/// Rays exactly through the vertices and edge midpoints of a flat 1 m grid (zero-thickness boxes,
/// quantized to the node grid) from random origins: the CWBVH hits the ground wherever the CPU
/// does, as the BVH2 on the device does.
#[test]
fn cwbvh_never_leaks_through_grid_edges() {
    let mut mesh = SceneMesh::new();
    mesh.push_heightfield((-48.0, -48.0), 1.0, (96, 96), |_, _| 0.0, |_, _| Surface::stuff(SemanticClass::ROAD));
    let Some(cw) = gpu_caster(&mesh, GpuBvh::Cwbvh, None) else { return };
    let bvh2 = gpu_caster(&mesh, GpuBvh::Bvh2, None).expect("an adapter");
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    let rays: Vec<Ray> = (0..50_000)
        .map(|_| {
            let (i, j) = (rng.random_range(-46..46) as f32, rng.random_range(-46..46) as f32);
            let (a, b) = [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.5, 0.5)][rng.random_range(0..4)];
            let target = Vec3::new(i + a, j + b, 0.0);
            let origin = match rng.random_range(0..3) {
                // In the vertical plane of a grid line.
                0 => Vec3::new(target.x + rng.random_range(-30.0..30.0), target.y, rng.random_range(0.3..25.0)),
                1 => Vec3::new(target.x, target.y + rng.random_range(-30.0..30.0), rng.random_range(0.3..25.0)),
                _ => Vec3::new(
                    target.x + rng.random_range(-30.0..30.0),
                    target.y + rng.random_range(-30.0..30.0),
                    rng.random_range(3.0..25.0),
                ),
            };
            Ray { origin, dir: (target - origin).normalize(), t_max: f32::INFINITY }
        })
        .collect();
    let expected = BvhCaster::new(&mesh).cast_all(&rays);
    assert!(expected.iter().all(Option::is_some));
    for (gpu, name) in [(&bvh2, "bvh2"), (&cw, "cwbvh")] {
        let got = gpu.cast_all(&rays);
        let misses = got.iter().filter(|h| h.is_none()).count();
        assert_eq!(misses, 0, "{name}: {misses} of {} rays leaked", rays.len());
        // The triangle may be the other one of the edge or vertex the ray goes through (the
        // device's f32 test has no f64 fallback), the distance not.
        for (i, (x, y)) in expected.iter().zip(&got).enumerate() {
            let (x, y) = (x.expect("a hit"), y.expect("a hit"));
            assert!((x.t - y.t).abs() <= 1e-3, "{name}: ray {i}: t {} (cpu) vs {} (gpu)", x.t, y.t);
        }
    }
}

/// The CWBVH's nodes split over both node bindings: the same hits as one binding. (Its nodes take
/// a fifth of its triangles' bytes: no common limit splits them while the triangles fit their 4
/// bindings, so the nodes get a limit of their own; then also with the triangles over 3.)
#[test]
fn cwbvh_splits_scene_over_two_node_bindings() {
    let mesh = random_scene(7);
    let Some(whole) = gpu_caster(&mesh, GpuBvh::Cwbvh, None) else { return };
    let (node_bytes, tri_bytes) = whole.scene_bytes();
    // A power of two of 80-byte nodes per binding that holds half of them or more.
    let node_limit = 80 * (node_bytes / 80).div_ceil(2).next_power_of_two();
    let tri_limit = 48 * (tri_bytes / 48).div_ceil(3).next_power_of_two();
    let rays = gpu_test_rays();
    let want = whole.cast_all(&rays);
    let expected = BvhCaster::new(&mesh).cast_all(&rays);
    assert_agrees(&mesh, &rays, &expected, &want);
    for max_binding_bytes in [None, Some(tri_limit)] {
        let options = GpuOptions { bvh: GpuBvh::Cwbvh, max_binding_bytes, max_node_binding_bytes: Some(node_limit) };
        let split = common::gpu_caster(&mesh, options).expect("an adapter");
        let (nodes, tris) = split.bindings_used();
        eprintln!(
            "limits {node_limit} / {max_binding_bytes:?} B: {node_bytes} + {tri_bytes} B in {nodes} + {tris} bindings"
        );
        assert!(nodes == 2 && tris == if max_binding_bytes.is_some() { 3 } else { 1 }, "{nodes} + {tris} bindings");
        assert_eq!(split.cast_all(&rays), want);
    }
    // Nodes that need more bindings than the shader has are refused with the sizes.
    let options =
        GpuOptions { bvh: GpuBvh::Cwbvh, max_node_binding_bytes: Some(node_limit / 2), ..GpuOptions::default() };
    let err = GpuCaster::with_options(&mesh, options).err().expect("too large");
    assert!(matches!(err, GpuError::TooLarge { buffer: "nodes", .. }), "{err}");
}

/// A spinning sensor's beams cast from poses, the rays made on the device, on the CWBVH: the same
/// hits as the CPU casting the rays the host makes ([`sim::cast::BeamSet::rays`]).
#[test]
fn cwbvh_casts_beams_made_on_the_device() {
    let mesh = random_scene(7);
    let Some(gpu) = gpu_caster(&mesh, GpuBvh::Cwbvh, None) else { return };
    let (set, poses) = spinning_beams(3);
    let rays = set.rays(&poses);
    let expected = BvhCaster::new(&mesh).cast_all(&rays);
    let got = gpu.cast_beams(&set, &poses);
    let (hits, ties, disagree) = assert_agrees(&mesh, &rays, &expected, &got);
    eprintln!("{} rays from beams: {hits} hits, {ties} ties, {disagree} disagreements", rays.len());
    assert_eq!(gpu.cast_beams(&set, &poses), got);
}

/// The layout's names: `bvh2` and `cwbvh` (any case); anything else is refused naming the variable
/// and the allowed values.
#[test]
fn layout_names_parse() {
    assert_eq!("bvh2".parse::<GpuBvh>().unwrap(), GpuBvh::Bvh2);
    assert_eq!(" CWBVH ".parse::<GpuBvh>().unwrap(), GpuBvh::Cwbvh);
    for b in [GpuBvh::Bvh2, GpuBvh::Cwbvh] {
        assert_eq!(b.to_string().parse::<GpuBvh>().unwrap(), b);
    }
    let err = "bvh8".parse::<GpuBvh>().unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, GpuError::Env { .. }), "{err:?}");
    for word in ["GROUNDTRUTH_GPU_BVH", "bvh8", "bvh2", "cwbvh"] {
        assert!(msg.contains(word), "{msg}");
    }
    assert_eq!(GpuOptions::default().bvh, GpuBvh::default());
}

/// Marks the child processes of [`gpu_caster_new_reads_the_layout_from_the_environment`] with the
/// outcome they check.
const CHILD: &str = "GROUNDTRUTH_TEST_GPU_BVH_EXPECT";

/// `GpuCaster::new` takes the layout from `GROUNDTRUTH_GPU_BVH` and refuses an unknown value
/// (before looking for an adapter). Each value is checked in a child process running this test
/// alone (the environment is process-wide; the other tests run in parallel).
#[test]
fn gpu_caster_new_reads_the_layout_from_the_environment() {
    let mut mesh = SceneMesh::new();
    mesh.push_box(Vec3::splat(-1.0), Vec3::splat(1.0), Surface::object(SemanticClass::CAR, 1));
    if let Ok(expect) = std::env::var(CHILD) {
        match (expect.as_str(), GpuCaster::new(&mesh)) {
            ("refused", Err(e @ GpuError::Env { .. })) => {
                let msg = e.to_string();
                assert!(msg.contains("GROUNDTRUTH_GPU_BVH") && msg.contains("bvh2, cwbvh"), "{msg}");
            }
            ("refused", other) => panic!("an unknown layout was not refused: {:?}", other.map(|g| g.bvh())),
            (_, Err(e @ GpuError::NoAdapter(_))) if std::env::var("GROUNDTRUTH_REQUIRE_GPU").as_deref() != Ok("1") => {
                eprintln!("GPU test skipped: {e}");
            }
            (want, got) => assert_eq!(got.expect("GPU backend").bvh().to_string(), want),
        }
        return;
    }
    let exe = std::env::current_exe().expect("the test binary");
    // The test's name in the harness: its module path less the test binary's crate name.
    let test = "gpu_caster_new_reads_the_layout_from_the_environment";
    let name = module_path!().split_once("::").map_or(test.to_string(), |(_, m)| format!("{m}::{test}"));
    for (value, expect) in
        [("bvh2", "bvh2"), ("cwbvh", "cwbvh"), ("", &*GpuBvh::default().to_string()), ("octree", "refused")]
    {
        let out = std::process::Command::new(&exe)
            .args(["--exact", &name, "--test-threads=1"])
            .env(GpuBvh::ENV, value)
            .env(CHILD, expect)
            .output()
            .expect("the test binary runs");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && text.contains("1 passed"),
            "{}={value:?}: {text}{}",
            GpuBvh::ENV,
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
