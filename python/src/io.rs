//! `read()` / `write()`: PCD, PLY, KITTI and LAS through the simulator's readers and writers.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use groundtruth_scenario::Scan;
use pyo3::prelude::*;
use sim::io::pcd::PcdLayout;

use crate::error::{sim_error, value_error};
use crate::frame::Frame;

/// The formats `write` takes.
pub const WRITE_FORMATS: [&str; 5] = ["pcd", "pcd-ascii", "ply", "kitti", "las"];

fn extension(path: &Path) -> String {
    path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default()
}

/// Reads a point-cloud file into a `Frame`: an organized or unorganized PCD (ours or a ROS
/// driver's), a PLY, a LAS, or a KITTI `.bin` (with its `.label` beside it when there is one:
/// labels and ground truth). Unorganized files give a `1 x N` grid in file order. Regions that need a scene
/// family (`ramp-surface`, ...) are not available on a file; `ground`, `class:...` and the others
/// are, from the file's labels. The GIL is released while reading.
#[pyfunction]
pub fn read(py: Python<'_>, path: PathBuf) -> PyResult<Frame> {
    let ext = extension(&path);
    if !path.is_file() {
        return Err(pyo3::exceptions::PyFileNotFoundError::new_err(format!("path: {}: no such file", path.display())));
    }
    let p = path.clone();
    let cloud = py
        .detach(move || match ext.as_str() {
            "pcd" => Some(sim::io::pcd::read(&p)),
            "ply" => Some(sim::io::ply::read(&p)),
            "las" => Some(sim::io::las::read(&p)),
            "bin" => {
                let label = p.with_extension("label");
                Some(sim::io::kitti::read(&p, label.is_file().then_some(label.as_path())))
            }
            _ => None,
        })
        .ok_or_else(|| {
            value_error(
                "path",
                format!(
                    "{}: unknown extension (readable: .pcd, .ply, .las, .bin with an optional .label)",
                    path.display()
                ),
            )
        })?
        .map_err(sim_error)?;
    let frame = sim::scan::Frame {
        index: 0,
        start_time_s: 0.0,
        vehicle_pose: Default::default(),
        world_from_vehicle: glam::Affine3A::IDENTITY,
        cloud,
    };
    let rig = sim::Rig { name: String::new(), sensors: Vec::new() };
    let name = path.display().to_string();
    Ok(Frame { scan: Arc::new(Scan::from_frames(vec![frame], &name, rig)), k: 0 })
}

/// Writes `frame` to `path` in `format` (`pcd`, `pcd-ascii`, `ply`, `kitti`, `las`; default: from
/// the extension, `.bin` = KITTI) with the same writers as `groundtruth scan --format`, atomically.
/// KITTI writes `path` (`.bin`), the `.label` beside it and, for a single-sensor rig, the
/// `.calib.txt` (points in the sensor frame, as the command line writes them). Returns the number of
/// points written. The GIL is released while writing.
#[pyfunction]
#[pyo3(signature = (frame, path, format=None))]
pub fn write(py: Python<'_>, frame: &Frame, path: PathBuf, format: Option<&str>) -> PyResult<usize> {
    let format = match format {
        Some(f) => f.to_ascii_lowercase(),
        None => match extension(&path).as_str() {
            "pcd" => "pcd".into(),
            "ply" => "ply".into(),
            "bin" => "kitti".into(),
            "las" => "las".into(),
            e => {
                return Err(value_error(
                    "format",
                    format!("none given and the extension `.{e}` names none (allowed: {})", WRITE_FORMATS.join(", ")),
                ));
            }
        },
    };
    if !WRITE_FORMATS.contains(&format.as_str()) {
        return Err(value_error("format", format!("`{format}` (allowed: {})", WRITE_FORMATS.join(", "))));
    }
    let scan = frame.scan.clone();
    let k = frame.k;
    py.detach(move || -> Result<usize, sim::SimError> {
        let cloud = &scan.frames()[k].cloud;
        let rig = scan.rig();
        let sensor_from_vehicle =
            (rig.sensors.len() == 1).then(|| rig.sensors[0].mount.vehicle_from_sensor().inverse());
        match format.as_str() {
            "pcd" | "pcd-ascii" => {
                sim::io::pcd::write_layout(&path, cloud, PcdLayout::Groundtruth, format == "pcd-ascii", None)
            }
            "ply" => sim::io::ply::write(&path, cloud),
            "las" => sim::io::las::write(&path, cloud),
            _ => {
                let (bin, label, n) = sim::io::kitti::encode(cloud, sensor_from_vehicle.as_ref())?;
                sim::io::atomic::write_bytes_atomic(&path, &bin)?;
                sim::io::atomic::write_bytes_atomic(&path.with_extension("label"), &label)?;
                if let Some(t) = sensor_from_vehicle {
                    let calib = sim::io::kitti::calib_text(&t.inverse());
                    let stem = path.with_extension("");
                    let calib_path = PathBuf::from(format!("{}.calib.txt", stem.display()));
                    sim::io::atomic::write_bytes_atomic(&calib_path, calib.as_bytes())?;
                }
                Ok(n)
            }
        }
    })
    .map_err(sim_error)
}
