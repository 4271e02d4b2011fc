//! The `groundtruth` Python package (extension module `groundtruth._native`): scans as numpy
//! arrays, the scenario API's regions and scores for any segmenter, our classifiers, and the
//! point-cloud readers and writers, all through the Rust crates (`groundtruth-scenario`, `sim`,
//! `classifier`), never re-implemented. Every failure on user input is a Python exception
//! (`ValueError`, `TypeError`, `OSError`) carrying the Rust message; scans, classification and file
//! I/O run with the GIL released.

mod args;
mod classify;
mod error;
mod eval_dataset;
mod frame;
mod io;
mod score;

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::{finite_f64, scene_scenario, uint, with_mount, with_params, with_rig};
use crate::error::{scenario_error, value_error};
use crate::frame::Frame;

/// The largest number of frames of one `scan` call.
const MAX_FRAMES: u64 = sim::scan::MAX_FRAMES as u64;

/// Builds the scenario of `scan()`'s arguments.
#[allow(clippy::too_many_arguments)]
fn scenario(
    scene: &str,
    rig: &str,
    params: Option<&Bound<'_, PyDict>>,
    mount: Option<&Bound<'_, PyDict>>,
    seed: &Bound<'_, PyAny>,
    frames: &Bound<'_, PyAny>,
    speed: &Bound<'_, PyAny>,
    ideal: bool,
    weather: Option<&str>,
) -> PyResult<groundtruth_scenario::Scenario> {
    let mut s = with_rig(scene_scenario(scene)?, rig)?;
    if let Some(p) = params {
        s = with_params(s, p)?;
    }
    if let Some(m) = mount {
        s = with_mount(s, m)?;
    }
    let speed = finite_f64(speed, "speed")?;
    if speed.abs() > 100.0 {
        return Err(value_error("speed", format!("{speed} m/s is out of range (allowed: -100 ..= 100)")));
    }
    if let Some(spec) = weather {
        s = s.weather(sim::effects::weather::Weather::parse(spec).map_err(crate::error::sim_error)?);
    }
    Ok(s.seed(uint(seed, "seed", 0, u64::MAX)?)
        .frames(uint(frames, "frames", 1, MAX_FRAMES)? as usize)
        .speed_m_per_s(speed as f32)
        .ideal(ideal))
}

/// Scans a scene with a rig and returns the frames (a list of `Frame`).
///
/// `scene`: a bundled scene (`groundtruth.SCENES`), a generator family (`groundtruth.FAMILIES`,
/// with its default parameters), a path to a scene `.toml` file, or scene TOML text. `rig`: a preset
/// (`groundtruth.RIGS`), a rig `.toml` path or rig TOML text. `params`: family parameters
/// (`{"slope_deg": -12.0}`), range-checked. `mount`: overrides of the sensor's mount (`x_m y_m z_m
/// roll_deg pitch_deg yaw_deg`, and `sensor` = which sensor, default 0). `seed`: the scene
/// generator's and the scan's seed. `frames`: frame count; `speed`: ego speed, m/s. `ideal`: exact
/// ranges, measurement effects off. `weather`: `"fog:visibility_m=50"`, `"rain:rate_mm_h=10"`,
/// `"snow:rate_mm_h=2"` or `"clear"` (default: the scene file's `[weather]`, else none); returns
/// from the medium are labelled fog (150), rain (151) or snow (152). Deterministic: the same arguments give the same arrays. The
/// GIL is released while the scene is generated and scanned.
#[pyfunction]
#[pyo3(
    signature = (scene, rig, *, params=None, mount=None, seed=None, frames=None, speed=None, ideal=false, weather=None),
    text_signature = "(scene, rig, *, params=None, mount=None, seed=0, frames=1, speed=0.0, ideal=False, weather=None)"
)]
#[allow(clippy::too_many_arguments)]
fn scan(
    py: Python<'_>,
    scene: &str,
    rig: &str,
    params: Option<&Bound<'_, PyDict>>,
    mount: Option<&Bound<'_, PyDict>>,
    seed: Option<&Bound<'_, PyAny>>,
    frames: Option<&Bound<'_, PyAny>>,
    speed: Option<&Bound<'_, PyAny>>,
    ideal: bool,
    weather: Option<&str>,
) -> PyResult<Vec<Frame>> {
    let zero = 0u64.into_pyobject(py)?.into_any();
    let one = 1u64.into_pyobject(py)?.into_any();
    let zero_f = 0.0f64.into_pyobject(py)?.into_any();
    let s = scenario(
        scene,
        rig,
        params,
        mount,
        seed.unwrap_or(&zero),
        frames.unwrap_or(&one),
        speed.unwrap_or(&zero_f),
        ideal,
        weather,
    )?;
    let scan = Arc::new(py.detach(move || s.scan()).map_err(scenario_error)?);
    Ok((0..scan.frames().len()).map(|k| Frame { scan: scan.clone(), k }).collect())
}

/// Benchmark helper: the same scan as `scan(scene, rig, ideal=ideal)` through the Rust API alone
/// (`Scenario::scan`, no Python objects), `repeats` times; returns the seconds of each.
#[pyfunction]
#[pyo3(signature = (scene, rig, repeats=5, ideal=false))]
fn _time_rust_scan(py: Python<'_>, scene: &str, rig: &str, repeats: usize, ideal: bool) -> PyResult<Vec<f64>> {
    let s = with_rig(scene_scenario(scene)?, rig)?.ideal(ideal);
    py.detach(move || {
        (0..repeats)
            .map(|_| {
                let t = std::time::Instant::now();
                let scan = s.scan()?;
                let dt = t.elapsed().as_secs_f64();
                drop(scan);
                Ok(dt)
            })
            .collect::<Result<Vec<f64>, groundtruth_scenario::ScenarioError>>()
    })
    .map_err(scenario_error)
}

/// The native part of the `groundtruth` package. Safe without the GIL (free-threaded Python): the
/// classes are frozen and hold immutable, shared (`Arc`) Rust data.
#[pymodule(gil_used = false)]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("SCENES", scenes::bundled_names())?;
    m.add("FAMILIES", scenes::families::NAMES.to_vec())?;
    m.add("RIGS", sim::rig::PRESETS.to_vec())?;
    m.add("METHODS", classifier::METHODS.to_vec())?;
    m.add("REGIONS", score::REGIONS.to_vec())?;
    m.add("WRITE_FORMATS", io::WRITE_FORMATS.to_vec())?;
    m.add_class::<Frame>()?;
    m.add_class::<score::Score>()?;
    m.add_function(wrap_pyfunction!(scan, m)?)?;
    m.add_function(wrap_pyfunction!(score::score, m)?)?;
    m.add_function(wrap_pyfunction!(score::regions, m)?)?;
    m.add_function(wrap_pyfunction!(classify::classify, m)?)?;
    m.add_function(wrap_pyfunction!(eval_dataset::eval_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(io::read, m)?)?;
    m.add_function(wrap_pyfunction!(io::write, m)?)?;
    m.add_function(wrap_pyfunction!(_time_rust_scan, m)?)?;
    Ok(())
}
