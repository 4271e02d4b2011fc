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
mod ordering;
mod score;

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::{finite_f64, scene_scenario, uint, with_mount, with_params, with_rig};
use crate::error::scenario_error;
use crate::frame::Frame;

/// The largest number of frames of one `scan` call.
const MAX_FRAMES: u64 = sim::scan::MAX_FRAMES as u64;

/// Scans a scene with a rig and returns the frames (a list of `Frame`).
///
/// `scene`: a bundled scene (`groundtruth.SCENES`), a simulator built-in (`flat-objects`) or
/// `fixture-terrain`, a generator family (`groundtruth.FAMILIES`, with its default parameters), a
/// path to a scene `.toml` file, or scene TOML text. `rig`: a preset (`groundtruth.RIGS`), a rig
/// `.toml` path or rig TOML text. The keywords are a scan spec's fields (docs/scan-spec.md), with
/// the same ranges and messages: `params` (family parameters, `{"slope_deg": -12.0}`), `mount`
/// (`x_m y_m z_m roll_deg pitch_deg yaw_deg`, `sensor` = an index, a name or `"rig"`, `mode` =
/// `"absolute"` or `"relative"`), `seed`, `frames`, `speed_m_per_s`, `yaw_rate_deg_per_s`,
/// `waypoints_m` (`[(x, y), ...]`), `ideal` (exact ranges), `noise_scale`, `dropout`,
/// `intensity_scale`, `weather` (`"fog:visibility_m=50"`, `"rain:rate_mm_h=10"`,
/// `"snow:rate_mm_h=2"` or `"clear"`; default the scene file's `[weather]`; returns from the medium
/// are labelled fog (150), rain (151) or snow (152)). `speed` is the deprecated spelling of
/// `speed_m_per_s`; any other keyword is refused with the spec's message. Deterministic: the same
/// arguments give the same arrays. The GIL is released while the scene is generated and scanned.
#[pyfunction]
#[pyo3(
    signature = (scene, rig, *, params=None, mount=None, seed=None, frames=None, speed_m_per_s=None, yaw_rate_deg_per_s=None, waypoints_m=None, ideal=false, noise_scale=None, dropout=None, intensity_scale=None, weather=None, speed=None, **rest),
    text_signature = "(scene, rig, *, params=None, mount=None, seed=0, frames=1, speed_m_per_s=0.0, yaw_rate_deg_per_s=0.0, waypoints_m=None, ideal=False, noise_scale=None, dropout=None, intensity_scale=None, weather=None)"
)]
#[allow(clippy::too_many_arguments)]
fn scan<'py>(
    py: Python<'py>,
    scene: &str,
    rig: &str,
    params: Option<Bound<'py, PyDict>>,
    mount: Option<Bound<'py, PyDict>>,
    seed: Option<Bound<'py, PyAny>>,
    frames: Option<Bound<'py, PyAny>>,
    speed_m_per_s: Option<Bound<'py, PyAny>>,
    yaw_rate_deg_per_s: Option<Bound<'py, PyAny>>,
    waypoints_m: Option<Vec<(f64, f64)>>,
    ideal: bool,
    noise_scale: Option<Bound<'py, PyAny>>,
    dropout: Option<Bound<'py, PyAny>>,
    intensity_scale: Option<Bound<'py, PyAny>>,
    weather: Option<String>,
    speed: Option<Bound<'py, PyAny>>,
    rest: Option<Bound<'py, PyDict>>,
) -> PyResult<Vec<Frame>> {
    // Every value checked with its field named, the ranges by the scan spec (the same messages as
    // a spec file, a dataset or sweep file, the command line and the Rust builder).
    if let Some(rest) = &rest
        && let Some((k, _)) = rest.iter().next()
    {
        let key: String = k.extract()?;
        return Err(scenario_error(groundtruth_scenario::spec::key_error(&key, "scan()")));
    }
    let mut s = with_rig(scene_scenario(scene)?, rig)?;
    if let Some(p) = &params {
        s = with_params(s, p)?;
    }
    if let Some(m) = &mount {
        s = with_mount(s, m)?;
    }
    if let Some(v) = &speed {
        PyErr::warn(
            py,
            py.get_type::<pyo3::exceptions::PyDeprecationWarning>().as_any(),
            c"scan(speed=...) is deprecated: use speed_m_per_s (the same metres per second)",
            1,
        )?;
        s = s.speed_m_per_s(finite_f64(v, "speed")? as f32);
    }
    if let Some(v) = &speed_m_per_s {
        s = s.speed_m_per_s(finite_f64(v, "speed_m_per_s")? as f32);
    }
    if let Some(v) = &yaw_rate_deg_per_s {
        s = s.yaw_rate_deg_per_s(finite_f64(v, "yaw_rate_deg_per_s")?);
    }
    if let Some(w) = waypoints_m {
        s = s.waypoints_m(w.into_iter().map(|(x, y)| [x, y]).collect());
    }
    if let Some(v) = &noise_scale {
        s = s.noise_scale(finite_f64(v, "noise_scale")?);
    }
    if let Some(v) = &dropout {
        s = s.dropout(finite_f64(v, "dropout")?);
    }
    if let Some(v) = &intensity_scale {
        s = s.intensity_scale(finite_f64(v, "intensity_scale")?);
    }
    if let Some(spec) = &weather {
        s = s.weather(sim::effects::weather::Weather::parse(spec).map_err(crate::error::sim_error)?);
    }
    if let Some(v) = &seed {
        s = s.seed(uint(v, "seed", 0, u64::MAX)?);
    }
    if let Some(v) = &frames {
        s = s.frames(uint(v, "frames", 1, MAX_FRAMES)? as usize);
    }
    let s = s.ideal(ideal);
    s.spec().validate().map_err(scenario_error)?;
    let scan = Arc::new(py.detach(move || s.scan()).map_err(scenario_error)?);
    Ok((0..scan.frames().len()).map(|k| Frame { scan: scan.clone(), k, ordering: None }).collect())
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
    m.add("WRITE_FORMATS", io::write_formats())?;
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
