//! Benchmark fixture for the casters: a 1.3 M-triangle hilly terrain with boxes, and the rays of a
//! 128 x 2048 spinning LiDAR on a roof-high origin. Used by `benches/raycast.rs` and
//! `groundtruth bench raycast --scene fixture-terrain --rig fixture-128x2048`.
//!
//! It does not depend on the sensor models, so the caster can be measured on its own.

use glam::Vec3;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::Ray;
use crate::scene::{SceneMesh, SemanticClass, Surface};

/// Cells per side of the fixture terrain (806 x 806 cells x 2 = 1,299,272 triangles).
pub const TERRAIN_CELLS: usize = 806;
/// Side of the fixture terrain square, metres (centred on the origin).
pub const TERRAIN_SIZE_M: f32 = 400.0;
/// Number of boxes (buildings, cars) on the fixture terrain.
pub const BOX_COUNT: usize = 64;
/// Sensor height above the terrain at the origin, metres (a roof-mounted sensor).
pub const SENSOR_HEIGHT_M: f32 = 1.9;
/// Rows (beams) of the fixture LiDAR.
pub const LIDAR_ROWS: usize = 128;
/// Columns (azimuth steps) of the fixture LiDAR.
pub const LIDAR_COLS: usize = 2048;
/// Half vertical field of view of the fixture LiDAR, degrees (elevations -22.5 ..= +22.5).
pub const LIDAR_HALF_FOV_DEG: f32 = 22.5;
/// Distance the sensor moves along +x between frames, metres.
pub const FRAME_STEP_M: f32 = 1.0;

/// Height of the fixture's smooth hills at `(x, y)`, metres.
pub fn terrain_height_m(x: f32, y: f32) -> f32 {
    3.0 * (x / 37.0).sin() * (y / 53.0).cos() + 1.2 * (x / 13.0 + y / 17.0).sin() + 0.02 * x
}

/// The fixture scene: an 806 x 806-cell heightfield over 400 m x 400 m with smooth hills, plus
/// [`BOX_COUNT`] boxes (seeded, deterministic) standing on it away from the sensor.
pub fn terrain_scene() -> SceneMesh {
    let mut m = SceneMesh::new();
    let half = TERRAIN_SIZE_M / 2.0;
    let cell = TERRAIN_SIZE_M / TERRAIN_CELLS as f32;
    m.push_heightfield((-half, -half), cell, (TERRAIN_CELLS, TERRAIN_CELLS), terrain_height_m, |_, y| {
        Surface::stuff(if y.abs() < 4.0 { SemanticClass::ROAD } else { SemanticClass::TERRAIN })
    });
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(0x6a7e_5ca1);
    for i in 0..BOX_COUNT {
        let (x, y) = loop {
            let x = rng.random_range(-150.0f32..150.0);
            let y = rng.random_range(-150.0f32..150.0);
            if x.abs() > 8.0 || y.abs() > 8.0 {
                break (x, y);
            }
        };
        let size = Vec3::new(rng.random_range(2.0..12.0), rng.random_range(2.0..12.0), rng.random_range(1.5..15.0));
        let z0 = terrain_height_m(x, y) - 0.5;
        let class = if size.z < 3.0 { SemanticClass::CAR } else { SemanticClass::BUILDING };
        m.push_box(Vec3::new(x, y, z0), Vec3::new(x, y, z0) + size, Surface::object(class, i as u32 + 1));
    }
    m
}

/// Sensor origin of frame `frame`, metres: [`SENSOR_HEIGHT_M`] above the terrain, moving along +x.
pub fn sensor_origin(frame: usize) -> Vec3 {
    let x = frame as f32 * FRAME_STEP_M;
    Vec3::new(x, 0.0, terrain_height_m(x, 0.0) + SENSOR_HEIGHT_M)
}

/// Unit direction of the fixture LiDAR's beam at `(row, col)`: row 0 is the lowest elevation
/// (-22.5 deg), rows are uniform up to +22.5 deg; column 0 is the left-most azimuth (+180 deg)
/// and azimuth decreases with the column (clockwise seen from above).
pub fn beam_dir(row: usize, col: usize) -> Vec3 {
    let el_deg = -LIDAR_HALF_FOV_DEG + 2.0 * LIDAR_HALF_FOV_DEG * row as f32 / (LIDAR_ROWS - 1) as f32;
    let az_rad = std::f32::consts::PI - std::f32::consts::TAU * col as f32 / LIDAR_COLS as f32;
    let el = el_deg.to_radians();
    Vec3::new(el.cos() * az_rad.cos(), el.cos() * az_rad.sin(), el.sin()).normalize()
}

/// The rays of `frames` fixture LiDAR frames, frame after frame, each row-major (like
/// `sim::sensor::ScanPattern`): `frames * 128 * 2048` rays with unlimited range.
pub fn lidar_rays(frames: usize) -> Vec<Ray> {
    let mut rays = Vec::with_capacity(frames * LIDAR_ROWS * LIDAR_COLS);
    for f in 0..frames {
        let origin = sensor_origin(f);
        for r in 0..LIDAR_ROWS {
            for c in 0..LIDAR_COLS {
                rays.push(Ray { origin, dir: beam_dir(r, c), t_max: f32::INFINITY });
            }
        }
    }
    rays
}

/// The fixture LiDAR as a beam set (one pose per frame, range unlimited), for casting from poses
/// ([`super::Caster::cast_beams`]): the rays of [`lidar_rays`] up to rounding.
pub fn lidar_beams() -> super::BeamSet {
    let beams = (0..LIDAR_ROWS)
        .flat_map(|r| (0..LIDAR_COLS).map(move |c| (r, c)))
        .map(|(r, c)| super::Beam {
            origin_in_sensor: Vec3::ZERO,
            dir_in_sensor: beam_dir(r, c),
            t_max_m: f32::INFINITY,
            pose: 0,
            pose_blend: 0.0,
            side_offset: 0.0,
        })
        .collect();
    super::BeamSet::new(beams, 1).expect("unit directions, one pose")
}

/// The fixture LiDAR's pose in each of `frames` frames (a translation to [`sensor_origin`]).
pub fn lidar_poses(frames: usize) -> Vec<glam::Affine3A> {
    (0..frames).map(|f| glam::Affine3A::from_translation(sensor_origin(f))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beam_geometry() {
        assert!((beam_dir(0, 0).z - (-22.5f32).to_radians().sin()).abs() < 1e-6);
        assert!((beam_dir(LIDAR_ROWS - 1, 0).z - 22.5f32.to_radians().sin()).abs() < 1e-6);
        // Column 0 points backwards (+180 deg), column 512 to the left (+90 deg).
        assert!(beam_dir(64, 0).x < -0.99);
        assert!(beam_dir(64, 512).y > 0.99);
        assert_eq!(lidar_rays(1).len(), 128 * 2048);
        let (beams, poses) = (lidar_beams(), lidar_poses(2));
        let (a, b) = (lidar_rays(2), beams.rays(&poses));
        assert_eq!(a.len(), b.len());
        assert!(a.iter().zip(&b).all(|(a, b)| a.origin == b.origin && (a.dir - b.dir).length() < 1e-6));
    }
}
