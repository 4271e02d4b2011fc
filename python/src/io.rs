//! `read()` / `write()`: PCD, PLY, KITTI and LAS through the simulator's readers and writers.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use classifier::recording::{LayoutChoice, Ordering, Recording, RecordingError, read_as_stored_as};
use groundtruth_scenario::Scan;
use pyo3::prelude::*;
use sim::io::formats::Format;
use sim::io::pcd::PcdLayout;

use crate::error::{sim_error, type_error, value_error};
use crate::frame::Frame;

/// The formats `write` takes (those of `groundtruth scan --format` this build writes).
pub fn write_formats() -> Vec<&'static str> {
    Format::available_names()
}

/// The lower-case extension of `path` (empty without one).
fn extension(path: &Path) -> String {
    path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default()
}

/// Reads a point-cloud file into a `Frame`: an organized or unorganized PCD (ours or a ROS
/// driver's), a PLY, a LAS, or a KITTI `.bin` (with its `.label` beside it when there is one:
/// labels and ground truth). Unorganized files give a `1 x N` grid in file order. Regions that need a scene
/// family (`ramp-surface`, ...) are not available on a file; `ground`, `class:...` and the others
/// are, from the file's labels. The GIL is released while reading.
///
/// A ROS 2 bag (an `.mcap` file or a rosbag2 directory) gives a list of Frames, one per
/// `sensor_msgs/msg/PointCloud2` message of `topic` (optional where the bag has one such topic),
/// each read as the PCD of the same cloud would be. A bag cut short is read up to its last whole
/// message, with a `UserWarning` naming the last message read.
///
/// Files and bags are read by the library's reader (`classifier::recording`), as stored. A
/// nuScenes `.pcd.bin` (x y z intensity ring) gives its rings; a `.bin` whose bytes are nuScenes
/// records is read as one; `layout` (`"kitti"`, `"nuscenes"`) names the records of a `.bin` file
/// outright.
#[pyfunction]
#[pyo3(signature = (path, topic=None, layout=None))]
pub fn read<'py>(
    py: Python<'py>,
    path: PathBuf,
    topic: Option<String>,
    layout: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let layout = layout.map(LayoutChoice::named).transpose().map_err(|e| value_error("layout", e))?;
    if sim::io::ros2::is_bag(&path) {
        if layout.is_some() {
            return Err(value_error("layout", "applies to .bin files, not to a bag"));
        }
        let frames = read_bag(py, &path, topic)?;
        return Ok(pyo3::types::PyList::new(py, frames)?.into_any());
    }
    if topic.is_some() {
        return Err(value_error(
            "topic",
            format!("applies to a bag (.mcap or rosbag2 directory); {} is none", path.display()),
        ));
    }
    Ok(Bound::new(py, read_file(py, path, layout)?)?.into_any())
}

/// The PointCloud2 messages of a bag's topic as Frames.
// The reader's error names files, topics and messages; it is returned once per call, not in a loop.
#[allow(clippy::result_large_err)]
fn read_bag(py: Python<'_>, path: &Path, topic: Option<String>) -> PyResult<Vec<Frame>> {
    let p = path.to_path_buf();
    let (clouds, warnings) = py
        .detach(move || -> Result<(Vec<sim::OrderedCloud>, Vec<String>), RecordingError> {
            let recording = Recording::open(&p, topic.as_deref())?;
            let mut frames = recording.frames(Ordering::AsStored)?;
            let mut out = Vec::new();
            while let Some(frame) = frames.next_frame() {
                out.push(frame?.cloud.clone());
            }
            Ok((out, frames.warnings().to_vec()))
        })
        .map_err(|e| match e {
            RecordingError::Topic(m) => value_error("topic", m),
            e => value_error("path", e),
        })?;
    for w in warnings {
        let message = std::ffi::CString::new(w).unwrap_or_default();
        PyErr::warn(py, py.get_type::<pyo3::exceptions::PyUserWarning>().as_any(), &message, 1)?;
    }
    let name = path.display().to_string();
    Ok(clouds.into_iter().map(|cloud| frame_of(cloud, &name)).collect())
}

/// A cloud read from a file as a one-frame scan named `name` (no rig, identity pose).
fn frame_of(cloud: sim::OrderedCloud, name: &str) -> Frame {
    let frame = sim::scan::Frame {
        index: 0,
        start_time_s: 0.0,
        vehicle_pose: Default::default(),
        world_from_vehicle: glam::Affine3A::IDENTITY,
        cloud,
    };
    let rig = sim::Rig { name: String::new(), sensors: Vec::new() };
    Frame { scan: Arc::new(Scan::from_frames(vec![frame], name, rig)), k: 0 }
}

/// Reads one point-cloud file (see [`read`]).
#[allow(clippy::result_large_err)] // As `read_bag`: one error per call.
fn read_file(py: Python<'_>, path: PathBuf, layout: Option<LayoutChoice>) -> PyResult<Frame> {
    if !path.is_file() {
        return Err(pyo3::exceptions::PyFileNotFoundError::new_err(format!("path: {}: no such file", path.display())));
    }
    let p = path.clone();
    let cloud = py.detach(move || read_as_stored_as(&p, layout).map(|(cloud, _)| cloud)).map_err(|e| match e {
        RecordingError::File(e) => sim_error(e),
        RecordingError::Unsupported { .. } => value_error(
            "path",
            format!(
                "{}: unknown extension (readable: .pcd, .ply, .las, .bin with an optional .label, .pcd.bin)",
                path.display()
            ),
        ),
        e @ RecordingError::LayoutOfNonRaw { .. } => value_error("layout", e),
        e => value_error("path", e),
    })?;
    Ok(frame_of(cloud, &path.display().to_string()))
}

/// Writes `frame` to `path` in `format` (`pcd`, `pcd-ascii`, `ply`, `kitti`, `las`; default: from
/// the extension, `.bin` = KITTI) with the same writers as `groundtruth scan --format`, atomically.
/// KITTI writes `path` (`.bin`), the `.label` beside it and, for a single-sensor rig, the
/// `.calib.txt` (points in the sensor frame, as the command line writes them). Returns the number of
/// points written. The GIL is released while writing.
///
/// `mcap` writes a ROS 2 bag (a rosbag2 directory at `path`: `metadata.yaml` and one MCAP file)
/// holding the frame, or every frame of a list in order, as `groundtruth scan --format mcap`
/// writes a scan: one PointCloud2 per frame and sensor in `layout` (`groundtruth`, `velodyne`,
/// `ouster`), `/tf` and `/tf_static`.
#[pyfunction]
#[pyo3(signature = (frame, path, format=None, layout="groundtruth"))]
pub fn write(
    py: Python<'_>,
    frame: &Bound<'_, PyAny>,
    path: PathBuf,
    format: Option<&str>,
    layout: &str,
) -> PyResult<usize> {
    let layout = PcdLayout::parse(layout).map_err(|e| value_error("layout", e))?;
    if format.is_some_and(|f| f.eq_ignore_ascii_case("mcap")) {
        let frames: Vec<PyRef<'_, Frame>> = if let Ok(f) = frame.cast::<Frame>() {
            vec![f.borrow()]
        } else {
            frame
                .try_iter()
                .map_err(|_| type_error("frame", "expected a Frame or a list of Frames"))?
                .map(|f| f.and_then(|f| Ok(f.cast::<Frame>()?.borrow())))
                .collect::<PyResult<_>>()
                .map_err(|_| type_error("frame", "expected a Frame or a list of Frames"))?
        };
        let work: Vec<(Arc<Scan>, usize)> = frames.iter().map(|f| (f.scan.clone(), f.k)).collect();
        return py
            .detach(move || -> Result<usize, sim::SimError> {
                let mut bag = sim::io::ros2::BagWriter::create(&path)?;
                let mut points = 0;
                for (k, (scan, i)) in work.iter().enumerate() {
                    let f = &scan.frames()[*i];
                    let mut sensors = sim::io::ros2::scan::sensor_topics(scan.rig());
                    if sensors.is_empty() {
                        // A file read back: one sensor at the vehicle's origin.
                        sensors.push(sim::io::ros2::scan::SensorTopic {
                            name: "lidar".into(),
                            topic: "/lidar/points".into(),
                            vehicle_from_sensor: glam::Affine3A::IDENTITY,
                        });
                    }
                    if k == 0 {
                        sim::io::ros2::scan::write_static(&mut bag, &sensors)?;
                    }
                    let written = sim::io::ros2::scan::write_frame(
                        &mut bag,
                        &f.cloud,
                        &sensors,
                        layout,
                        f.start_time_s,
                        &f.world_from_vehicle,
                    )?;
                    points += written.iter().map(|w| w.1).sum::<usize>();
                }
                bag.finish()?;
                Ok(points)
            })
            .map_err(sim_error);
    }
    let frame: PyRef<'_, Frame> = frame
        .cast::<Frame>()
        .map_err(|_| type_error("frame", "expected a Frame (a list only with format=\"mcap\")"))?
        .borrow();
    let format = match format {
        Some(f) => Format::parse_field(f, "format").map_err(|e| value_error("format", format!("`{f}`: {e}")))?,
        None => {
            let e = extension(&path);
            Format::from_extension(&e).filter(|f| *f != Format::Mcap).ok_or_else(|| {
                value_error(
                    "format",
                    format!("none given and the extension `.{e}` names none (allowed: {})", write_formats().join(", ")),
                )
            })?
        }
    };
    let scan = frame.scan.clone();
    let k = frame.k;
    py.detach(move || -> Result<usize, sim::SimError> {
        let cloud = &scan.frames()[k].cloud;
        let rig = scan.rig();
        let sensor_from_vehicle =
            (rig.sensors.len() == 1).then(|| rig.sensors[0].mount.vehicle_from_sensor().inverse());
        let files = sim::io::formats::write_file(&path, cloud, format, layout, sensor_from_vehicle.as_ref())?;
        Ok(files.first().map_or(0, |f| f.points))
    })
    .map_err(sim_error)
}
