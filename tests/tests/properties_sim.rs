//! Simulator properties: ideal returns on analytic surfaces (plane, sphere, box, through parry3d's
//! exact ray casts) lie at the analytic distance; every return's ground flag agrees with its class
//! and no return holds a NaN; the grid shape is the sensor's; the same seed gives the same bytes at
//! 1 and 2 threads; moving the mount (and the scene) by a known offset moves the ideal returns by
//! exactly that offset.
//!
//! Case counts are CI-sized and the cases drawn are fixed (seed 0); `GT_PROPTEST_CASES=N` raises
//! every property to N cases, `GT_PROPTEST_SEED=S` draws other ones.

use glam::{Affine3A, Vec3};
use groundtruth_scenario::strategies::config;
use gt_tests::{LoadedScene, ScanSpec, cloud_bits, scan_on, scan_spec, scan_with_threads};
use parry3d::math::Pose;
use parry3d::query::{Ray, RayCast};
use parry3d::shape::{Ball, Cuboid};
use proptest::prelude::*;
use sim::rig::{Mount, Rig};
use sim::{SceneMesh, SemanticClass, Surface};

/// Sphere tessellation: 64 subdivisions around, 32 from pole to pole.
const SPHERE_THETA: u32 = 64;
const SPHERE_PHI: u32 = 32;

fn vlp16_at(mount: Mount) -> Rig {
    let mut rig = Rig::preset("vlp16-roof").unwrap();
    rig.sensors[0].mount = mount;
    rig
}

fn push_trimesh(mesh: &mut SceneMesh, (vertices, triangles): (Vec<Vec3>, Vec<[u32; 3]>), at: Vec3, s: Surface) {
    let base: Vec<u32> = vertices.iter().map(|&v| mesh.push_vertex(v + at)).collect();
    for [a, b, c] in triangles {
        mesh.push_triangle([base[a as usize], base[b as usize], base[c as usize]], s);
    }
}

/// A scene of three analytic shapes: a ground plane z = 0 from x = 8 m on (none under the wheels,
/// so the vehicle stays at z = 0), a sphere (instance 1) and a box (instance 2).
struct Shapes {
    ball: (Ball, Vec3),
    cuboid: (Cuboid, Vec3),
}

impl Shapes {
    fn mesh(&self, shift: Vec3) -> SceneMesh {
        let mut mesh = SceneMesh::new();
        let g = Surface::stuff(SemanticClass::ROAD);
        let z = |x: f32, y: f32| Vec3::new(x, y, 0.0) + shift;
        mesh.push_quad([z(8.0, -60.0), z(80.0, -60.0), z(80.0, 60.0), z(8.0, 60.0)], g);
        let (ball, c) = self.ball;
        push_trimesh(
            &mut mesh,
            ball.to_trimesh(SPHERE_THETA, SPHERE_PHI),
            c + shift,
            Surface::object(SemanticClass::OTHER_OBJECT, 1),
        );
        let (cuboid, c) = self.cuboid;
        push_trimesh(&mut mesh, cuboid.to_trimesh(), c + shift, Surface::object(SemanticClass::BUILDING, 2));
        mesh
    }
}

proptest! {
    #![proptest_config(config(6))]

    /// Bounds: plane and box within 2e-4 of the range (worst seen in the long run, 64 cases:
    /// 1.2e-6 and 4.5e-7); sphere (tessellated 64 x 32) within its facet tolerance (worst 0.48 of it).
    #[test]
    fn ideal_returns_lie_at_the_analytic_distance(
        height in 0.8f32..2.5,
        pitch in -5.0f32..5.0,
        ball_at in (10.0f32..20.0, -10.0f32..10.0, 0.5f32..3.0),
        radius in 0.5f32..3.0,
        box_at in (-20.0f32..-8.0, -10.0f32..10.0),
        half in (0.8f32..3.0, 0.8f32..3.0, 0.8f32..3.0),
    ) {
        let shapes = Shapes {
            ball: (Ball::new(radius), Vec3::new(ball_at.0, ball_at.1, ball_at.2 + radius)),
            cuboid: (Cuboid::new(Vec3::new(half.0, half.1, half.2)), Vec3::new(box_at.0, box_at.1, half.2 + 0.5)),
        };
        let mesh = shapes.mesh(Vec3::ZERO);
        let mount = Mount { x_m: 1.3, y_m: 0.0, z_m: height, roll_deg: 0.0, pitch_deg: pitch, yaw_deg: 0.0 };
        let frames = scan_on(&LoadedScene::from_mesh(mesh, "shapes"), &vlp16_at(mount), &ScanSpec { ideal: true, ..ScanSpec::default() });
        let f = &frames[0];
        prop_assert_eq!(f.vehicle_pose.z_m, 0.0);
        let c = &f.cloud;
        let origin = mount.vehicle_from_sensor().transform_point3(Vec3::ZERO);
        // The tessellated sphere lies inside the true one, at most its sagitta below it.
        let sagitta = radius * (1.0 - (std::f32::consts::PI / SPHERE_PHI as f32).cos());
        let mut counts = [0usize; 3];
        // Worst plane and box error relative to the range, worst sphere error over its tolerance.
        let mut worst = [0f32; 3];
        for i in (0..c.len()).filter(|&i| c.has_return(i)) {
            let p = c.point_in_vehicle[i];
            let dir = (p - origin).normalize();
            let ray = Ray::new(origin, dir);
            prop_assert!((c.range_m[i] - (p - origin).length()).abs() < 1e-3, "range vs point at cell {}", i);
            match c.instance[i] {
                0 => {
                    // Plane z = 0.
                    let t = -origin.z / dir.z;
                    prop_assert!((c.range_m[i] - t).abs() < 2e-4 * t.max(1.0), "plane: {} vs {}", c.range_m[i], t);
                    worst[0] = worst[0].max((c.range_m[i] - t).abs() / t.max(1.0));
                    counts[0] += 1;
                }
                1 => {
                    let (ball, at) = shapes.ball;
                    let t = ball.cast_ray(&Pose::from_translation(at), &ray, 1e4, true);
                    prop_assert!(t.is_some(), "sphere return with no analytic hit at cell {}", i);
                    let t = t.unwrap();
                    // Off the facet by at most the sagitta along the normal: sagitta / cos along the
                    // ray; at grazing incidence (cos < 0.3) by at most the cap's chord, 2 sqrt(2 r s).
                    let cos = (-dir).dot(c.normal[i]);
                    let tol = if cos >= 0.3 { sagitta / cos } else { 2.0 * (2.0 * radius * sagitta).sqrt() };
                    let d = c.range_m[i] - t;
                    prop_assert!(d > -1e-3 && d < tol + 1e-3, "sphere: {} vs {} (sagitta {}, cos {})", c.range_m[i], t, sagitta, cos);
                    worst[1] = worst[1].max(d.abs() / (tol + 1e-3));
                    counts[1] += 1;
                }
                _ => {
                    let (cuboid, at) = shapes.cuboid;
                    let t = cuboid.cast_ray(&Pose::from_translation(at), &ray, 1e4, true);
                    prop_assert!(t.is_some(), "box return with no analytic hit at cell {}", i);
                    let t = t.unwrap();
                    prop_assert!((c.range_m[i] - t).abs() < 2e-4 * t.max(1.0), "box: {} vs {}", c.range_m[i], t);
                    worst[2] = worst[2].max((c.range_m[i] - t).abs() / t.max(1.0));
                    counts[2] += 1;
                }
            }
        }
        eprintln!("SIM analytic worst: plane {:.3e} box {:.3e} (relative), sphere {:.3} of its tolerance; returns {:?}", worst[0], worst[2], worst[1], counts);
        prop_assert!(counts[0] > 100 && counts[1] > 0 && counts[2] > 0, "returns on plane, sphere, box: {:?}", counts);
    }

    /// On every bundled scene (any seed, noise on or off) every return's ground flag is its class's,
    /// nothing is NaN, and the grid is the sensor's rows x columns.
    #[test]
    fn ground_flags_follow_classes_and_no_return_holds_nan(
        scene in prop::sample::select(scenes::bundled_names()),
        rig in prop::sample::select(vec!["vlp16-roof", "os1-64-roof", "lux"]),
        seed in 0u64..1000,
        ideal in any::<bool>(),
    ) {
        let spec = ScanSpec { scene: scene.to_string(), rig: rig.to_string(), seed, ideal, ..ScanSpec::default() };
        let (frames, rig) = scan_spec(&spec);
        let c = &frames[0].cloud;
        let pattern = rig.sensors[0].spec.pattern();
        prop_assert_eq!((c.rows, c.cols), (pattern.rows, pattern.cols));
        prop_assert_eq!(c.len(), c.rows * c.cols * c.planes);
        prop_assert!(c.returns() > 100, "returns {}", c.returns());
        for i in (0..c.len()).filter(|&i| c.has_return(i)) {
            prop_assert_eq!(c.ground[i], c.label[i].is_ground(), "cell {} class {}", i, c.label[i].name());
            let p = c.point_in_vehicle[i];
            let n = c.normal[i];
            prop_assert!(p.is_finite() && n.is_finite(), "cell {}: point {:?} normal {:?}", i, p, n);
            prop_assert!(c.range_m[i].is_finite() && c.range_m[i] > 0.0, "cell {}: range {}", i, c.range_m[i]);
            prop_assert!(c.intensity[i].is_finite() && c.time_s[i].is_finite(), "cell {}", i);
            prop_assert!((n.length() - 1.0).abs() < 1e-3, "cell {}: normal {:?}", i, n);
        }
    }

    /// The same seed gives the same bytes at 1 and 2 threads (noise on, moving vehicle).
    #[test]
    fn same_seed_same_bytes_at_one_and_two_threads(
        scene in prop::sample::select(vec!["city", "basin", "elevated", "ramp-down"]),
        seed in 0u64..1_000_000,
        speed in 0.0f32..20.0,
    ) {
        let spec = ScanSpec { scene: scene.to_string(), seed, frames: 2, speed_m_per_s: f64::from(speed), ..ScanSpec::default() };
        let scene = spec.load_scene().unwrap();
        let rig = Rig::preset("vlp16-roof").unwrap();
        let one = scan_with_threads(1, &scene, &rig, &spec);
        let two = scan_with_threads(2, &scene, &rig, &spec);
        for (a, b) in one.iter().zip(&two) {
            prop_assert!(cloud_bits(&a.cloud) == cloud_bits(&b.cloud), "frame {} differs", a.index);
        }
    }

    /// Moving the mount by d and the scene by the same d moves every ideal return by exactly d in
    /// the vehicle frame and keeps its range, within 2e-4 of the range (worst seen in the long run:
    /// 2.6e-5 m).
    #[test]
    fn moving_the_mount_moves_the_returns(
        d in (-1.0f32..1.0, -1.0f32..1.0, -0.5f32..0.5),
        height in 1.0f32..2.0,
        pitch in -3.0f32..3.0,
    ) {
        let shapes = Shapes {
            ball: (Ball::new(1.5), Vec3::new(20.0, 4.0, 1.5)),
            cuboid: (Cuboid::new(Vec3::new(2.0, 1.0, 1.5)), Vec3::new(-20.0, -5.0, 1.5)),
        };
        let d = Vec3::new(d.0, d.1, d.2);
        let m0 = Mount { x_m: 1.3, y_m: 0.0, z_m: height, roll_deg: 0.0, pitch_deg: pitch, yaw_deg: 0.0 };
        let m1 = Mount { x_m: m0.x_m + d.x, y_m: m0.y_m + d.y, z_m: m0.z_m + d.z, ..m0 };
        let spec = ScanSpec { ideal: true, ..ScanSpec::default() };
        let a = scan_on(&LoadedScene::from_mesh(shapes.mesh(Vec3::ZERO), "shapes"), &vlp16_at(m0), &spec);
        let b = scan_on(&LoadedScene::from_mesh(shapes.mesh(d), "shapes moved"), &vlp16_at(m1), &spec);
        prop_assert_eq!(a[0].world_from_vehicle, Affine3A::IDENTITY);
        prop_assert_eq!(b[0].world_from_vehicle, Affine3A::IDENTITY);
        let (a, b) = (&a[0].cloud, &b[0].cloud);
        let mut moved = 0;
        let mut worst = 0f32;
        for i in 0..a.len() {
            prop_assert_eq!(a.has_return(i), b.has_return(i), "cell {}", i);
            if a.has_return(i) {
                let err = (b.point_in_vehicle[i] - (a.point_in_vehicle[i] + d)).length();
                prop_assert!(err < 2e-4 * a.range_m[i].max(1.0), "cell {}: moved by {:?}, error {}", i, b.point_in_vehicle[i] - a.point_in_vehicle[i], err);
                prop_assert!((a.range_m[i] - b.range_m[i]).abs() < 2e-4 * a.range_m[i].max(1.0));
                prop_assert_eq!(a.instance[i], b.instance[i]);
                worst = worst.max(err);
                moved += 1;
            }
        }
        eprintln!("SIM mount worst: {worst:.3e} m over {moved} returns, offset {d:?}");
        prop_assert!(moved > 1000, "returns {}", moved);
    }
}
