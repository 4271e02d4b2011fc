//! `hill`: the ego vehicle on a steep road (`slope_deg`, up to 25 deg) that goes on up to a
//! rounded crest, falls at `descent_deg` into a rounded dip and climbs again at `rise_deg`. The
//! longitudinal gradient is piecewise linear in x (constant on the slopes, changing linearly over
//! the crest and dip lengths), so the height is its exact integral with z = 0 at the origin.

use glam::{Affine3A, Quat, Vec3};
use rand::RngExt;
use serde::Deserialize;
use sim::{SceneMesh, SemanticClass, Surface};

use super::{Family, Generated, rng};
use crate::error::{SceneError, check};
use crate::grid::{Grid, axis};
use crate::objects::{self, Ids};

/// Parameters of `hill`.
#[derive(Deserialize, Debug, Clone)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Slope under and ahead of the ego vehicle, degrees (0 ..= 25, default 18).
    pub slope_deg: f32,
    /// x of the crest's centre, metres (10 ..= 150, default 50).
    pub crest_x_m: f32,
    /// Length over which the gradient turns from climb to descent, metres (2 ..= 100, default 24).
    pub crest_length_m: f32,
    /// Slope of the descent beyond the crest, degrees (0 ..= 25, default 12).
    pub descent_deg: f32,
    /// Distance from the crest centre to the dip centre, metres (20 ..= 200, default 70).
    pub dip_distance_m: f32,
    /// Length over which the gradient turns from descent to climb, metres (2 ..= 100, default 20).
    pub dip_length_m: f32,
    /// Slope of the climb after the dip, degrees (0 ..= 25, default 6).
    pub rise_deg: f32,
    /// Road width, metres (3 ..= 20, default 7).
    pub road_width_m: f32,
    /// Side of the square terrain, metres (200 ..= 1000, default 400).
    pub size_m: f32,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            slope_deg: 18.0,
            crest_x_m: 50.0,
            crest_length_m: 24.0,
            descent_deg: 12.0,
            dip_distance_m: 70.0,
            dip_length_m: 20.0,
            rise_deg: 6.0,
            road_width_m: 7.0,
            size_m: 400.0,
        }
    }
}

/// A piecewise-linear gradient `dz/dx` given by knots; constant beyond the first and last knot.
#[derive(Debug, Clone)]
pub struct Profile {
    knots: Vec<(f32, f32)>,
}

impl Profile {
    /// Gradient at `x`.
    pub fn gradient(&self, x: f32) -> f32 {
        let k = &self.knots;
        if x <= k[0].0 {
            return k[0].1;
        }
        for w in k.windows(2) {
            if x <= w[1].0 {
                let t = (x - w[0].0) / (w[1].0 - w[0].0);
                return w[0].1 + t * (w[1].1 - w[0].1);
            }
        }
        k[k.len() - 1].1
    }

    /// Height at `x`: the integral of the gradient from 0 (exact: trapezoids between knots).
    pub fn height(&self, x: f32) -> f32 {
        let (a, b, sign) = if x >= 0.0 { (0.0, x, 1.0) } else { (x, 0.0, -1.0) };
        let mut pts = vec![a];
        pts.extend(self.knots.iter().map(|k| k.0).filter(|&kx| kx > a && kx < b));
        pts.push(b);
        let mut sum = 0.0f64;
        for w in pts.windows(2) {
            sum += 0.5 * f64::from(w[1] - w[0]) * f64::from(self.gradient(w[0]) + self.gradient(w[1]));
        }
        sign * sum as f32
    }

    /// The knot x positions.
    pub fn knot_xs(&self) -> Vec<f32> {
        self.knots.iter().map(|k| k.0).collect()
    }
}

impl Params {
    /// The road's longitudinal profile.
    pub fn profile(&self) -> Profile {
        let t = |d: f32| d.to_radians().tan();
        let (c, cl) = (self.crest_x_m, 0.5 * self.crest_length_m);
        let (d, dl) = (self.crest_x_m + self.dip_distance_m, 0.5 * self.dip_length_m);
        Profile {
            knots: vec![
                (c - cl, t(self.slope_deg)),
                (c + cl, -t(self.descent_deg)),
                (d - dl, -t(self.descent_deg)),
                (d + dl, t(self.rise_deg)),
            ],
        }
    }
}

impl Family for Params {
    fn validate(&self) -> Result<(), SceneError> {
        check("slope_deg", self.slope_deg, 0.0, 25.0)?;
        check("crest_x_m", self.crest_x_m, 10.0, 150.0)?;
        check("crest_length_m", self.crest_length_m, 2.0, 100.0)?;
        check("descent_deg", self.descent_deg, 0.0, 25.0)?;
        check("dip_distance_m", self.dip_distance_m, 20.0, 200.0)?;
        check("dip_length_m", self.dip_length_m, 2.0, 100.0)?;
        check("rise_deg", self.rise_deg, 0.0, 25.0)?;
        check("road_width_m", self.road_width_m, 3.0, 20.0)?;
        check("size_m", self.size_m, 200.0, 1000.0)?;
        if self.crest_x_m - 0.5 * self.crest_length_m < 5.0 {
            return Err(SceneError::invalid(
                "params.crest_length_m",
                self.crest_length_m,
                format!(
                    "<= 2 * (crest_x_m - 5) = {} (the ego vehicle stands on the slope)",
                    2.0 * (self.crest_x_m - 5.0)
                ),
            ));
        }
        if 0.5 * (self.crest_length_m + self.dip_length_m) > self.dip_distance_m {
            return Err(SceneError::invalid(
                "params.dip_distance_m",
                self.dip_distance_m,
                format!(">= (crest_length_m + dip_length_m) / 2 = {}", 0.5 * (self.crest_length_m + self.dip_length_m)),
            ));
        }
        Ok(())
    }

    fn build(&self, seed: u64) -> Generated {
        let half = 0.5 * self.size_m;
        let hw = 0.5 * self.road_width_m;
        let prof = self.profile();
        let xs = axis(half, 100.0, 1.0, 2.0, &prof.knot_xs(), &[]);
        let ys = axis(half, 30.0, 1.0, 2.0, &[-hw, hw], &[]);
        let mut mesh = SceneMesh::new();
        let p2 = prof.clone();
        Grid::new(xs, ys).push(
            &mut mesh,
            move |x, _| p2.height(x),
            |c| Some(Surface::stuff(if c.y.abs() < hw { SemanticClass::ROAD } else { SemanticClass::TERRAIN })),
        );
        let mut ids = Ids::default();
        let mut r = rng(seed, 17);
        let reach = half - 5.0;
        // Poles along the road, trees on the slopes, and vehicles pitched to the road.
        let mut x = -reach;
        while x < reach {
            objects::pole(&mut mesh, &mut ids, Vec3::new(x, -hw - 1.0, prof.height(x)), 6.0);
            x += 30.0;
        }
        for _ in 0..120 {
            let (x, y) = (r.random_range(-reach..reach), r.random_range(hw + 4.0..reach));
            let y = if r.random_bool(0.5) { y } else { -y };
            objects::tree(&mut mesh, &mut ids, Vec3::new(x, y, prof.height(x)), 3.0, 0.2, 2.2);
        }
        for k in 0..4 {
            let x = 20.0 + 35.0 * k as f32 + r.random_range(0.0..10.0f32);
            let (y, yaw) = if k % 2 == 0 { (-1.75, 0.0) } else { (1.75, std::f32::consts::PI) };
            let mut car = SceneMesh::new();
            objects::car(&mut car, &mut ids, Vec3::ZERO, yaw);
            let pitch = prof.gradient(x).atan();
            let at =
                Affine3A::from_rotation_translation(Quat::from_rotation_y(-pitch), Vec3::new(x, y, prof.height(x)));
            mesh.append_transformed(&car, at);
        }
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}
