//! How a frame read with `read(..., ordered=True)` was put into rings and columns: the library's
//! ordering report ([`classifier::ordering::OrderingReport`]) and where the frame came from
//! ([`classifier::recording::Provenance`]), as `Frame.ordering` (a dict); its report maps
//! `Frame.decisions_per_point` to the file's own point order.

use classifier::ordering::OrderingReport;
use classifier::recording::Provenance;
use pyo3::prelude::*;
use sim::OrderedCloud;

use crate::error::value_error;

/// What ordering did with one frame read from a file or a bag's message.
#[derive(Clone, Debug)]
pub struct ReadOrdering {
    /// The ordering report; `None` for a frame kept as written (one of our own files, already in
    /// ring x column order).
    pub report: Option<OrderingReport>,
    /// The file or message, its layout and what decided it.
    pub provenance: Provenance,
    /// `(rows, cols, planes)` of the grid it was ordered into.
    pub grid: (usize, usize, usize),
}

impl ReadOrdering {
    /// The ordering of a frame of [`classifier::recording::Frames`] (its cloud, report and
    /// provenance).
    pub fn of(cloud: &OrderedCloud, report: Option<&OrderingReport>, provenance: &Provenance) -> Self {
        Self { report: report.cloned(), provenance: provenance.clone(), grid: (cloud.rows, cloud.cols, cloud.planes) }
    }

    /// The line the command line's `classify` prints for the frame: `ordered into R x C x P: ...`
    /// with the report's summary (the sensor matched or unnamed, the path taken, the counts), or
    /// `kept as written` for a frame without a report.
    pub fn summary(&self) -> String {
        let (rows, cols, planes) = self.grid;
        match &self.report {
            Some(r) => r.grid_line(rows, cols, planes),
            None => format!("kept as written ({rows} x {cols} x {planes}: already in ring x column order)"),
        }
    }

    /// The report as a Python dict: the report's fields (`path`, `sensor`, `placed`, ... as the
    /// library serializes them; `path` None for a frame kept as written), `points` (input points),
    /// `rows`, `cols`, `planes`, `summary`, and the provenance's (`file`, `layout`, `layout_by`,
    /// `layout_description`, `topic`, `message`, `log_time_ns`, `sequence`).
    pub fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mut doc = serde_json::Map::new();
        let fields = |v: serde_json::Result<serde_json::Value>| match v {
            Ok(serde_json::Value::Object(m)) => Ok(m),
            Ok(other) => Err(value_error("ordering", format!("not a record: {other}"))),
            Err(e) => Err(value_error("ordering", e)),
        };
        doc.extend(fields(serde_json::to_value(&self.provenance))?);
        doc.insert("layout_description".into(), self.provenance.layout.description().into());
        match &self.report {
            Some(r) => {
                doc.extend(fields(serde_json::to_value(r))?);
                doc.insert("points".into(), r.cell_of_point.len().into());
            }
            None => {
                doc.insert("path".into(), serde_json::Value::Null);
                doc.insert("sensor".into(), serde_json::Value::Null);
            }
        }
        let (rows, cols, planes) = self.grid;
        doc.insert("rows".into(), rows.into());
        doc.insert("cols".into(), cols.into());
        doc.insert("planes".into(), planes.into());
        doc.insert("summary".into(), self.summary().into());
        // Through Python's json module: plain dicts, lists, numbers, strings and None.
        let text = serde_json::to_string(&doc).map_err(|e| value_error("ordering", e))?;
        py.import("json")?.call_method1("loads", (text,))
    }
}
