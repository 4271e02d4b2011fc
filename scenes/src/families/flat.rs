//! `flat`: open flat ground at z = 0, a baseline. A road along x through the origin, terrain
//! elsewhere, and a few scattered objects (cars, poles, signs, bushes) placed by the seed.

use glam::Vec3;
use rand::RngExt;
use serde::Deserialize;
use sim::{SceneMesh, SemanticClass, Surface};

use super::{Family, Generated, clear_of_ego, rng};
use crate::error::{SceneError, check, check_count};
use crate::grid::{Grid, axis};
use crate::objects::{self, Ids};

/// Most ground triangles a `flat` scene may have.
const MAX_TRIANGLES: f32 = 4_000_000.0;

/// Parameters of `flat`.
#[derive(Deserialize, Debug, Clone)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Side of the square terrain, metres (100 ..= 2000, default 400).
    pub size_m: f32,
    /// Grid cell, metres (0.25 ..= 5, default 2).
    pub cell_m: f32,
    /// Road width, metres (0 ..= 40, default 8).
    pub road_width_m: f32,
    /// Number of scattered objects (0 ..= 500, default 12).
    pub objects: u32,
}

impl Default for Params {
    fn default() -> Self {
        Self { size_m: 400.0, cell_m: 2.0, road_width_m: 8.0, objects: 12 }
    }
}

impl Family for Params {
    fn validate(&self) -> Result<(), SceneError> {
        check("size_m", self.size_m, 100.0, 2000.0)?;
        check("cell_m", self.cell_m, 0.25, 5.0)?;
        check("road_width_m", self.road_width_m, 0.0, 40.0)?;
        check_count("objects", self.objects, 0, 500)?;
        let cells = (self.size_m / self.cell_m).ceil();
        if 2.0 * cells * cells > MAX_TRIANGLES {
            return Err(SceneError::invalid(
                "params.cell_m",
                self.cell_m,
                format!(
                    ">= size_m / {} (at most {MAX_TRIANGLES} ground triangles)",
                    (0.5 * MAX_TRIANGLES).sqrt().floor()
                ),
            ));
        }
        Ok(())
    }

    fn build(&self, seed: u64) -> Generated {
        let half = 0.5 * self.size_m;
        let rw = 0.5 * self.road_width_m;
        let mut mesh = SceneMesh::new();
        let xs = axis(half, half, self.cell_m, self.cell_m, &[], &[]);
        let ys = axis(half, half, self.cell_m, self.cell_m, &[-rw, rw], &[]);
        Grid::new(xs, ys).push(
            &mut mesh,
            |_, _| 0.0,
            |c| Some(Surface::stuff(if c.y.abs() < rw { SemanticClass::ROAD } else { SemanticClass::TERRAIN })),
        );
        let mut ids = Ids::default();
        let mut r = rng(seed, 1);
        let reach = 0.9 * half;
        for _ in 0..self.objects {
            let p = Vec3::new(r.random_range(-reach..reach), r.random_range(-reach..reach), 0.0);
            if !clear_of_ego(p, 10.0) || p.y.abs() < rw + 1.0 {
                continue;
            }
            let yaw = r.random_range(0.0..std::f32::consts::TAU);
            match r.random_range(0..4u32) {
                0 => objects::car(&mut mesh, &mut ids, p, yaw),
                1 => objects::pole(&mut mesh, &mut ids, p, 6.0),
                2 => objects::sign(&mut mesh, &mut ids, p, yaw),
                _ => objects::bush(&mut mesh, &mut ids, p, 1.0, 1.2),
            };
        }
        // A post beside the road 12 m ahead, so every seed has a non-ground object.
        objects::pole(&mut mesh, &mut ids, Vec3::new(12.0, rw + 1.5, 0.0), 6.0);
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}
