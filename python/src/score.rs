//! Regions and scores: the scenario API's regions as masks, and `score()` of any boolean decisions
//! (over the returns or the cells) through `groundtruth_scenario::Scan::score_frame`.

use groundtruth_scenario::{Region, RegionScore, ScenarioError};
use numpy::{PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::args::type_name;
use crate::error::{scenario_error, type_error, value_error};
use crate::frame::{Frame, frames_arg};

/// Every region name `parse_region` takes without an argument.
pub const REGIONS: [&str; 12] = [
    "all",
    "ground",
    "non-ground",
    "ramp-surface",
    "basin-floor",
    "beyond-basin",
    "plateau",
    "flat-raised-tops",
    "vehicle-roofs",
    "hill-slope",
    "vegetation",
    "weather",
];

/// The region called `name` (its `Display` name in the Rust API), or `class:<name or id>`,
/// `instance:<id>`, `range:<min>-<max>`.
pub fn parse_region(name: &str) -> PyResult<Region> {
    let bad = |why: &str| {
        value_error(
            "region",
            format!(
                "`{name}`: {why} (allowed: {}, class:<name or id>, instance:<id>, range:<min>-<max> metres)",
                REGIONS.join(", ")
            ),
        )
    };
    Ok(match name {
        "all" => Region::All,
        "ground" => Region::Ground,
        "non-ground" => Region::NonGround,
        "ramp-surface" => Region::RampSurface,
        "basin-floor" => Region::BasinFloor,
        "beyond-basin" => Region::BeyondBasin,
        "plateau" => Region::Plateau,
        "flat-raised-tops" => Region::FlatRaisedTops,
        "vehicle-roofs" => Region::VehicleRoofs,
        "hill-slope" => Region::HillSlope,
        "vegetation" => Region::Vegetation,
        "weather" => Region::Weather,
        _ => {
            if let Some(c) = name.strip_prefix("class:") {
                let spec = match c.parse::<u16>() {
                    Ok(id) => scenes::schema::ClassSpec::Id(id),
                    Err(_) => scenes::schema::ClassSpec::Name(c.to_string()),
                };
                Region::Class(spec.resolve("region class").map_err(|e| value_error("region", e))?)
            } else if let Some(i) = name.strip_prefix("instance:") {
                Region::Instance(i.parse().map_err(|_| bad("the instance is not a u32"))?)
            } else if let Some(r) = name.strip_prefix("range:") {
                let (a, b) = r.split_once('-').ok_or_else(|| bad("expected range:<min>-<max>"))?;
                let min_m: f32 = a.trim().parse().map_err(|_| bad("min is not a number"))?;
                let max_m: f32 = b.trim().parse().map_err(|_| bad("max is not a number"))?;
                Region::RangeBand { min_m, max_m }
            } else {
                return Err(bad("unknown region"));
            }
        }
    })
}

/// Every region of `REGIONS` the frame's scene family has, name -> mask.
pub fn regions_of<'py>(py: Python<'py>, frame: &Frame) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    for name in REGIONS {
        let region = parse_region(name)?;
        match frame.scan.region_mask(frame.k, &region) {
            Ok(m) => out.set_item(name, crate::frame::grid_array(py, m, frame.grid(), None)?)?,
            Err(ScenarioError::RegionFamily { .. }) => {}
            Err(e) => return Err(scenario_error(e)),
        }
    }
    Ok(out)
}

/// Ground decisions over a region: confusion counts (ground is positive) and the rates.
///
/// A rate whose denominator is zero is NaN (e.g. the recall of a region without ground), so an
/// assertion like `s.recall >= 0.9` fails rather than passing vacuously.
#[pyclass(frozen, module = "groundtruth")]
pub struct Score(pub RegionScore);

#[pymethods]
impl Score {
    /// The region's name.
    #[getter]
    fn region(&self) -> &str {
        &self.0.region
    }
    /// Ground returns called ground.
    #[getter]
    fn tp(&self) -> u64 {
        self.0.tp
    }
    /// Non-ground returns called ground (false ground).
    #[getter]
    fn fp(&self) -> u64 {
        self.0.fp
    }
    /// Non-ground returns called non-ground.
    #[getter]
    fn tn(&self) -> u64 {
        self.0.tn
    }
    /// Ground returns called non-ground (missed ground).
    #[getter(r#fn)]
    fn fn_(&self) -> u64 {
        self.0.fn_
    }
    /// Returns in the region.
    #[getter]
    fn returns(&self) -> u64 {
        self.0.returns()
    }
    /// Ground returns in the region.
    #[getter]
    fn ground(&self) -> u64 {
        self.0.ground()
    }
    /// Share of the returns decided right, `(tp + tn) / returns`.
    #[getter]
    fn accuracy(&self) -> f64 {
        self.0.accuracy()
    }
    /// False-ground rate (FPR), `fp / (fp + tn)`.
    #[getter]
    fn fpr(&self) -> f64 {
        self.0.false_ground_rate()
    }
    /// Same as `fpr`: the share of the non-ground returns called ground.
    #[getter]
    fn false_ground_rate(&self) -> f64 {
        self.0.false_ground_rate()
    }
    /// `tp / (tp + fp)`.
    #[getter]
    fn precision(&self) -> f64 {
        self.0.precision()
    }
    /// `tp / (tp + fn)`.
    #[getter]
    fn recall(&self) -> f64 {
        self.0.recall()
    }
    /// F1 of the ground class.
    #[getter]
    fn f1(&self) -> f64 {
        self.0.f1()
    }
    /// Intersection over union of the ground class, `tp / (tp + fp + fn)`.
    #[getter]
    fn iou(&self) -> f64 {
        self.0.counts().iou()
    }
    /// Everything as a dict (counts and rates).
    fn as_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("region", &self.0.region)?;
        for (k, v) in [("tp", self.0.tp), ("fn", self.0.fn_), ("fp", self.0.fp), ("tn", self.0.tn)] {
            d.set_item(k, v)?;
        }
        d.set_item("returns", self.0.returns())?;
        for (k, v) in [
            ("accuracy", self.accuracy()),
            ("fpr", self.fpr()),
            ("precision", self.precision()),
            ("recall", self.recall()),
            ("f1", self.f1()),
            ("iou", self.iou()),
        ] {
            d.set_item(k, v)?;
        }
        Ok(d)
    }
    fn __repr__(&self) -> String {
        format!("Score({}, accuracy {:.4}, IoU {:.4})", self.0, self.accuracy(), self.iou())
    }
}

/// Per-cell decisions from `decisions`: a numpy bool array of the grid shape `(H, W)`, of `H * W`
/// cells, or of one decision per return in `points()` order (grid order).
pub fn cell_decisions(frame: &Frame, decisions: &Bound<'_, PyAny>) -> PyResult<Vec<bool>> {
    let Ok(arr) = decisions.cast::<PyUntypedArray>() else {
        return Err(type_error("decisions", format!("expected a numpy bool array, got {}", type_name(decisions))));
    };
    let dtype = arr.dtype();
    if !dtype.is_equiv_to(&numpy::dtype::<bool>(decisions.py())) {
        return Err(type_error("decisions", format!("expected dtype bool, got {}", dtype.str()?)));
    }
    let arr = arr.cast::<numpy::PyArrayDyn<bool>>()?;
    let values: Vec<bool> = arr
        .try_readonly()
        .map_err(|e| value_error("decisions", format!("the array cannot be read: {e}")))?
        .as_array()
        .iter()
        .copied()
        .collect();
    let c = frame.cloud();
    let (h, w) = frame.grid();
    let shape = arr.shape().to_vec();
    let returns = c.returns();
    if shape == [h, w] || shape == [h * w] {
        return Ok(values);
    }
    if shape == [returns] {
        let mut d = vec![false; c.len()];
        let cells = (0..c.len()).filter(|&i| c.has_return(i));
        for (i, g) in cells.zip(values) {
            d[i] = g;
        }
        return Ok(d);
    }
    Err(value_error(
        "decisions",
        format!("shape {shape:?} matches neither the grid ({h}, {w}), its {} cells, nor the {returns} returns", h * w),
    ))
}

/// Scores ground decisions on `frame` over `region` (default: every return): accuracy, FPR,
/// precision, recall, F1, IoU and the counts. `decisions` is a numpy bool array over the cells
/// (grid shape or flat) or over the returns in `points()` order. With a list of frames (all the
/// frames of one scan, in order, as `scan()` returns them) and a list of decision arrays, the
/// counts are pooled over the frames, as the Rust API's `Scan::score` pools them.
#[pyfunction]
#[pyo3(signature = (frame, decisions, region=None))]
pub fn score(frame: &Bound<'_, PyAny>, decisions: &Bound<'_, PyAny>, region: Option<&str>) -> PyResult<Score> {
    let region = parse_region(region.unwrap_or("all"))?;
    let (frames, single) = frames_arg(frame, "a Frame, or a list of the Frames of one scan")?;
    if single {
        let f = frames[0].get();
        let d = cell_decisions(f, decisions)?;
        return Ok(Score(f.scan.score_frame(f.k, &region, &d).map_err(scenario_error)?));
    }
    let Some(first) = frames.first() else {
        return Err(value_error("frame", "an empty list"));
    };
    let scan = first.get().scan.clone();
    let whole = frames.len() == scan.frames().len()
        && frames.iter().enumerate().all(|(i, f)| std::sync::Arc::ptr_eq(&f.get().scan, &scan) && f.get().k == i);
    if !whole {
        return Err(value_error(
            "frame",
            format!(
                "pooled scores take all {} frames of one scan, in order, as scan() returns them",
                scan.frames().len()
            ),
        ));
    }
    if !(decisions.is_instance_of::<PyList>() || decisions.is_instance_of::<PyTuple>()) {
        return Err(type_error(
            "decisions",
            format!("expected a list of one bool array per frame, got {}", type_name(decisions)),
        ));
    }
    let arrays: Vec<Bound<'_, PyAny>> = decisions.try_iter()?.collect::<PyResult<_>>()?;
    if arrays.len() != frames.len() {
        return Err(value_error("decisions", format!("{} arrays for {} frames", arrays.len(), frames.len())));
    }
    let cells: Vec<Vec<bool>> =
        frames.iter().zip(&arrays).map(|(f, d)| cell_decisions(f.get(), d)).collect::<PyResult<_>>()?;
    Ok(Score(scan.score(&region, &cells).map_err(scenario_error)?))
}

/// Every region the frame's scene has, name -> bool `(H, W)` mask.
#[pyfunction]
pub fn regions<'py>(py: Python<'py>, frame: &Frame) -> PyResult<Bound<'py, PyDict>> {
    regions_of(py, frame)
}
