//! `basin`: a straight road along x with a rain-water basin beside it (seed 000, Fig. 1 and 12):
//! `depth_m` deep, a flat bottom `bottom_width_m` wide, banks at `bank_slope_deg` on all four
//! sides, and flat ground at road level beyond it (the "elevated target" after a lowered surface).
//! Grid lines run along every bank edge, so the bottom lies exactly at `-depth_m`.

use glam::Vec3;
use rand::RngExt;
use serde::Deserialize;
use sim::{SceneMesh, SemanticClass, Surface};

use super::{Family, Generated, rng};
use crate::error::{SceneError, check};
use crate::grid::{Grid, axis};
use crate::objects::{self, Ids};

/// Which side of the road the basin is on.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// -y (right of the ego vehicle), as in Fig. 12.
    Right,
    /// +y.
    Left,
}

/// Parameters of `basin`.
#[derive(Deserialize, Debug, Clone)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Basin depth below road level, metres (0.2 ..= 10, default 2).
    pub depth_m: f32,
    /// Width of the flat bottom across the road direction, metres (0 ..= 100, default 8).
    pub bottom_width_m: f32,
    /// Bank slope, degrees (5 ..= 60, default 30).
    pub bank_slope_deg: f32,
    /// Length of the basin (top edge to top edge) along the road, metres (10 ..= 300, default 80).
    pub length_m: f32,
    /// x where the basin's top edge begins, metres (-150 ..= 150, default -10).
    pub start_x_m: f32,
    /// Road width, metres (3 ..= 30, default 7).
    pub road_width_m: f32,
    /// Grass strip between road edge and the basin's top edge, metres (0 ..= 20, default 2).
    pub shoulder_m: f32,
    /// Side of the road: "right" (-y) or "left" (+y), default "right".
    pub side: Side,
    /// Side of the square terrain, metres (200 ..= 1000, default 400).
    pub size_m: f32,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            depth_m: 2.0,
            bottom_width_m: 8.0,
            bank_slope_deg: 30.0,
            length_m: 80.0,
            start_x_m: -10.0,
            road_width_m: 7.0,
            shoulder_m: 2.0,
            side: Side::Right,
            size_m: 400.0,
        }
    }
}

/// A trapezoid profile: 0 outside `[a, d]`, rising linearly on `[a, b]`, 1 on `[b, c]`, falling on `[c, d]`.
pub fn trapezoid(v: f32, [a, b, c, d]: [f32; 4]) -> f32 {
    if v <= a || v >= d {
        0.0
    } else if v < b {
        (v - a) / (b - a)
    } else if v <= c {
        1.0
    } else {
        (d - v) / (d - c)
    }
}

impl Params {
    fn bank_run_m(&self) -> f32 {
        self.depth_m / self.bank_slope_deg.to_radians().tan()
    }

    /// Basin edges across the road (|y| from the road centre line): top, bottom, bottom, top.
    pub fn cross_edges(&self) -> [f32; 4] {
        let a = 0.5 * self.road_width_m + self.shoulder_m;
        let r = self.bank_run_m();
        [a, a + r, a + r + self.bottom_width_m, a + 2.0 * r + self.bottom_width_m]
    }

    /// Basin edges along the road: top, bottom, bottom, top.
    pub fn along_edges(&self) -> [f32; 4] {
        let r = self.bank_run_m();
        let a = self.start_x_m;
        [a, a + r, a + self.length_m - r, a + self.length_m]
    }

    fn sign(&self) -> f32 {
        if self.side == Side::Right { -1.0 } else { 1.0 }
    }
}

impl Family for Params {
    fn validate(&self) -> Result<(), SceneError> {
        check("depth_m", self.depth_m, 0.2, 10.0)?;
        check("bottom_width_m", self.bottom_width_m, 0.0, 100.0)?;
        check("bank_slope_deg", self.bank_slope_deg, 5.0, 60.0)?;
        check("length_m", self.length_m, 10.0, 300.0)?;
        check("start_x_m", self.start_x_m, -150.0, 150.0)?;
        check("road_width_m", self.road_width_m, 3.0, 30.0)?;
        check("shoulder_m", self.shoulder_m, 0.0, 20.0)?;
        check("size_m", self.size_m, 200.0, 1000.0)?;
        let [_, b, c, _] = self.along_edges();
        if c < b {
            return Err(SceneError::invalid(
                "params.length_m",
                self.length_m,
                format!(">= 2 * depth_m / tan(bank_slope_deg) = {}", 2.0 * self.bank_run_m()),
            ));
        }
        let far = self.cross_edges()[3].max(self.along_edges()[3]).max(-self.start_x_m);
        if far > 0.5 * self.size_m - 10.0 {
            return Err(SceneError::invalid("params.size_m", self.size_m, format!(">= {}", 2.0 * (far + 10.0))));
        }
        Ok(())
    }

    fn build(&self, seed: u64) -> Generated {
        let half = 0.5 * self.size_m;
        let hw = 0.5 * self.road_width_m;
        let s = self.sign();
        let cross = self.cross_edges();
        let along = self.along_edges();
        let ybreaks: Vec<f32> = cross.iter().map(|e| s * e).chain([-hw, hw]).collect();
        let xs = axis(half, 80.0, 1.0, 2.0, &along, &[]);
        let ys = axis(half, 50.0, 1.0, 2.0, &ybreaks, &[]);
        let height = |x: f32, y: f32| -self.depth_m * trapezoid(x, along).min(trapezoid(s * y, cross));
        let mut mesh = SceneMesh::new();
        Grid::new(xs, ys).push(&mut mesh, height, |c| {
            Some(Surface::stuff(if c.y.abs() < hw { SemanticClass::ROAD } else { SemanticClass::TERRAIN }))
        });
        let mut ids = Ids::default();
        let mut r = rng(seed, 3);
        // Posts along the road side opposite the basin, a tree line beyond the basin on the
        // level ground (the elevated target), traffic on the road.
        let mut x = -half + 10.0;
        while x < half - 10.0 {
            objects::pole(&mut mesh, &mut ids, Vec3::new(x, -s * (hw + 1.5), 0.0), 7.0);
            x += 40.0;
        }
        let beyond = s * (cross[3] + 6.0);
        let mut x = along[0] - 20.0;
        while x < along[3] + 20.0 {
            let jitter = r.random_range(-2.0..2.0);
            objects::tree(&mut mesh, &mut ids, Vec3::new(x + jitter, beyond, 0.0), 2.5, 0.2, 2.0);
            x += 10.0;
        }
        for _ in 0..4 {
            let x = r.random_range(15.0..150.0f32);
            let lane = if r.random_bool(0.5) { 1.75 } else { -1.75 };
            let yaw = if lane < 0.0 { 0.0 } else { std::f32::consts::PI };
            objects::car(&mut mesh, &mut ids, Vec3::new(x, lane, 0.0), yaw);
        }
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}
