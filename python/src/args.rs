//! Arguments of `scan()`: the scene and the rig (a name, a TOML file or TOML text), family
//! parameters and mount overrides, checked with the field named, turned into a
//! [`groundtruth_scenario::Scenario`] (the same builder the Rust API and its tests use).

use std::path::Path;

use groundtruth_scenario::{MountMode, MountOverride, MountTarget, ParamValue, Scenario};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString};

use crate::error::{scenario_error, sim_error, type_error, value_error};

/// Whether `s` looks like TOML text rather than a name or a path (a newline, or a `key = value`).
fn is_toml_text(s: &str) -> bool {
    s.contains('\n') || s.contains('=')
}

/// The scene: TOML text, a `.toml` file (or any existing file), a bundled scene name, a simulator
/// built-in (`flat-objects`) or `fixture-terrain`, or a generator family name (bundled names
/// first, as the command line resolves them).
pub fn scene_scenario(scene: &str) -> PyResult<Scenario> {
    if is_toml_text(scene) {
        return Ok(Scenario::toml(scene));
    }
    if scene.ends_with(".toml") || Path::new(scene).is_file() {
        return Ok(Scenario::toml_file(scene));
    }
    let builtin = sim::scene::builtin::NAMES.contains(&scene) || scene == groundtruth_scenario::spec::FIXTURE_TERRAIN;
    if scenes::bundled_names().contains(&scene) || builtin {
        return Ok(Scenario::bundled(scene));
    }
    if scenes::families::NAMES.contains(&scene) {
        return Ok(Scenario::family(scene));
    }
    Err(value_error(
        "scene",
        format!(
            "unknown scene `{scene}`; known: {} (bundled), {}, {} (built-in), families {} (or a path to a .toml scene file, or TOML text)",
            scenes::bundled_names().join(", "),
            sim::scene::builtin::NAMES.join(", "),
            groundtruth_scenario::spec::FIXTURE_TERRAIN,
            scenes::families::NAMES.join(", ")
        ),
    ))
}

/// Applies the rig: a preset name or a rig file path (as the command line's `--rig`), or rig TOML
/// text.
pub fn with_rig(scenario: Scenario, rig: &str) -> PyResult<Scenario> {
    if is_toml_text(rig) {
        let mut r = sim::Rig::from_toml_str(rig, "<rig TOML>").map_err(sim_error)?;
        if r.name.is_empty() {
            r.name = "custom".into();
        }
        return Ok(scenario.rig_value(r));
    }
    if !sim::rig::PRESETS.contains(&rig) && !Path::new(rig).is_file() {
        return Err(value_error(
            "rig",
            format!(
                "unknown rig `{rig}`; known: {} (or a path to a rig .toml file, or TOML text)",
                sim::rig::PRESETS.join(", ")
            ),
        ));
    }
    Ok(scenario.rig(rig))
}

/// A finite float from a Python int or float (bools refused), naming `field`.
pub fn finite_f64(v: &Bound<'_, PyAny>, field: &str) -> PyResult<f64> {
    if v.is_instance_of::<PyBool>() || !(v.is_instance_of::<PyFloat>() || v.is_instance_of::<PyInt>()) {
        return Err(type_error(field, format!("expected a number, got {}", type_name(v))));
    }
    let x: f64 = v.extract().map_err(|e| value_error(field, e))?;
    if !x.is_finite() {
        return Err(value_error(field, format!("{x} is not a finite number")));
    }
    Ok(x)
}

/// A non-negative integer (bools refused), naming `field`, at most `max`.
pub fn uint(v: &Bound<'_, PyAny>, field: &str, min: u64, max: u64) -> PyResult<u64> {
    if v.is_instance_of::<PyBool>() || !v.is_instance_of::<PyInt>() {
        return Err(type_error(field, format!("expected an int, got {}", type_name(v))));
    }
    let x: i128 = v.extract().map_err(|e| value_error(field, e))?;
    if x < i128::from(min) || x > i128::from(max) {
        return Err(value_error(field, format!("{x} is out of range (allowed: {min} ..= {max})")));
    }
    Ok(x as u64)
}

/// The Python type name of `v`, for messages.
pub fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into())
}

/// Family parameters from a dict `{name: number | int | bool | str}`.
pub fn with_params(mut scenario: Scenario, params: &Bound<'_, PyDict>) -> PyResult<Scenario> {
    for (k, v) in params.iter() {
        let Ok(name) = k.cast::<PyString>() else {
            return Err(type_error("params", format!("keys must be str, got {}", type_name(&k))));
        };
        let name = name.to_str()?.to_string();
        let field = format!("params.{name}");
        let value = if v.is_instance_of::<PyBool>() {
            ParamValue::Bool(v.extract()?)
        } else if v.is_instance_of::<PyInt>() {
            ParamValue::Int(v.extract().map_err(|e| value_error(&field, e))?)
        } else if v.is_instance_of::<PyFloat>() {
            ParamValue::Float(finite_f64(&v, &field)?)
        } else if let Ok(s) = v.cast::<PyString>() {
            ParamValue::Text(s.to_str()?.to_string())
        } else {
            return Err(type_error(&field, format!("expected a number, bool or str, got {}", type_name(&v))));
        };
        scenario = scenario.param(&name, value);
    }
    Ok(scenario)
}

/// The mount override from a dict with the keys of a scan spec's `mount`: `x_m y_m z_m roll_deg
/// pitch_deg yaw_deg`, `sensor` (an index, a sensor name or `"rig"`) and `mode` (`"absolute"` or
/// `"relative"`); an unknown key gets the spec's own message.
pub fn with_mount(scenario: Scenario, mount: &Bound<'_, PyDict>) -> PyResult<Scenario> {
    let mut o = MountOverride::default();
    for (k, v) in mount.iter() {
        let Ok(name) = k.cast::<PyString>() else {
            return Err(type_error("mount", format!("keys must be str, got {}", type_name(&k))));
        };
        let name = name.to_str()?;
        let field = format!("mount.{name}");
        if name == "sensor" {
            o.sensor = Some(match v.cast::<PyString>() {
                Ok(s) => MountTarget::Name(s.to_str()?.to_string()),
                Err(_) => MountTarget::Index(uint(&v, &field, 0, 255)? as usize),
            });
            continue;
        }
        if name == "mode" {
            let Ok(mode) = v.cast::<PyString>() else {
                return Err(type_error(
                    &field,
                    format!("expected \"absolute\" or \"relative\", got {}", type_name(&v)),
                ));
            };
            o.mode = match mode.to_str()? {
                "absolute" => MountMode::Absolute,
                "relative" => MountMode::Relative,
                other => return Err(value_error(&field, format!("`{other}` (allowed: absolute, relative)"))),
            };
            continue;
        }
        let x = Some(finite_f64(&v, &field)? as f32);
        match name {
            "x_m" => o.x_m = x,
            "y_m" => o.y_m = x,
            "z_m" => o.z_m = x,
            "roll_deg" => o.roll_deg = x,
            "pitch_deg" => o.pitch_deg = x,
            "yaw_deg" => o.yaw_deg = x,
            _ => return Err(value_error(&field, groundtruth_scenario::spec::mount_key_error(name))),
        }
    }
    o.validate().map_err(scenario_error)?;
    Ok(scenario.mount(o))
}
