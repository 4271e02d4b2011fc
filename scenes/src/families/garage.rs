//! `garage`: a multi-level car park seen from its ground floor (seed 000, Fig. 11: one ramp up on
//! the left, one ramp down on the right). Level 0 is the ground at z = 0; level 1's floor slab
//! is at `floor_height_m`, with an opening over the up-ramp; level -1 lies `floor_height_m` below,
//! reached by the down-ramp cut into the ground and covered by level 0's slab. Pillars, parked
//! cars on every level, ceilings (slab undersides, class other-structure), a roof and outer walls
//! with an entrance behind the ego vehicle. Floors and ramps are ground (parking / road).

use glam::Vec3;
use rand::RngExt;
use serde::Deserialize;
use sim::{SceneMesh, SemanticClass, Surface};

use super::ramp::sheared_box;
use super::{Family, Generated, rng};
use crate::error::{SceneError, check};
use crate::grid::{Grid, axis};
use crate::objects::{self, Ids};

/// Parameters of `garage`.
#[derive(Deserialize, Debug, Clone)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Height from one floor to the next, metres (2.4 ..= 5, default 3).
    pub floor_height_m: f32,
    /// Slope of both ramps, degrees (4 ..= 20, default 10).
    pub ramp_slope_deg: f32,
    /// Distance from the ego origin to the foot of the ramps, metres (5 ..= 40, default 15).
    pub ramp_distance_m: f32,
    /// Ramp width, metres (3 ..= 8, default 4).
    pub ramp_width_m: f32,
    /// Fraction of parking bays taken (0 ..= 1, default 0.6).
    pub occupancy: f32,
}

impl Default for Params {
    fn default() -> Self {
        Self { floor_height_m: 3.0, ramp_slope_deg: 10.0, ramp_distance_m: 15.0, ramp_width_m: 4.0, occupancy: 0.6 }
    }
}

/// Slab thickness, metres.
const SLAB_M: f32 = 0.3;
/// Half-width of the garage (y), metres.
const HALF_WIDTH_M: f32 = 22.0;
/// x of the entrance wall, metres.
const FRONT_X_M: f32 = -30.0;
/// |y| of the near edge of each ramp corridor, metres.
const RAMP_INNER_Y_M: f32 = 2.0;

/// A box with its own surface on top (a floor) and another on its other faces (slab edges, ceiling).
fn floor_slab(mesh: &mut SceneMesh, min: Vec3, max: Vec3, top: Surface, rest: Surface) {
    let n0 = mesh.len();
    mesh.push_box(min, max, rest);
    // push_box emits the top face (+z) as its second quad: triangles 2 and 3.
    mesh.surfaces[n0 + 2] = top;
    mesh.surfaces[n0 + 3] = top;
}

impl Family for Params {
    fn validate(&self) -> Result<(), SceneError> {
        check("floor_height_m", self.floor_height_m, 2.4, 5.0)?;
        check("ramp_slope_deg", self.ramp_slope_deg, 4.0, 20.0)?;
        check("ramp_distance_m", self.ramp_distance_m, 5.0, 40.0)?;
        check("ramp_width_m", self.ramp_width_m, 3.0, 8.0)?;
        check("occupancy", self.occupancy, 0.0, 1.0)
    }

    fn build(&self, seed: u64) -> Generated {
        let h = self.floor_height_m;
        let tan = self.ramp_slope_deg.to_radians().tan();
        let (x0, x1) = (self.ramp_distance_m, self.ramp_distance_m + h / tan);
        let xe = x1 + 40.0;
        let (yr0, yr1) = (RAMP_INNER_Y_M, RAMP_INNER_Y_M + self.ramp_width_m);
        let hy = HALF_WIDTH_M;
        let in_footprint = |x: f32, y: f32| x > FRONT_X_M && x < xe && y.abs() < hy;
        let in_pit = |x: f32, y: f32| x > x1 && x < xe && y.abs() < hy;
        let in_down = |x: f32, y: f32| x > x0 && x < x1 && y > -yr1 && y < -yr0;
        let half = 100.0f32.max(xe + 20.0);
        let xs = axis(half, 100.0, 1.0, 2.0, &[x0, FRONT_X_M], &[x1, xe]);
        let ys = axis(half, 30.0, 1.0, 2.0, &[-4.0, 4.0], &[-yr1, -yr0, -hy, hy]);
        let mut mesh = SceneMesh::new();
        Grid::new(xs, ys).push(
            &mut mesh,
            |x, y| {
                if in_pit(x, y) {
                    -h
                } else if in_down(x, y) {
                    -(x - x0) * tan
                } else {
                    0.0
                }
            },
            |c| {
                let class = if c.vertical {
                    if c.x > x0 && c.x < x1 { SemanticClass::FENCE } else { SemanticClass::OTHER_STRUCTURE }
                } else if in_down(c.x, c.y) {
                    SemanticClass::ROAD
                } else if in_footprint(c.x, c.y) {
                    SemanticClass::PARKING
                } else if c.y.abs() < 4.0 && c.x < FRONT_X_M {
                    SemanticClass::ROAD
                } else {
                    SemanticClass::TERRAIN
                };
                Some(Surface::stuff(class))
            },
        );
        let mut ids = Ids::default();
        let slab = |mesh: &mut SceneMesh, ids: &mut Ids, min: Vec3, max: Vec3, floor: bool| {
            let id = ids.fresh();
            let rest = Surface::object(SemanticClass::OTHER_STRUCTURE, id);
            let top = if floor { Surface::stuff(SemanticClass::PARKING) } else { rest };
            floor_slab(mesh, min, max, top, rest);
        };
        // Level 0 over the pit; level 1 around the up-ramp opening; the roof.
        slab(&mut mesh, &mut ids, Vec3::new(x1, -hy, -SLAB_M), Vec3::new(xe, hy, 0.0), true);
        let (lo, hi) = (h - SLAB_M, h);
        slab(&mut mesh, &mut ids, Vec3::new(FRONT_X_M, -hy, lo), Vec3::new(x0, hy, hi), true);
        slab(&mut mesh, &mut ids, Vec3::new(x1, -hy, lo), Vec3::new(xe, hy, hi), true);
        slab(&mut mesh, &mut ids, Vec3::new(x0, -hy, lo), Vec3::new(x1, yr0, hi), true);
        slab(&mut mesh, &mut ids, Vec3::new(x0, yr1, lo), Vec3::new(x1, hy, hi), true);
        slab(&mut mesh, &mut ids, Vec3::new(FRONT_X_M, -hy, 2.0 * h - SLAB_M), Vec3::new(xe, hy, 2.0 * h), false);
        // The up-ramp: a wedge from level 0 to level 1 with parapets.
        let road = Surface::stuff(SemanticClass::ROAD);
        let side = Surface::object(SemanticClass::FENCE, ids.fresh());
        let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        mesh.push_quad([p(x0, yr0, 0.0), p(x1, yr0, h), p(x1, yr1, h), p(x0, yr1, 0.0)], road);
        let a = mesh.push_vertex(p(x0, yr0, 0.0));
        let b = mesh.push_vertex(p(x1, yr0, 0.0));
        let c = mesh.push_vertex(p(x1, yr0, h));
        mesh.push_triangle([a, b, c], side);
        let a = mesh.push_vertex(p(x0, yr1, 0.0));
        let b = mesh.push_vertex(p(x1, yr1, 0.0));
        let c = mesh.push_vertex(p(x1, yr1, h));
        mesh.push_triangle([a, c, b], side);
        let parapet = Surface::object(SemanticClass::FENCE, ids.fresh());
        for y in [yr0 - 0.1, yr1 + 0.1] {
            sheared_box(&mut mesh, p(x0, y, 0.0), p(x1, y, h), (-0.2, 0.9), parapet);
        }
        // Outer walls; the entrance (|y| < 4, below 2.5 m) in the front wall.
        let wall = |mesh: &mut SceneMesh, ids: &mut Ids, min: Vec3, max: Vec3| {
            mesh.push_box(min, max, Surface::object(SemanticClass::BUILDING, ids.fresh()));
        };
        let top = 2.0 * h + 1.0;
        wall(&mut mesh, &mut ids, p(xe, -hy - 0.3, -h), p(xe + 0.3, hy + 0.3, top));
        wall(&mut mesh, &mut ids, p(FRONT_X_M, hy, -0.3), p(xe, hy + 0.3, top));
        wall(&mut mesh, &mut ids, p(FRONT_X_M, -hy - 0.3, -0.3), p(xe, -hy, top));
        wall(&mut mesh, &mut ids, p(FRONT_X_M - 0.3, -hy, -0.3), p(FRONT_X_M, -4.0, top));
        wall(&mut mesh, &mut ids, p(FRONT_X_M - 0.3, 4.0, -0.3), p(FRONT_X_M, hy, top));
        wall(&mut mesh, &mut ids, p(FRONT_X_M - 0.3, -4.0, 2.5), p(FRONT_X_M, 4.0, top));
        // Pillars and parked cars on each level, in bays between pillar lines at |y| = 9.5 and 15.8.
        let mut r = rng(seed, 23);
        let levels = [(-h, x1 + 1.0), (0.0, FRONT_X_M + 2.0), (h, FRONT_X_M + 2.0)];
        for (z, start) in levels {
            let mut x = start + 1.0;
            while x < xe - 2.0 {
                for y in [-15.8f32, -9.5, 9.5, 15.8] {
                    objects::slab(&mut mesh, &mut ids, p(x - 0.25, y - 0.25, z), p(x + 0.25, y + 0.25, z + h - SLAB_M));
                }
                for k in 0..3 {
                    let cx = x + 1.25 + 2.5 * k as f32;
                    if cx > xe - 3.0 {
                        break;
                    }
                    for y in [-19.2f32, -12.7, 12.7, 19.2] {
                        if r.random_bool(f64::from(self.occupancy)) {
                            let yaw = if y > 0.0 { -std::f32::consts::FRAC_PI_2 } else { std::f32::consts::FRAC_PI_2 };
                            objects::car(&mut mesh, &mut ids, p(cx, y, z), yaw);
                        }
                    }
                }
                x += 7.5;
            }
        }
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}
