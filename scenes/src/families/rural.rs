//! `rural`: a two-lane country road (seed 000's rural scenario) on a low embankment: grass
//! shoulders, ditches on both sides, fields below street level with gentle smooth relief, bushes
//! and hedgerows in the fields, trees along the road, and a rain-water basin in the field.

use glam::Vec3;
use rand::RngExt;
use serde::Deserialize;
use sim::{SceneMesh, SemanticClass, Surface};

use super::basin::trapezoid;
use super::{Family, Generated, clear_of_ego, rng};
use crate::error::{SceneError, check, check_count};
use crate::grid::{Grid, axis};
use crate::noise::Fbm;
use crate::objects::{self, Ids};

/// Parameters of `rural`.
#[derive(Deserialize, Debug, Clone)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Road width, metres (4 ..= 12, default 6.5).
    pub road_width_m: f32,
    /// Grass shoulder between road edge and ditch, metres (0 ..= 5, default 1).
    pub shoulder_m: f32,
    /// Ditch depth below road level, metres (0.2 ..= 3, default 1.2).
    pub ditch_depth_m: f32,
    /// How far the fields lie below road level, metres (0 ..= 3, default 0.6; at most the ditch depth).
    pub field_drop_m: f32,
    /// Peak height of the fields' smooth relief, metres (0 ..= 3, default 0.4).
    pub relief_m: f32,
    /// Number of bushes in the fields (0 ..= 3000, default 400).
    pub bushes: u32,
    /// Depth of the rain-water basin below the field, metres (0 ..= 5, default 1.5; 0 = no basin).
    pub basin_depth_m: f32,
    /// Side of the square terrain, metres (200 ..= 1000, default 400).
    pub size_m: f32,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            road_width_m: 6.5,
            shoulder_m: 1.0,
            ditch_depth_m: 1.2,
            field_drop_m: 0.6,
            relief_m: 0.4,
            bushes: 400,
            basin_depth_m: 1.5,
            size_m: 400.0,
        }
    }
}

/// Basin footprint (top edges) in the field left of the road: x range and y range, metres.
const BASIN_X: (f32, f32) = (40.0, 90.0);
const BASIN_Y: (f32, f32) = (16.0, 40.0);
/// Basin bank slope, as run per unit of depth (1 : 2).
const BASIN_RUN_PER_DEPTH: f32 = 2.0;
/// Ditch bank run per unit of depth (1 : 1.5), and ditch bottom width, metres.
const DITCH_RUN_PER_DEPTH: f32 = 1.5;
const DITCH_BOTTOM_M: f32 = 0.8;

impl Params {
    /// |y| of: road edge, ditch top, ditch bottom start, ditch bottom end, field start.
    fn cross(&self) -> [f32; 5] {
        let e0 = 0.5 * self.road_width_m;
        let e1 = e0 + self.shoulder_m;
        let e2 = e1 + DITCH_RUN_PER_DEPTH * self.ditch_depth_m;
        let e3 = e2 + DITCH_BOTTOM_M;
        let e4 = e3 + DITCH_RUN_PER_DEPTH * (self.ditch_depth_m - self.field_drop_m);
        [e0, e1, e2, e3, e4]
    }

    fn basin_edges(&self) -> ([f32; 4], [f32; 4]) {
        let r = BASIN_RUN_PER_DEPTH * self.basin_depth_m;
        ([BASIN_X.0, BASIN_X.0 + r, BASIN_X.1 - r, BASIN_X.1], [BASIN_Y.0, BASIN_Y.0 + r, BASIN_Y.1 - r, BASIN_Y.1])
    }
}

impl Family for Params {
    fn validate(&self) -> Result<(), SceneError> {
        check("road_width_m", self.road_width_m, 4.0, 12.0)?;
        check("shoulder_m", self.shoulder_m, 0.0, 5.0)?;
        check("ditch_depth_m", self.ditch_depth_m, 0.2, 3.0)?;
        check("field_drop_m", self.field_drop_m, 0.0, self.ditch_depth_m)?;
        check("relief_m", self.relief_m, 0.0, 3.0)?;
        check_count("bushes", self.bushes, 0, 3000)?;
        check("basin_depth_m", self.basin_depth_m, 0.0, 5.0)?;
        check("size_m", self.size_m, 200.0, 1000.0)
    }

    fn build(&self, seed: u64) -> Generated {
        let half = 0.5 * self.size_m;
        let cross = self.cross();
        let (bx, by) = self.basin_edges();
        let fbm = Fbm { seed: seed ^ 0x52_55_52, wavelength_m: 60.0, amplitude_m: self.relief_m, octaves: 3 };
        let (d, f) = (self.ditch_depth_m, self.field_drop_m);
        let basin_depth = self.basin_depth_m;
        let height = move |x: f32, y: f32| {
            let a = y.abs();
            let [_, e1, e2, e3, e4] = cross;
            let base = if a <= e1 {
                0.0
            } else if a < e2 {
                -d * (a - e1) / (e2 - e1)
            } else if a <= e3 {
                -d
            } else if a < e4 {
                -d + (d - f) * (a - e3) / (e4 - e3)
            } else {
                -f
            };
            // Relief fades in over 6 m beyond the field edge, so the ditch stays clean.
            let blend = ((a - e4) / 6.0).clamp(0.0, 1.0);
            let basin = if basin_depth > 0.0 { basin_depth * trapezoid(x, bx).min(trapezoid(y, by)) } else { 0.0 };
            base + blend * fbm.at(x, y) - basin
        };
        let mut ybreaks: Vec<f32> = cross.iter().flat_map(|&e| [e, -e]).collect();
        let mut xbreaks = Vec::new();
        if basin_depth > 0.0 {
            ybreaks.extend(by);
            xbreaks.extend(bx);
        }
        let xs = axis(half, 80.0, 1.0, 2.0, &xbreaks, &[]);
        let ys = axis(half, 50.0, 1.0, 2.0, &ybreaks, &[]);
        let road_half = cross[0];
        let mut mesh = SceneMesh::new();
        Grid::new(xs, ys).push(&mut mesh, height, |c| {
            Some(Surface::stuff(if c.y.abs() < road_half { SemanticClass::ROAD } else { SemanticClass::TERRAIN }))
        });
        let mut ids = Ids::default();
        let mut r = rng(seed, 7);
        let field_edge = cross[4] + 2.0;
        let in_basin = |p: Vec3| p.x > bx[0] - 2.0 && p.x < bx[3] + 2.0 && p.y > by[0] - 2.0 && p.y < by[3] + 2.0;
        let reach = half - 5.0;
        let mut placed = 0;
        let mut tries = 0;
        while placed < self.bushes && tries < 20 * self.bushes {
            tries += 1;
            let side = if r.random_bool(0.5) { 1.0 } else { -1.0 };
            // Bushes cluster in hedgerows along the field edge and scatter across the fields.
            let y = if r.random_bool(0.5) {
                side * (field_edge + r.random_range(0.0..4.0f32))
            } else {
                side * r.random_range(field_edge..reach)
            };
            let p = Vec3::new(r.random_range(-reach..reach), y, 0.0);
            if in_basin(p) && basin_depth > 0.0 || !clear_of_ego(p, 5.0) {
                continue;
            }
            let rad = r.random_range(0.6..1.8f32);
            let hgt = r.random_range(0.8..2.2f32);
            objects::bush(&mut mesh, &mut ids, Vec3::new(p.x, p.y, height(p.x, p.y)), rad, hgt);
            placed += 1;
        }
        let mut x = -reach + r.random_range(0.0..20.0f32);
        while x < reach {
            let y = (cross[4] + 1.0) * if r.random_bool(0.5) { 1.0 } else { -1.0 };
            if !(BASIN_X.0 - 5.0..BASIN_X.1 + 5.0).contains(&x) {
                let (th, cr) = (r.random_range(2.0..4.0f32), r.random_range(2.0..3.5f32));
                objects::tree(&mut mesh, &mut ids, Vec3::new(x, y, height(x, y)), th, 0.25, cr);
            }
            x += r.random_range(15.0..45.0f32);
        }
        for k in 0..3 {
            let x = 25.0 + 45.0 * k as f32 + r.random_range(0.0..20.0f32);
            let (y, yaw) = if k % 2 == 0 { (-1.6, 0.0) } else { (1.6, std::f32::consts::PI) };
            objects::car(&mut mesh, &mut ids, Vec3::new(x, y, 0.0), yaw);
        }
        objects::sign(&mut mesh, &mut ids, Vec3::new(30.0, -(cross[0] + 0.5), 0.0), std::f32::consts::PI);
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}
