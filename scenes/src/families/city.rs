//! `city`: a main street along x crossed by side streets, raised sidewalks with vertical curbs
//! (`curb_height_m`, class sidewalk), buildings along the blocks, parked and moving cars,
//! pedestrians, street lights, signs and street trees. The centre line is a dashed marking cut
//! out of the road surface (exactly coplanar).

use glam::Vec3;
use rand::RngExt;
use serde::Deserialize;
use sim::{SceneMesh, SemanticClass, Surface};

use super::{Family, Generated, rng};
use crate::error::{SceneError, check};
use crate::grid::{Grid, axis};
use crate::objects::{self, Ids};

/// Parameters of `city`.
#[derive(Deserialize, Debug, Clone)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Carriageway width (kerb to kerb), metres (6 ..= 30, default 12).
    pub road_width_m: f32,
    /// Sidewalk width, metres (1.5 ..= 10, default 4).
    pub sidewalk_width_m: f32,
    /// Curb height, metres (0.05 ..= 0.3, default 0.12).
    pub curb_height_m: f32,
    /// Distance between side streets, metres (40 ..= 300, default 80); side streets at x = ±spacing/2, ±3 spacing/2, ...
    pub block_length_m: f32,
    /// Fraction of parking spots taken (0 ..= 1, default 0.6).
    pub parking_occupancy: f32,
    /// Pedestrians per 100 m of sidewalk (0 ..= 50, default 6).
    pub pedestrians_per_100m: f32,
    /// Side of the square terrain, metres (200 ..= 1000, default 400).
    pub size_m: f32,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            road_width_m: 12.0,
            sidewalk_width_m: 4.0,
            curb_height_m: 0.12,
            block_length_m: 80.0,
            parking_occupancy: 0.6,
            pedestrians_per_100m: 6.0,
            size_m: 400.0,
        }
    }
}

/// Centre-line dash and gap, metres (multiples of the 2 m grid).
const DASH_M: f32 = 4.0;
const DASH_PERIOD_M: f32 = 12.0;

impl Family for Params {
    fn validate(&self) -> Result<(), SceneError> {
        check("road_width_m", self.road_width_m, 6.0, 30.0)?;
        check("sidewalk_width_m", self.sidewalk_width_m, 1.5, 10.0)?;
        check("curb_height_m", self.curb_height_m, 0.05, 0.3)?;
        check("block_length_m", self.block_length_m, 40.0, 300.0)?;
        check("parking_occupancy", self.parking_occupancy, 0.0, 1.0)?;
        check("pedestrians_per_100m", self.pedestrians_per_100m, 0.0, 50.0)?;
        check("size_m", self.size_m, 200.0, 1000.0)
    }

    fn build(&self, seed: u64) -> Generated {
        let half = 0.5 * self.size_m;
        let hw = 0.5 * self.road_width_m;
        let sw = self.sidewalk_width_m;
        let curb = self.curb_height_m;
        let bl = self.block_length_m;
        let mut cross_x = Vec::new();
        let mut k = 0.5 * bl;
        while k < half - hw - 5.0 {
            cross_x.extend([k, -k]);
            k += bl;
        }
        cross_x.sort_by(f32::total_cmp);
        let on_road = |x: f32, y: f32| y.abs() < hw || cross_x.iter().any(|cx| (x - cx).abs() < hw);
        let near_road = |x: f32, y: f32| y.abs() < hw + sw || cross_x.iter().any(|cx| (x - cx).abs() < hw + sw);
        let xsteps: Vec<f32> = cross_x.iter().flat_map(|cx| [cx - hw, cx + hw]).collect();
        let xbreaks: Vec<f32> = cross_x.iter().flat_map(|cx| [cx - hw - sw, cx + hw + sw]).collect();
        let xs = axis(half, 80.0, 1.0, 2.0, &xbreaks, &xsteps);
        let ys = axis(half, 40.0, 1.0, 2.0, &[-hw - sw, hw + sw, -0.075, 0.075], &[-hw, hw]);
        let mut mesh = SceneMesh::new();
        Grid::new(xs, ys).push(
            &mut mesh,
            |x, y| if on_road(x, y) { 0.0 } else { curb },
            |c| {
                let class = if c.vertical {
                    SemanticClass::SIDEWALK
                } else if on_road(c.x, c.y) {
                    let centre = c.y.abs() < 0.075 && !cross_x.iter().any(|cx| (c.x - cx).abs() < hw + 1.0);
                    if centre && (c.x + 1000.0 * DASH_PERIOD_M).rem_euclid(DASH_PERIOD_M) < DASH_M {
                        SemanticClass::LANE_MARKING
                    } else {
                        SemanticClass::ROAD
                    }
                } else if near_road(c.x, c.y) {
                    SemanticClass::SIDEWALK
                } else {
                    SemanticClass::OTHER_GROUND
                };
                Some(Surface::stuff(class))
            },
        );
        let mut ids = Ids::default();
        let mut r = rng(seed, 11);
        let reach = half - 4.0;
        // Blocks between consecutive side streets (and the terrain edges).
        let mut edges = vec![-reach];
        edges.extend(cross_x.iter().flat_map(|cx| [cx - hw - sw, cx + hw + sw]));
        edges.push(reach);
        let blocks: Vec<(f32, f32)> =
            edges.chunks_exact(2).map(|c| (c[0], c[1])).filter(|(a, b)| b - a > 8.0).collect();
        for &(x0, x1) in &blocks {
            for side in [-1.0f32, 1.0] {
                // Buildings along the block face, set back 1 m from the sidewalk.
                let mut x = x0 + 1.0;
                while x < x1 - 6.0 {
                    let len = r.random_range(12.0..30.0f32).min(x1 - 1.0 - x);
                    let depth = r.random_range(12.0..20.0f32);
                    let height = r.random_range(8.0..30.0f32);
                    let y = side * (hw + sw + 1.0 + 0.5 * depth);
                    objects::building(
                        &mut mesh,
                        &mut ids,
                        Vec3::new(x + 0.5 * len, y, curb),
                        0.0,
                        Vec3::new(len, depth, height),
                    );
                    x += len + r.random_range(1.0..4.0f32);
                }
                // Parked cars along the curb, street furniture on the sidewalk.
                let mut x = x0 + 3.0;
                while x < x1 - 3.0 {
                    let yaw = if side < 0.0 { 0.0 } else { std::f32::consts::PI };
                    if r.random_bool(f64::from(self.parking_occupancy)) && !(x.abs() < 4.0 && side < 0.0) {
                        objects::car(&mut mesh, &mut ids, Vec3::new(x + 2.5, side * (hw - 1.1), 0.0), yaw);
                    }
                    x += 6.0;
                }
                let mut x = x0 + 5.0;
                let mut n = 0;
                while x < x1 - 2.0 {
                    let y_edge = side * (hw + 0.6);
                    match n % 3 {
                        0 => objects::pole(&mut mesh, &mut ids, Vec3::new(x, y_edge, curb), 7.5),
                        _ => objects::tree(&mut mesh, &mut ids, Vec3::new(x, y_edge, curb), 2.8, 0.15, 1.8),
                    };
                    n += 1;
                    x += 12.0;
                }
                let peds = (self.pedestrians_per_100m * (x1 - x0) / 100.0).round() as u32;
                for _ in 0..peds {
                    let p = Vec3::new(
                        r.random_range(x0 + 1.0..x1 - 1.0),
                        side * r.random_range(hw + 1.2..hw + sw - 0.5),
                        curb,
                    );
                    objects::pedestrian(&mut mesh, &mut ids, p, r.random_range(0.0..std::f32::consts::TAU));
                }
            }
        }
        // Signs at the corners and moving traffic on the main street.
        for &cx in &cross_x {
            objects::sign(&mut mesh, &mut ids, Vec3::new(cx - hw - 0.8, -hw - 0.8, curb), std::f32::consts::PI);
        }
        let lanes = [(-0.25 * self.road_width_m, 0.0), (0.25 * self.road_width_m, std::f32::consts::PI)];
        for (y, yaw) in lanes {
            let mut x = -reach + r.random_range(0.0..30.0f32);
            while x < reach - 5.0 {
                if !(y < 0.0 && x.abs() < 10.0) {
                    objects::car(&mut mesh, &mut ids, Vec3::new(x, y, 0.0), yaw);
                }
                x += r.random_range(15.0..60.0f32);
            }
        }
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}
