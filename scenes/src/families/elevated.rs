//! `elevated`: flat horizontal surfaces that are *not* ground next to raised surfaces that *are*.
//! A paved yard at z = 0 with a warehouse and its raised loading dock (class other-structure),
//! free-standing platforms, parked cars, vans and trucks (flat roofs), picnic tables, and two raised
//! ground plateaus with sloped banks (class terrain / other-ground: ground, though elevated).

use glam::Vec3;
use rand::RngExt;
use serde::Deserialize;
use sim::{SceneMesh, SemanticClass, Surface};

use super::basin::trapezoid;
use super::{Family, Generated, rng};
use crate::error::{SceneError, check};
use crate::grid::{Grid, axis};
use crate::objects::{self, Ids};

/// Parameters of `elevated`.
#[derive(Deserialize, Debug, Clone)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Height of the loading dock and platforms, metres (0.3 ..= 3, default 1.2).
    pub dock_height_m: f32,
    /// Height of the raised ground plateaus, metres (0.2 ..= 10, default 1.5).
    pub plateau_height_m: f32,
    /// Bank slope of the plateaus, degrees (5 ..= 60, default 30).
    pub plateau_bank_deg: f32,
    /// Side of the square terrain, metres (200 ..= 1000, default 400).
    pub size_m: f32,
}

impl Default for Params {
    fn default() -> Self {
        Self { dock_height_m: 1.2, plateau_height_m: 1.5, plateau_bank_deg: 30.0, size_m: 400.0 }
    }
}

/// Plateau tops: (x0, x1, y0, y1) in metres; the banks lie outside.
pub const PLATEAUS: [(f32, f32, f32, f32); 2] = [(25.0, 45.0, -30.0, -14.0), (-40.0, -20.0, 12.0, 30.0)];

impl Params {
    fn run_m(&self) -> f32 {
        self.plateau_height_m / self.plateau_bank_deg.to_radians().tan()
    }
}

impl Family for Params {
    fn validate(&self) -> Result<(), SceneError> {
        check("dock_height_m", self.dock_height_m, 0.3, 3.0)?;
        check("plateau_height_m", self.plateau_height_m, 0.2, 10.0)?;
        check("plateau_bank_deg", self.plateau_bank_deg, 5.0, 60.0)?;
        check("size_m", self.size_m, 200.0, 1000.0)
    }

    fn build(&self, seed: u64) -> Generated {
        let half = 0.5 * self.size_m;
        let run = self.run_m();
        let h = self.plateau_height_m;
        let edges: Vec<([f32; 4], [f32; 4])> = PLATEAUS
            .iter()
            .map(|&(x0, x1, y0, y1)| ([x0 - run, x0, x1, x1 + run], [y0 - run, y0, y1, y1 + run]))
            .collect();
        let xb: Vec<f32> = edges.iter().flat_map(|e| e.0).collect();
        let yb: Vec<f32> = edges.iter().flat_map(|e| e.1).collect();
        let xs = axis(half, 70.0, 1.0, 2.0, &xb, &[]);
        let ys = axis(half, 70.0, 1.0, 2.0, &yb, &[]);
        let height = |x: f32, y: f32| {
            edges.iter().map(|(ex, ey)| h * trapezoid(x, *ex).min(trapezoid(y, *ey))).fold(0.0, f32::max)
        };
        let mut mesh = SceneMesh::new();
        Grid::new(xs, ys).push(&mut mesh, height, |c| {
            let class = if c.z_max > 0.0 {
                if c.z_min >= h - 1e-4 { SemanticClass::OTHER_GROUND } else { SemanticClass::TERRAIN }
            } else if c.x.abs() < 60.0 && c.y.abs() < 60.0 {
                SemanticClass::PARKING
            } else {
                SemanticClass::TERRAIN
            };
            Some(Surface::stuff(class))
        });
        let mut ids = Ids::default();
        let dock = self.dock_height_m;
        // Warehouse with a loading dock along its front (facing -x), trucks backed up to it.
        objects::building(&mut mesh, &mut ids, Vec3::new(60.0, 20.0, 0.0), 0.0, Vec3::new(20.0, 30.0, 9.0));
        objects::slab(&mut mesh, &mut ids, Vec3::new(46.0, 6.0, -0.2), Vec3::new(50.0, 34.0, dock));
        objects::truck(&mut mesh, &mut ids, Vec3::new(39.5, 12.0, 0.0), 0.0);
        objects::van(&mut mesh, &mut ids, Vec3::new(43.0, 24.0, 0.0), 0.0);
        // Free-standing platforms of several heights.
        for (k, (x, y)) in [(15.0, 8.0), (-15.0, -12.0), (30.0, 40.0)].into_iter().enumerate() {
            let ph = dock * (0.5 + 0.25 * k as f32);
            objects::slab(&mut mesh, &mut ids, Vec3::new(x - 4.0, y - 3.0, -0.2), Vec3::new(x + 4.0, y + 3.0, ph));
        }
        // Parked vehicles in rows, picnic tables, a few poles.
        let mut r = rng(seed, 19);
        for row in [-6.0f32, 6.0] {
            let mut x = -55.0;
            while x < 0.0 {
                let p = Vec3::new(x, row + r.random_range(-0.3..0.3f32), 0.0);
                match r.random_range(0..6u32) {
                    0 => {
                        objects::van(&mut mesh, &mut ids, p, std::f32::consts::FRAC_PI_2);
                    }
                    1 => {}
                    _ => {
                        objects::car(&mut mesh, &mut ids, p, std::f32::consts::FRAC_PI_2);
                    }
                }
                x += 3.0;
            }
        }
        objects::truck(&mut mesh, &mut ids, Vec3::new(10.0, -40.0, 0.0), 0.3);
        for k in 0..6 {
            let p = Vec3::new(-8.0 + 3.0 * k as f32, -24.0 + r.random_range(-1.0..1.0f32), 0.0);
            objects::table(&mut mesh, &mut ids, p, r.random_range(0.0..1.0f32));
        }
        // A curbed island (15 cm, ground) with a tree at the end of each parking row.
        for y in [-6.0f32, 6.0] {
            let (x0, x1, y0, y1) = (-62.0, -58.0, y - 2.5, y + 2.5);
            for (a, b) in [((x0, y0), (x1, y0)), ((x1, y0), (x1, y1)), ((x1, y1), (x0, y1)), ((x0, y1), (x0, y0))] {
                objects::curb(&mut mesh, Vec3::new(a.0, a.1, 0.0), Vec3::new(b.0, b.1, 0.0), 0.2, 0.15);
            }
            objects::tree(&mut mesh, &mut ids, Vec3::new(-60.0, y, 0.0), 2.5, 0.15, 1.8);
        }
        for x in [-60.0f32, -20.0, 20.0, 60.0] {
            objects::pole(&mut mesh, &mut ids, Vec3::new(x, -50.0, 0.0), 8.0);
        }
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}
