//! `ramp`: the ego vehicle on flat ground approaching a parking-garage ramp (seed 000, Fig. 4 and
//! 11). A corridor `width_m` wide starts `distance_m` ahead, climbs (or descends, for a negative
//! slope) at `slope_deg` over `length_m` of horizontal run, then continues level for `landing_m`
//! and ends in a vertical face (the garage). The corridor sides are vertical retaining faces
//! (class fence) with walls or railings along them.
//!
//! The ramp surface is bounded by grid lines at its start and end, so every ramp triangle lies
//! exactly in the plane of the requested slope.

use glam::{Affine3A, Vec3};
use serde::Deserialize;
use sim::{SceneMesh, SemanticClass, Surface};

use super::{Family, Generated};
use crate::error::{SceneError, check};
use crate::grid::{Grid, axis};
use crate::objects::{self, Ids};

/// What stands along the ramp's sides.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Sides {
    /// Concrete walls (class fence), `wall_height_m` above the ramp surface.
    Walls,
    /// Guard rails (class fence) on the corridor edges.
    Railings,
    /// Nothing but the retaining faces.
    None,
}

/// Parameters of `ramp`.
#[derive(Deserialize, Debug, Clone)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Ramp slope, degrees; positive climbs, negative descends (-20 ..= 20, default 12).
    pub slope_deg: f32,
    /// Horizontal run of the sloped part, metres (2 ..= 100, default 20).
    pub length_m: f32,
    /// Distance from the ego origin to the foot of the ramp, metres (3 ..= 100, default 15).
    pub distance_m: f32,
    /// Corridor width, metres (3 ..= 20, default 6).
    pub width_m: f32,
    /// Level landing after the slope, metres (0 ..= 100, default 20).
    pub landing_m: f32,
    /// Side structures: "walls", "railings" or "none" (default "walls").
    pub sides: Sides,
    /// Wall height above the ramp surface, metres (0.3 ..= 4, default 1.1).
    pub wall_height_m: f32,
    /// Side of the square terrain, metres (100 ..= 1000, default 400).
    pub size_m: f32,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            slope_deg: 12.0,
            length_m: 20.0,
            distance_m: 15.0,
            width_m: 6.0,
            landing_m: 20.0,
            sides: Sides::Walls,
            wall_height_m: 1.1,
            size_m: 400.0,
        }
    }
}

impl Params {
    /// Height of the corridor floor at `x` (0 before the ramp), metres.
    pub fn profile_z(&self, x: f32) -> f32 {
        let t = self.slope_deg.to_radians().tan();
        (x - self.distance_m).clamp(0.0, self.length_m) * t
    }

    /// x of the corridor's end face, metres.
    pub fn end_x(&self) -> f32 {
        self.distance_m + self.length_m + self.landing_m
    }
}

impl Family for Params {
    fn validate(&self) -> Result<(), SceneError> {
        check("slope_deg", self.slope_deg, -20.0, 20.0)?;
        check("length_m", self.length_m, 2.0, 100.0)?;
        check("distance_m", self.distance_m, 3.0, 100.0)?;
        check("width_m", self.width_m, 3.0, 20.0)?;
        check("landing_m", self.landing_m, 0.0, 100.0)?;
        check("wall_height_m", self.wall_height_m, 0.3, 4.0)?;
        check("size_m", self.size_m, 100.0, 1000.0)?;
        if self.end_x() > 0.5 * self.size_m - 5.0 {
            return Err(SceneError::invalid(
                "params.size_m",
                self.size_m,
                format!(">= 2 * (distance_m + length_m + landing_m + 5) = {}", 2.0 * (self.end_x() + 5.0)),
            ));
        }
        Ok(())
    }

    fn build(&self, _seed: u64) -> Generated {
        let half = 0.5 * self.size_m;
        let hw = 0.5 * self.width_m;
        let (x0, x1, xe) = (self.distance_m, self.distance_m + self.length_m, self.end_x());
        let mut mesh = SceneMesh::new();
        let xs = axis(half, 80.0, 1.0, 2.0, &[x0, x1], &[xe]);
        let ys = axis(half, 40.0, 1.0, 2.0, &[], &[-hw, hw]);
        let inside = |x: f32, y: f32| y.abs() < hw && x < xe;
        let up = self.slope_deg >= 0.0;
        Grid::new(xs, ys).push(
            &mut mesh,
            |x, y| if inside(x, y) { self.profile_z(x) } else { 0.0 },
            |c| {
                let class = if c.vertical {
                    if c.x == xe && up {
                        SemanticClass::OTHER_STRUCTURE
                    } else if c.x == xe {
                        SemanticClass::BUILDING
                    } else {
                        SemanticClass::FENCE
                    }
                } else if inside(c.x, c.y) {
                    if c.x > x1 { SemanticClass::PARKING } else { SemanticClass::ROAD }
                } else if c.y.abs() < hw + 15.0 && c.x < xe + 10.0 && c.x > -40.0 {
                    SemanticClass::OTHER_GROUND
                } else {
                    SemanticClass::TERRAIN
                };
                Some(Surface::stuff(class))
            },
        );
        let mut ids = Ids::default();
        let h_end = self.profile_z(x1);
        for side in [-1.0f32, 1.0] {
            // Walls stand flush against the corridor edge (0.2 m thick, outside it); railing posts
            // stand 0.15 m outside it.
            let y = side * (hw + if self.sides == Sides::Walls { 0.1 } else { 0.15 });
            match self.sides {
                Sides::None => {}
                Sides::Railings if up => {
                    let id = ids.fresh();
                    rail_segment(&mut mesh, id, Vec3::new(x0, y, 0.0), Vec3::new(x1, y, h_end));
                    rail_segment(&mut mesh, id, Vec3::new(x1, y, h_end), Vec3::new(xe, y, h_end));
                }
                Sides::Railings => {
                    let id = ids.fresh();
                    rail_segment(&mut mesh, id, Vec3::new(x0, y, 0.0), Vec3::new(xe, y, 0.0));
                }
                Sides::Walls if up => {
                    let id = ids.fresh();
                    let s = Surface::object(SemanticClass::FENCE, id);
                    let depth = h_end + 0.3;
                    sheared_box(
                        &mut mesh,
                        Vec3::new(x0, y, 0.0),
                        Vec3::new(x1, y, h_end),
                        (-depth, self.wall_height_m),
                        s,
                    );
                    sheared_box(
                        &mut mesh,
                        Vec3::new(x1, y, h_end),
                        Vec3::new(xe, y, h_end),
                        (-depth, self.wall_height_m),
                        s,
                    );
                }
                Sides::Walls => {
                    let id = ids.fresh();
                    let s = Surface::object(SemanticClass::FENCE, id);
                    sheared_box(&mut mesh, Vec3::new(x0, y, 0.0), Vec3::new(xe, y, 0.0), (-0.3, self.wall_height_m), s);
                }
            }
        }
        // A sign at the foot of the ramp and the garage's front wall across the end face.
        objects::sign(&mut mesh, &mut ids, Vec3::new(x0 - 2.0, -hw - 1.0, 0.0), std::f32::consts::PI);
        let front_top = if up { h_end + 3.0 } else { 3.0 };
        let front_bottom = if up { h_end + 2.4 } else { 0.0 };
        if front_top > front_bottom {
            objects::slab(
                &mut mesh,
                &mut ids,
                Vec3::new(xe, -hw - 4.0, front_bottom),
                Vec3::new(xe + 0.4, hw + 4.0, front_top),
            );
        }
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}

/// A box 0.2 m thick whose bottom and top edges run from `a` to `b` (following a slope), spanning
/// `z_rel` below/above that line.
pub fn sheared_box(mesh: &mut SceneMesh, a: Vec3, b: Vec3, (z_lo, z_hi): (f32, f32), s: Surface) {
    let d = b - a;
    let len = d.truncate().length().max(1e-6);
    let dir = d.truncate() / len;
    let at = Affine3A::from_cols(
        Vec3::new(dir.x, dir.y, d.z / len).into(),
        Vec3::new(-dir.y, dir.x, 0.0).into(),
        Vec3::Z.into(),
        a.into(),
    );
    mesh.push_oriented_box(at, Vec3::new(0.0, -0.1, z_lo), Vec3::new(len, 0.1, z_hi), s);
}

/// A railing segment: posts every 2 m (0.9 m tall) and a top rail following the slope from `a` to `b`.
fn rail_segment(mesh: &mut SceneMesh, id: u32, a: Vec3, b: Vec3) {
    let s = Surface::object(SemanticClass::FENCE, id);
    let d = b - a;
    let len = d.truncate().length();
    let n = (len / 2.0).floor() as u32;
    for k in 0..=n {
        let p = a + d * (k as f32 * 2.0 / len.max(1e-6));
        mesh.push_box(p + Vec3::new(-0.04, -0.04, -0.2), p + Vec3::new(0.04, 0.04, 0.9), s);
    }
    sheared_box(mesh, a, b, (0.8, 0.95), s);
}
