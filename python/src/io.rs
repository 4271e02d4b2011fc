//! `read()` / `write()`: PCD, PLY, KITTI, LAS and ROS 2 bags read through the library's recording
//! reader (`classifier::recording`: ordered as `groundtruth classify` orders them, or as stored) and
//! written by the simulator's writers.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use classifier::ordering::SensorSetup;
use classifier::recording::{self, LayoutChoice, Ordering, Recording, RecordingError, read_as_stored_as};
use groundtruth_scenario::Scan;
use pyo3::prelude::*;
use sim::io::formats::Format;
use sim::io::pcd::PcdLayout;

use crate::error::{sim_error, type_error, value_error};
use crate::frame::Frame;
use crate::ordering::ReadOrdering;

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
/// labels and ground truth). Regions that need a scene family (`ramp-surface`, ...) are not
/// available on a file; `ground`, `class:...` and the others are, from the file's labels. The GIL
/// is released while reading.
///
/// By default (`ordered=True`) the frame is ordered into rings and columns exactly as
/// `groundtruth classify` orders it (the library's recording reader, `classifier::recording`, with
/// the same sensor setup): a ring-less KITTI `.bin`, an unorganized PCD / PLY / LAS or a one-row
/// PointCloud2 gets its rings and columns recovered (the sensor matched against the catalogue, or
/// ordered as an unnamed sensor with the rings it shows), from its `ring` field where it has one,
/// or from the beam table of `rig` (a single-sensor rig: preset name or TOML file, as `--rig`) or
/// `calibration` (the sensor's calibration file, as `--calibration`: our `.toml` / `.txt`, the
/// velodyne driver's `.yaml`, Ouster's metadata `.json`); an organized cloud of another tool has
/// its rows put in elevation order; our own files are kept as written. `frame.ordering` says what
/// was done (the line `groundtruth classify` prints), `frame.decisions_per_point(decisions)` maps
/// decisions back to the file's points (the bytes of `classify`'s `.ground` file), and
/// `frame.index` is the frame's index as `classify` numbers it. A file whose order cannot be
/// recovered raises `ValueError` (`ordered=False` reads it as stored).
///
/// `ordered=False` reads the file as stored: an organized cloud keeps its grid, anything else is a
/// `1 x N` grid in file order (which `classify()` refuses); `rig` and `calibration` do not apply.
///
/// A ROS 2 bag (an `.mcap` file or a rosbag2 directory) gives a list of Frames, one per
/// `sensor_msgs/msg/PointCloud2` message of `topic` (optional where the bag has one such topic),
/// each read as the PCD of the same cloud would be. A bag cut short is read up to its last whole
/// message, with a `UserWarning` naming the last message read; ordered, a message that cannot be
/// read or ordered is skipped with a `UserWarning` naming it (as `classify` skips it), and a bag
/// none of whose messages can be read raises `ValueError`.
///
/// A nuScenes `.pcd.bin` (x y z intensity ring) gives its rings; a `.bin` whose bytes are nuScenes
/// records is read as one; `layout` (`"kitti"`, `"nuscenes"`) names the records of a `.bin` file
/// outright.
#[pyfunction]
#[pyo3(signature = (path, topic=None, layout=None, rig=None, calibration=None, ordered=true))]
pub fn read<'py>(
    py: Python<'py>,
    path: PathBuf,
    topic: Option<String>,
    layout: Option<&str>,
    rig: Option<String>,
    calibration: Option<PathBuf>,
    ordered: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let layout = layout.map(LayoutChoice::named).transpose().map_err(|e| value_error("layout", e))?;
    let setup = match ordered {
        true => Some(sensor_setup(rig.as_deref(), calibration.as_deref())?),
        false => {
            let given = [("rig", rig.is_some()), ("calibration", calibration.is_some())];
            if let Some((name, _)) = given.iter().find(|g| g.1) {
                return Err(value_error(
                    name,
                    "names the sensor that orders the frame; ordered=False reads it as stored (give ordered=True)",
                ));
            }
            None
        }
    };
    if sim::io::ros2::is_bag(&path) {
        if layout.is_some() {
            return Err(value_error("layout", "applies to .bin files, not to a bag"));
        }
        let frames = read_bag(py, &path, topic, setup)?;
        return Ok(pyo3::types::PyList::new(py, frames)?.into_any());
    }
    if topic.is_some() {
        return Err(value_error(
            "topic",
            format!("applies to a bag (.mcap or rosbag2 directory); {} is none", path.display()),
        ));
    }
    Ok(Bound::new(py, read_file(py, path, layout, setup)?)?.into_any())
}

/// The sensor setup of `rig` and `calibration`, as `groundtruth classify --rig --calibration`
/// builds it ([`recording::sensor_setup`]); an error names the argument at fault.
fn sensor_setup(rig: Option<&str>, calibration: Option<&Path>) -> PyResult<SensorSetup> {
    let with_rig = recording::sensor_setup(rig, None).map_err(|e| value_error("rig", e))?;
    let Some(file) = calibration else { return Ok(with_rig) };
    if !file.is_file() {
        return Err(pyo3::exceptions::PyFileNotFoundError::new_err(format!(
            "calibration: {}: no such file",
            file.display()
        )));
    }
    recording::sensor_setup(rig, Some(file)).map_err(|e| value_error("calibration", e))
}

/// A recording's error as a Python exception naming the argument at fault (`path` for the file's
/// own content).
fn recording_error(e: RecordingError, path: &Path) -> PyErr {
    match e {
        RecordingError::File(e) => sim_error(e),
        RecordingError::Unsupported { .. } => value_error(
            "path",
            format!(
                "{}: unknown extension (readable: .pcd, .ply, .las, .bin with an optional .label, .pcd.bin)",
                path.display()
            ),
        ),
        e @ RecordingError::LayoutOfNonRaw { .. } => value_error("layout", e),
        e @ RecordingError::CalibrationRows { .. } => value_error("calibration", e),
        e @ (RecordingError::Ordering { .. } | RecordingError::Message { .. }) => unorderable(e),
        e => value_error("path", e),
    }
}

/// A file or message whose order cannot be recovered, as `ValueError` naming `path` and the ways on.
fn unorderable(e: RecordingError) -> PyErr {
    value_error("path", format!("{e} (ordered=False reads it as stored; rig= or calibration= name the sensor)"))
}

/// The PointCloud2 messages of a bag's topic as Frames: ordered with `setup` (messages that cannot
/// be read skipped, as `classify` skips them), else as stored.
// The reader's error names files, topics and messages; it is returned once per call, not in a loop.
#[allow(clippy::result_large_err)]
fn read_bag(py: Python<'_>, path: &Path, topic: Option<String>, setup: Option<SensorSetup>) -> PyResult<Vec<Frame>> {
    let p = path.to_path_buf();
    let bag_error = |e: RecordingError| match e {
        RecordingError::Topic(m) => value_error("topic", m),
        e @ (RecordingError::Ordering { .. } | RecordingError::Message { .. }) => unorderable(e),
        e => value_error("path", e),
    };
    let read = py.detach(move || -> PyResult<(Vec<Read>, Vec<String>)> {
        let recording = Recording::open(&p, topic.as_deref()).map_err(bag_error)?;
        let ordering = match &setup {
            Some(s) => Ordering::Ordered(s),
            None => Ordering::AsStored,
        };
        let mut frames = recording.frames(ordering).map_err(bag_error)?;
        let (mut out, mut skipped) = (Vec::new(), Vec::new());
        while let Some(frame) = frames.next_frame() {
            match frame {
                Ok(f) => out.push(Read::of(&f, setup.is_some())),
                Err(e) if setup.is_some() && e.is_message() => skipped.push(format!("{e}; skipped")),
                Err(e) => return Err(bag_error(e)),
            }
        }
        if out.is_empty() && !skipped.is_empty() {
            return Err(value_error(
                "path",
                format!(
                    "no message of `{}` in `{}` could be read ({} skipped; the first: {})",
                    recording.topic().unwrap_or_default(),
                    p.display(),
                    skipped.len(),
                    skipped[0]
                ),
            ));
        }
        skipped.extend(frames.warnings().iter().cloned());
        Ok((out, skipped))
    });
    let (reads, warnings) = read?;
    for w in warnings {
        let message = std::ffi::CString::new(w).unwrap_or_default();
        PyErr::warn(py, py.get_type::<pyo3::exceptions::PyUserWarning>().as_any(), &message, 1)?;
    }
    let name = path.display().to_string();
    Ok(reads.into_iter().map(|r| r.into_frame(&name)).collect())
}

/// One frame read: its cloud, its index as `classify` numbers it and, read ordered, how it was
/// ordered.
struct Read {
    cloud: sim::OrderedCloud,
    index: usize,
    ordering: Option<ReadOrdering>,
}

impl Read {
    /// The frame `f` of a recording (`ordered`: read with [`Ordering::Ordered`]).
    fn of(f: &recording::Frame<'_>, ordered: bool) -> Self {
        Self {
            cloud: f.cloud.clone(),
            index: if ordered { f.index } else { 0 },
            ordering: ordered.then(|| ReadOrdering::of(f.cloud, f.report, f.provenance)),
        }
    }

    /// A one-frame scan named `name` (no rig, identity pose).
    fn into_frame(self, name: &str) -> Frame {
        let frame = sim::scan::Frame {
            index: self.index,
            start_time_s: 0.0,
            vehicle_pose: Default::default(),
            world_from_vehicle: glam::Affine3A::IDENTITY,
            cloud: self.cloud,
        };
        let rig = sim::Rig { name: String::new(), sensors: Vec::new() };
        Frame { scan: Arc::new(Scan::from_frames(vec![frame], name, rig)), k: 0, ordering: self.ordering.map(Arc::new) }
    }
}

/// Reads one point-cloud file (see [`read`]): ordered with `setup`, else as stored.
#[allow(clippy::result_large_err)] // As `read_bag`: one error per call.
fn read_file(
    py: Python<'_>,
    path: PathBuf,
    layout: Option<LayoutChoice>,
    setup: Option<SensorSetup>,
) -> PyResult<Frame> {
    if !path.is_file() {
        return Err(pyo3::exceptions::PyFileNotFoundError::new_err(format!("path: {}: no such file", path.display())));
    }
    let p = path.clone();
    let read = py.detach(move || -> Result<Read, RecordingError> {
        let Some(setup) = setup else {
            let (cloud, _) = read_as_stored_as(&p, layout)?;
            return Ok(Read { cloud, index: 0, ordering: None });
        };
        let recording = Recording::open(&p, None)?.with_layout(layout)?;
        let mut frames = recording.frames(Ordering::Ordered(&setup))?;
        match frames.next_frame() {
            Some(f) => Ok(Read::of(&f?, true)),
            None => Err(RecordingError::Empty { path: p.clone() }),
        }
    });
    Ok(read.map_err(|e| recording_error(e, &path))?.into_frame(&path.display().to_string()))
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
