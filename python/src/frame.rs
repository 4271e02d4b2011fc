//! `Frame`: one scanned (or read) frame, its ordered cloud's fields as numpy arrays in grid shape.
//!
//! The grid shape is `(planes * rows, cols)`: row 0 is the lowest beam, echo plane `k` occupies rows
//! `k * rows .. (k + 1) * rows` (as in the organized PCD); for every sensor but the multi-echo LUX
//! there is one plane, so the shape is `(rows, cols)`. Each array is one copy of the Rust field
//! (`PyArray::from_vec`, then a reshape that does not copy); the frame keeps the Rust cloud for
//! regions, scores and classification.

use std::sync::Arc;

use groundtruth_scenario::{Region, Scan};
use numpy::{Element, PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use sim::OrderedCloud;

use crate::args::type_name;
use crate::error::{scenario_error, type_error};
use crate::ordering::ReadOrdering;
use crate::score::{cell_decisions, parse_region};

/// One frame of a scan, or a file read back: the labelled ordered cloud as numpy arrays.
///
/// Arrays have the grid shape `(planes * rows, cols)` (row 0 = lowest beam, column 0 = left-most
/// azimuth); cells without a return hold NaN positions and ranges. Every property access returns a
/// fresh array (one copy of the Rust field): keep a reference rather than reading it in a loop.
#[pyclass(frozen, module = "groundtruth")]
pub struct Frame {
    /// The scan the frame belongs to (a one-frame pseudo scan for files read back).
    pub scan: Arc<Scan>,
    /// Index of the frame in `scan`.
    pub k: usize,
    /// How the frame was ordered, for a frame read with `read(..., ordered=True)`; `None` for
    /// scans and frames read as stored.
    pub ordering: Option<Arc<ReadOrdering>>,
}

impl Frame {
    /// The frame's cloud.
    pub fn cloud(&self) -> &OrderedCloud {
        &self.scan.frames()[self.k].cloud
    }

    /// `(planes * rows, cols)`.
    pub fn grid(&self) -> (usize, usize) {
        let c = self.cloud();
        (c.planes * c.rows, c.cols)
    }
}

/// The frames of a `frame` argument and whether it was a single Frame (else a list or tuple of
/// Frames); anything else is a `TypeError` naming `frame` that says it expected `expected`.
pub fn frames_arg<'py>(frame: &Bound<'py, PyAny>, expected: &str) -> PyResult<(Vec<Bound<'py, Frame>>, bool)> {
    if let Ok(f) = frame.cast::<Frame>() {
        return Ok((vec![f.clone()], true));
    }
    if !(frame.is_instance_of::<PyList>() || frame.is_instance_of::<PyTuple>()) {
        return Err(type_error("frame", format!("expected {expected}, got {}", type_name(frame))));
    }
    let frames = frame
        .try_iter()?
        .map(|f| {
            f?.cast_into::<Frame>().map_err(|e| {
                type_error(
                    "frame",
                    format!("expected {expected}, got a list holding {}", type_name(e.into_inner().as_any())),
                )
            })
        })
        .collect::<PyResult<_>>()?;
    Ok((frames, false))
}

/// `v` (one entry per cell, grid order) as an array of shape `(h, w)` or `(h, w, depth)`.
pub fn grid_array<'py, T: Element>(
    py: Python<'py>,
    v: Vec<T>,
    (h, w): (usize, usize),
    depth: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = PyArray1::from_vec(py, v);
    Ok(match depth {
        None => a.reshape([h, w])?.into_any(),
        Some(d) => a.reshape([h, w, d])?.into_any(),
    })
}

fn vec3s(v: &[glam::Vec3]) -> Vec<f32> {
    let mut out = Vec::with_capacity(3 * v.len());
    for p in v {
        out.extend_from_slice(&p.to_array());
    }
    out
}

#[pymethods]
impl Frame {
    /// Grid rows per echo plane (rings, row 0 lowest).
    #[getter]
    fn rows(&self) -> usize {
        self.cloud().rows
    }

    /// Grid columns (column 0 = left-most azimuth).
    #[getter]
    fn cols(&self) -> usize {
        self.cloud().cols
    }

    /// Echo planes (1 except multi-echo sensors).
    #[getter]
    fn planes(&self) -> usize {
        self.cloud().planes
    }

    /// The arrays' grid shape `(planes * rows, cols)`.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        self.grid()
    }

    /// Frame index within its scan.
    #[getter]
    fn index(&self) -> usize {
        self.scan.frames()[self.k].index
    }

    /// The scene's name (bundled name, family, file) or the file read.
    #[getter]
    fn scene(&self) -> &str {
        self.scan.scene_name()
    }

    /// The scene's generator family (`"unknown"` for a file read back).
    #[getter]
    fn family(&self) -> &str {
        self.scan.family()
    }

    /// The rig's name (empty for a file read back).
    #[getter]
    fn rig(&self) -> &str {
        &self.scan.rig().name
    }

    /// The scan's seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.scan.seed()
    }

    /// Number of cells holding a return.
    #[getter]
    fn returns(&self) -> usize {
        self.cloud().returns()
    }

    /// Number of returns whose ground truth is ground.
    #[getter]
    fn ground_returns(&self) -> usize {
        self.cloud().ground_returns()
    }

    /// Vehicle pose at the start of the frame as a 4 x 4 float32 matrix (world from vehicle).
    #[getter]
    fn world_from_vehicle<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = glam::Mat4::from(self.scan.frames()[self.k].world_from_vehicle).transpose();
        grid_array(py, m.to_cols_array().to_vec(), (4, 4), None)
    }

    /// The mount of sensor `sensor` of the rig as a 4 x 4 float32 matrix (vehicle from sensor:
    /// its last column is the sensor's position in the vehicle frame). `ValueError` for a sensor
    /// the rig does not have (a file read back has none).
    #[pyo3(signature = (sensor=0))]
    fn vehicle_from_sensor<'py>(&self, py: Python<'py>, sensor: usize) -> PyResult<Bound<'py, PyAny>> {
        let sensors = &self.scan.rig().sensors;
        let s = sensors.get(sensor).ok_or_else(|| {
            crate::error::value_error(
                "sensor",
                format!(
                    "{sensor}: the rig has {} sensor(s){}",
                    sensors.len(),
                    if sensors.is_empty() { " (a file read back has no rig)" } else { "" }
                ),
            )
        })?;
        let m = glam::Mat4::from(s.mount.vehicle_from_sensor()).transpose();
        grid_array(py, m.to_cols_array().to_vec(), (4, 4), None)
    }

    /// Positions `x y z` in the vehicle frame (metres; x forward, y left, z up from the ground under
    /// the rear axle), float32 `(H, W, 3)`, NaN where there is no return.
    #[getter]
    fn xyz<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, vec3s(&self.cloud().point_in_vehicle), self.grid(), Some(3))
    }

    /// True surface normals (vehicle frame, unit), float32 `(H, W, 3)`, zero where no return.
    #[getter]
    fn normal<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, vec3s(&self.cloud().normal), self.grid(), Some(3))
    }

    /// Measured range from the beam origin, metres, float32 `(H, W)`, NaN where no return.
    #[getter]
    fn range<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, self.cloud().range_m.clone(), self.grid(), None)
    }

    /// Intensity in [0, 1], float32 `(H, W)`, 0 where no return.
    #[getter]
    fn intensity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, self.cloud().intensity.clone(), self.grid(), None)
    }

    /// Shot time, seconds since the start of the scan, float64 `(H, W)` (every cell).
    #[getter]
    fn time<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, self.cloud().time_s.clone(), self.grid(), None)
    }

    /// The sensor's own ring (laser) index, uint16 `(H, W)` (every cell).
    #[getter]
    fn ring<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, self.cloud().ring.clone(), self.grid(), None)
    }

    /// The sensor's own column index, uint32 `(H, W)` (every cell).
    #[getter]
    fn column<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, self.cloud().column.clone(), self.grid(), None)
    }

    /// Sensor id (index into the rig), uint8 `(H, W)`; 255 where no sensor covers the cell.
    #[getter]
    fn sensor<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, self.cloud().sensor.clone(), self.grid(), None)
    }

    /// Echo number of the return (0 = first), uint8 `(H, W)`.
    #[getter]
    fn echo<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, self.cloud().echo.clone(), self.grid(), None)
    }

    /// SemanticKITTI class id of the surface hit (ours for bush: 73), uint16 `(H, W)`; 0 where no
    /// return.
    #[getter]
    fn label<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, self.cloud().label.iter().map(|c| c.0).collect(), self.grid(), None)
    }

    /// Instance id of the surface hit, uint32 `(H, W)`; 0 for stuff (ground, walls) and no return.
    #[getter]
    fn instance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid_array(py, self.cloud().instance.clone(), self.grid(), None)
    }

    /// Ground truth: whether the surface hit is ground, bool `(H, W)`; False where no return.
    #[getter]
    fn ground<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let c = self.cloud();
        let v = (0..c.len()).map(|i| c.ground[i] && c.has_return(i)).collect();
        grid_array(py, v, self.grid(), None)
    }

    /// Whether the cell holds a return, bool `(H, W)`.
    #[getter]
    fn valid<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let c = self.cloud();
        grid_array(py, (0..c.len()).map(|i| c.has_return(i)).collect(), self.grid(), None)
    }

    /// The returns as an `(N, 4)` float32 array of `x y z intensity` (a KITTI `.bin` record; vehicle
    /// frame), in grid order (plane by plane, row by row, column by column), and the index map
    /// back to the cells: an `(N,)` int64 array of flat cell indices, so that
    /// `frame.xyz.reshape(-1, 3)[cells] == points[:, :3]`.
    fn points<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let c = self.cloud();
        let cells: Vec<i64> = (0..c.len()).filter(|&i| c.has_return(i)).map(|i| i as i64).collect();
        let mut pts = Vec::with_capacity(4 * cells.len());
        for &i in &cells {
            let p = c.point_in_vehicle[i as usize];
            pts.extend_from_slice(&[p.x, p.y, p.z, c.intensity[i as usize]]);
        }
        let n = cells.len();
        let pts = PyArray1::from_vec(py, pts).reshape([n, 4])?.into_any();
        Ok((pts, PyArray1::from_vec(py, cells).into_any()))
    }

    /// The mask of region `name` over the cells, bool `(H, W)` (see `groundtruth.REGIONS`; also
    /// `class:<name or id>`, `instance:<id>`, `range:<min>-<max>`). A region of another scene family
    /// raises `ValueError`.
    fn region<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let region = parse_region(name)?;
        self.mask(py, &region)
    }

    /// Every region this frame's scene has, name -> bool `(H, W)` mask (as `groundtruth.regions`).
    fn regions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::score::regions_of(py, self)
    }

    /// How `read()` put the frame into rings and columns (the ordering report the command line's
    /// `classify` prints), as a dict: `summary` (the line `groundtruth classify` prints: `ordered
    /// into ROWS x COLS x PLANES: path ...; sensor matched: vlp16 (...)` or `... unnamed sensor: ...`),
    /// `sensor` (`model`: the catalogue's sensor matched, None for an unnamed one; `rings`, `rows`,
    /// `columns`, `order`, `echoes`, `mean_error_deg`; None where `rig` or `calibration` named
    /// the sensor, or none was recovered), `path` (`"unfolded"`, `"beam-table"`, `"ring-field"`,
    /// `"organized"`; None for one of our own files kept as written), the counts (`points`,
    /// `placed`, `moved`, `stacked`, `shared`, `outside`, `skipped`, `no_returns`, `too_near`: the
    /// no-returns nearer than the sensor's minimum range `min_range_m`, `rings_found`),
    /// `fallback`, `rows`, `cols`, `planes`, and where the frame came from (`file`, `layout`,
    /// `layout_description`, `layout_by`: `"name"`, `"content"` or `"flag"` for `layout=`; `topic`,
    /// `message` for a bag's message). None for scans and frames read with `ordered=False`.
    #[getter]
    fn ordering<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.ordering.as_ref().map(|o| o.to_dict(py)).transpose()
    }

    /// The cell of each point of the file (or message) read, in the file's own point order: an
    /// int64 `(N,)` array of flat cell indices into the `(H, W)` grid (`frame.xyz.reshape(-1,
    /// 3)[cell]`), -1 for a point ordering skipped (NaN coordinates, a no-return). None for scans,
    /// frames read with `ordered=False` and our own files kept as written (their points are the
    /// cells).
    #[getter]
    fn cell_of_point<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyAny>> {
        let report = self.ordering.as_ref()?.report.as_ref()?;
        let cells: Vec<i64> = report.cell_of_point.iter().map(|c| c.map_or(-1, i64::from)).collect();
        Some(PyArray1::from_vec(py, cells).into_any())
    }

    /// Decisions over the cells (a bool `(H, W)` array, as `classify()` returns) as one uint8 per
    /// point of the file read, in the file's own point order, 1 = ground (0 for points ordering
    /// skipped): the bytes `groundtruth classify` writes to `frame_NNNNNN.ground`. For a frame not
    /// reordered (a scan, `ordered=False`, our own files) one byte per cell.
    fn decisions_per_point<'py>(&self, py: Python<'py>, decisions: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let cells = cell_decisions(self, decisions)?;
        let report = self.ordering.as_ref().and_then(|o| o.report.as_ref());
        let bytes = classifier::ordering::decisions_per_input_point(report, &cells);
        Ok(PyArray1::from_vec(py, bytes).into_any())
    }

    fn __repr__(&self) -> String {
        let c = self.cloud();
        format!(
            "Frame(scene={:?}, rig={:?}, index={}, shape=({}, {}), returns={}, ground_returns={})",
            self.scan.scene_name(),
            self.scan.rig().name,
            self.index(),
            c.planes * c.rows,
            c.cols,
            c.returns(),
            c.ground_returns()
        )
    }
}

impl Frame {
    /// The mask of `region` as a bool `(H, W)` array.
    pub fn mask<'py>(&self, py: Python<'py>, region: &Region) -> PyResult<Bound<'py, PyAny>> {
        let m = self.scan.region_mask(self.k, region).map_err(scenario_error)?;
        grid_array(py, m, self.grid(), None)
    }
}
