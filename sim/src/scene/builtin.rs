//! The simulator's built-in scenes: `flat` (open flat ground) and `flat-objects` (flat ground with a
//! box and a car-sized object). The full, seeded scene library lives in the `scenes` crate.

use glam::Vec3;

use super::{SceneMesh, SemanticClass, Surface};
use crate::error::{Result, SimError};

/// Names of the built-in scenes.
pub const NAMES: [&str; 2] = ["flat", "flat-objects"];

/// Half-size of the built-in ground square, metres (400 m x 400 m, enough for a 200 m sensor).
pub const HALF_SIZE_M: f32 = 200.0;

/// Ground grid cell size of the built-in scenes, metres.
pub const CELL_M: f32 = 2.0;

/// A built-in scene by name.
pub fn builtin(name: &str) -> Result<SceneMesh> {
    match name {
        "flat" => Ok(flat()),
        "flat-objects" => Ok(flat_objects()),
        _ => Err(SimError::UnknownName { kind: "scene", name: name.into(), known: NAMES.join(", ") }),
    }
}

/// Open flat ground at z = 0: road within 5 m of the x axis, terrain elsewhere.
pub fn flat() -> SceneMesh {
    let mut m = SceneMesh::new();
    let n = (2.0 * HALF_SIZE_M / CELL_M) as usize;
    m.push_heightfield(
        (-HALF_SIZE_M, -HALF_SIZE_M),
        CELL_M,
        (n, n),
        |_, _| 0.0,
        |_, y| Surface::stuff(if y.abs() < 5.0 { SemanticClass::ROAD } else { SemanticClass::TERRAIN }),
    );
    m
}

/// [`flat`] plus a 1 m cube (instance 1, other-object) 10 m ahead and a car-sized box
/// (4.5 x 1.8 x 1.5 m, instance 2, car) 15 m ahead, 3 m to the left.
pub fn flat_objects() -> SceneMesh {
    let mut m = flat();
    m.push_box(Vec3::new(9.5, -0.5, 0.0), Vec3::new(10.5, 0.5, 1.0), Surface::object(SemanticClass::OTHER_OBJECT, 1));
    m.push_box(Vec3::new(12.75, 2.1, 0.0), Vec3::new(17.25, 3.9, 1.5), Surface::object(SemanticClass::CAR, 2));
    m
}
