//! Synthetic ordered clouds for the classifier's tests and benchmarks, independent of the
//! simulator's ray caster: a ring x column sensor at a height above a few analytic shapes (planes
//! limited to an x-y rectangle, axis-aligned boxes), cast by exact ray-shape intersection.

use glam::Vec3;
use sim::{OrderedCloud, SemanticClass};

/// A shape of a synthetic scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// The plane through `point` with `normal`, where its x-y lies in `[min_xy, max_xy]`.
    Patch {
        /// A point on the plane.
        point: Vec3,
        /// Plane normal (need not be unit).
        normal: Vec3,
        /// Lower x-y corner.
        min_xy: glam::Vec2,
        /// Upper x-y corner.
        max_xy: glam::Vec2,
        /// Semantic class.
        class: SemanticClass,
    },
    /// An axis-aligned box.
    Aabb {
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
        /// Semantic class.
        class: SemanticClass,
    },
}

impl Shape {
    /// A horizontal ground patch at height `z_m` over a rectangle.
    pub fn ground(z_m: f32, min_xy: [f32; 2], max_xy: [f32; 2]) -> Self {
        Shape::Patch {
            point: Vec3::new(0.0, 0.0, z_m),
            normal: Vec3::Z,
            min_xy: min_xy.into(),
            max_xy: max_xy.into(),
            class: SemanticClass::ROAD,
        }
    }

    /// Ray hit distance and class.
    fn hit(&self, o: Vec3, d: Vec3) -> Option<(f32, SemanticClass, Vec3)> {
        match *self {
            Shape::Patch { point, normal, min_xy, max_xy, class } => {
                let den = normal.dot(d);
                if den.abs() < 1e-9 {
                    return None;
                }
                let t = normal.dot(point - o) / den;
                let p = o + d * t;
                (t > 1e-4 && p.x >= min_xy.x && p.x <= max_xy.x && p.y >= min_xy.y && p.y <= max_xy.y)
                    .then(|| (t, class, normal.normalize() * -den.signum()))
            }
            Shape::Aabb { min, max, class } => {
                let inv = d.recip();
                let t0 = (min - o) * inv;
                let t1 = (max - o) * inv;
                let tmin = t0.min(t1);
                let tmax = t0.max(t1);
                let enter = tmin.max_element();
                let exit = tmax.min_element();
                if enter > 1e-4 && enter <= exit {
                    let axis = if enter == tmin.x {
                        0
                    } else if enter == tmin.y {
                        1
                    } else {
                        2
                    };
                    let mut n = Vec3::ZERO;
                    n[axis] = -d[axis].signum();
                    Some((enter, class, n))
                } else {
                    None
                }
            }
        }
    }
}

/// A ring x column sensor with horizontal rings, at `origin` in the vehicle frame.
#[derive(Clone, Debug, PartialEq)]
pub struct SyntheticSensor {
    /// Elevation per row, radians, increasing.
    pub elevations_rad: Vec<f32>,
    /// Columns.
    pub cols: usize,
    /// Azimuth of column 0, radians.
    pub azimuth_left_rad: f32,
    /// Azimuth step per column, radians (azimuth decreases with the column).
    pub azimuth_step_rad: f32,
    /// Beam origin in the vehicle frame.
    pub origin: Vec3,
    /// Largest range, metres.
    pub max_range_m: f32,
}

impl SyntheticSensor {
    /// A 360-degree spinning sensor with `rows` rings evenly from `lo_deg` to `hi_deg` and `cols` columns.
    pub fn spinning(rows: usize, cols: usize, lo_deg: f32, hi_deg: f32, height_m: f32) -> Self {
        let step = std::f32::consts::TAU / cols as f32;
        Self {
            elevations_rad: (0..rows)
                .map(|r| (lo_deg + (hi_deg - lo_deg) * r as f32 / (rows.max(2) - 1) as f32).to_radians())
                .collect(),
            cols,
            azimuth_left_rad: std::f32::consts::PI - 0.5 * step,
            azimuth_step_rad: step,
            origin: Vec3::new(0.0, 0.0, height_m),
            max_range_m: 120.0,
        }
    }

    /// A forward-looking sensor covering `fov_deg` of azimuth centred ahead.
    pub fn forward(rows: usize, cols: usize, lo_deg: f32, hi_deg: f32, fov_deg: f32, height_m: f32) -> Self {
        let step = fov_deg.to_radians() / cols as f32;
        Self {
            azimuth_left_rad: 0.5 * fov_deg.to_radians() - 0.5 * step,
            azimuth_step_rad: step,
            ..Self::spinning(rows, cols, lo_deg, hi_deg, height_m)
        }
    }

    /// Unit beam direction of `(row, col)`.
    pub fn direction(&self, row: usize, col: usize) -> Vec3 {
        let e = self.elevations_rad[row];
        let a = self.azimuth_left_rad - col as f32 * self.azimuth_step_rad;
        Vec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
    }

    /// Casts every beam against `shapes` and returns the ordered labelled cloud (one plane).
    pub fn scan(&self, shapes: &[Shape]) -> OrderedCloud {
        let (rows, cols) = (self.elevations_rad.len(), self.cols);
        let mut cloud = OrderedCloud::empty(rows, cols, 1);
        for r in 0..rows {
            for c in 0..cols {
                let i = r * cols + c;
                cloud.ring[i] = r as u16;
                cloud.column[i] = c as u32;
                cloud.sensor[i] = 0;
                let d = self.direction(r, c);
                let hit = shapes
                    .iter()
                    .filter_map(|s| s.hit(self.origin, d))
                    .filter(|h| h.0 <= self.max_range_m)
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                if let Some((t, class, n)) = hit {
                    cloud.point_in_vehicle[i] = self.origin + d * t;
                    cloud.range_m[i] = t;
                    cloud.label[i] = class;
                    cloud.ground[i] = class.is_ground();
                    cloud.normal[i] = n;
                    cloud.intensity[i] = 0.5;
                }
            }
        }
        cloud
    }
}

/// A car-sized box (class car) with its footprint centred at `(x, y)` on ground at height `z`.
pub fn car(x: f32, y: f32, z: f32) -> Shape {
    Shape::Aabb {
        min: Vec3::new(x - 2.2, y - 0.9, z),
        max: Vec3::new(x + 2.2, y + 0.9, z + 1.5),
        class: SemanticClass::CAR,
    }
}

/// A flat ground plane 200 m across at z = 0.
pub fn flat_ground() -> Shape {
    Shape::ground(0.0, [-100.0, -100.0], [100.0, 100.0])
}

/// The 128 x 2048 benchmark frame: a spinning sensor 1.8 m up over flat ground with a few cars and
/// a building wall.
pub fn benchmark_frame() -> OrderedCloud {
    let sensor = SyntheticSensor::spinning(128, 2048, -25.0, 15.0, 1.8);
    let shapes = [
        flat_ground(),
        car(10.0, 3.0, 0.0),
        car(-12.0, -3.0, 0.0),
        car(20.0, -6.0, 0.0),
        Shape::Aabb {
            min: Vec3::new(-50.0, 15.0, 0.0),
            max: Vec3::new(50.0, 20.0, 12.0),
            class: SemanticClass::BUILDING,
        },
    ];
    sensor.scan(&shapes)
}

/// A small frame with two cars on flat ground (24 rows; spinning 360 columns or a 90 deg forward
/// sensor of 200), a fraction `drop` of returns removed and uniform z noise of +-`z_noise_m`, from
/// Xoshiro256++ seeded with `seed`: the test frame of the equivalence tests of the fast paths.
pub fn noisy_cars_frame(drop: f32, seed: u64, spinning: bool, z_noise_m: f32) -> OrderedCloud {
    use rand::{RngExt, SeedableRng};
    let shapes = [flat_ground(), car(6.0, 1.0, 0.0), car(-9.0, -2.0, 0.0)];
    let sensor = if spinning {
        SyntheticSensor::spinning(24, 360, -25.0, 5.0, 1.8)
    } else {
        SyntheticSensor::forward(24, 200, -25.0, 5.0, 90.0, 1.8)
    };
    let mut cloud = sensor.scan(&shapes);
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    for i in 0..cloud.point_in_vehicle.len() {
        if rng.random::<f32>() < drop {
            cloud.point_in_vehicle[i] = Vec3::NAN;
            cloud.range_m[i] = f32::NAN;
        } else {
            cloud.point_in_vehicle[i].z += (rng.random::<f32>() * 2.0 - 1.0) * z_noise_m;
        }
    }
    cloud
}
