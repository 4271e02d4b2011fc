//! The built-in rigs. Vehicle frame (ISO 8855): x forward from the rear axle, y left, z up from
//! the ground; mounts in metres and degrees, positive `pitch_deg` tilts the sensor down.
//!
//! | preset | sensors and mounts |
//! | --- | --- |
//! | `lux` | one LUX on the front bumper: x 3.7, z 0.5, pitched 1 deg down (lowest layer reaches the ground at about 13 m, the top layer is level). |
//! | `lux-roof-4` | 4 forward LUX on the roof front edge (x 1.6, z 1.6, y +0.45 / +0.15 / -0.15 / -0.45), pitched 0.8 / 4.0 / 7.2 / 10.4 deg down: the pitches differ by the LUX's 3.2 deg fan, so the 4 fans **stack** into one 16-layer fan with 0.8 deg between all neighbouring layers, from +0.4 down to -11.6 deg (the lowest layer reaches the ground at about 7.8 m). |
//! | `lux-highway-7` | `lux-roof-4` plus 3 LUX on the rear bumper facing backwards (x -1.0, z 0.5, y +0.6 / 0 / -0.6, yaw 180), pitched 0.4 / 3.6 / 6.8 deg down: a second stacked 12-layer fan from +0.8 to -8.0 deg looking back; 28 layers in all. |
//! | `utm30lx-nodding` | the nodding Hokuyo of seed 002, tilt axis at x 0, z 0.55 (the pattern's own frame is the tilt axis frame). |
//! | `utm30lx-nodding-180` | the same with 180 deg of the 270 deg field of view (200 x 721), as seed 002's sparse scene used it. |
//! | `vlp16-roof` | VLP-16 at x 1.3, z 1.85. |
//! | `hdl64e-roof` | HDL-64E base at x 1.3, z 1.80 (its beams start 0.14-0.22 m higher). |
//! | `os1-64-roof` | OS1-64 gen1, 1024 x 10 Hz, at x 1.3, z 1.85. |
//! | `os1-128-roof` | OS1-128, 2048 x 10 Hz, at x 1.3, z 1.85. |
//! | `hdl32e-roof`, `vlp32c-roof`, `vls128-roof`, `os0-128-roof`, `os2-128-roof`, `pandar64-roof`, `pandar-xt32-roof`, `rs-helios-5515-roof` | the catalogued sensor of that name ([`crate::sensor::catalogue`]) with its defaults (10 Hz, strongest return; Ouster 1024 columns) at x 1.3, z 1.85. |
//!
//! Why stacking rather than interleaving for the roof LUX: each LUX layer is a 0.8 deg tall beam,
//! so four fans offset by 0.2 deg would illuminate the same 3.2 deg slice four times; offsetting
//! them by 3.2 deg tiles 12.8 deg without overlap and gives the uniform 16-layer cloud of seed 000.

use super::{Mount, MountedSensor, Rig};
use crate::error::{Result, SimError};
use crate::sensor::SensorSpec;

/// Names of the built-in rigs.
pub const PRESETS: &[&str] = &[
    "lux",
    "lux-roof-4",
    "lux-highway-7",
    "utm30lx-nodding",
    "utm30lx-nodding-180",
    "vlp16-roof",
    "hdl64e-roof",
    "os1-64-roof",
    "os1-128-roof",
    "hdl32e-roof",
    "vlp32c-roof",
    "vls128-roof",
    "os0-128-roof",
    "os2-128-roof",
    "pandar64-roof",
    "pandar-xt32-roof",
    "rs-helios-5515-roof",
];

/// A sensor of `model` with its defaults at `mount`.
fn sensor(name: &str, model: &str, mount: Mount) -> Result<MountedSensor> {
    Ok(MountedSensor { name: name.to_string(), spec: SensorSpec::default_for(model)?, mount })
}

/// A mount with no roll.
fn at(x_m: f32, y_m: f32, z_m: f32, pitch_deg: f32, yaw_deg: f32) -> Mount {
    Mount { x_m, y_m, z_m, roll_deg: 0.0, pitch_deg, yaw_deg }
}

/// The four stacked roof LUX of seed 000.
fn roof_lux() -> Result<Vec<MountedSensor>> {
    [(0.45, 0.8), (0.15, 4.0), (-0.15, 7.2), (-0.45, 10.4)]
        .iter()
        .enumerate()
        .map(|(i, &(y, pitch))| sensor(&format!("roof_{i}"), "ibeo-lux", at(1.6, y, 1.6, pitch, 0.0)))
        .collect()
}

/// The three backward LUX of the highway rig.
fn rear_lux() -> Result<Vec<MountedSensor>> {
    [(0.6, 0.4), (0.0, 3.6), (-0.6, 6.8)]
        .iter()
        .enumerate()
        .map(|(i, &(y, pitch))| sensor(&format!("rear_{i}"), "ibeo-lux", at(-1.0, y, 0.5, pitch, 180.0)))
        .collect()
}

/// The preset rig `name` (one of [`PRESETS`]).
pub fn preset(name: &str) -> Result<Rig> {
    let roof = |model: &str, z_m: f32| Ok(vec![sensor("roof", model, at(1.3, 0.0, z_m, 0.0, 0.0))?]);
    let sensors: Result<Vec<MountedSensor>> = match name {
        "lux" => Ok(vec![sensor("front", "ibeo-lux", at(3.7, 0.0, 0.5, 1.0, 0.0))?]),
        "lux-roof-4" => roof_lux(),
        "lux-highway-7" => {
            let mut s = roof_lux()?;
            s.extend(rear_lux()?);
            Ok(s)
        }
        "utm30lx-nodding" => Ok(vec![sensor("nodder", "utm30lx-nodding", at(0.0, 0.0, 0.55, 0.0, 0.0))?]),
        "utm30lx-nodding-180" => {
            let mut s = sensor("nodder", "utm30lx-nodding", at(0.0, 0.0, 0.55, 0.0, 0.0))?;
            if let SensorSpec::Utm30lxNodding(spec) = &mut s.spec {
                spec.fov_deg = 180.0;
            }
            Ok(vec![s])
        }
        "vlp16-roof" => roof("vlp16", 1.85),
        "hdl64e-roof" => roof("hdl64e", 1.80),
        "os1-64-roof" => roof("os1-64", 1.85),
        "os1-128-roof" => roof("os1-128", 1.85),
        "hdl32e-roof" => roof("hdl32e", 1.85),
        "vlp32c-roof" => roof("vlp32c", 1.85),
        "vls128-roof" => roof("vls128", 1.85),
        "os0-128-roof" => roof("os0-128", 1.85),
        "os2-128-roof" => roof("os2-128", 1.85),
        "pandar64-roof" => roof("pandar64", 1.85),
        "pandar-xt32-roof" => roof("pandar-xt32", 1.85),
        "rs-helios-5515-roof" => roof("rs-helios-5515", 1.85),
        _ => return Err(SimError::UnknownName { kind: "rig", name: name.to_string(), known: PRESETS.join(", ") }),
    };
    Ok(Rig { name: name.to_string(), sensors: sensors? })
}
