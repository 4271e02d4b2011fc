//! Ordering recovery: puts a cloud from another source (a KITTI `.bin`, a shuffled or merged cloud)
//! back into ring x column order, so the method runs on it (the paper: "it can be easily computed
//! from the physical sensor layout"), and keeps every point.
//!
//! Paths, chosen per cloud ([`order_cloud`], [`OrderingPath`]):
//! - **scan unfolding** ([`unfold`]) for clouds in scan order (KITTI `.bin`): rings from the turns
//!   of the azimuth, matched to the beam table's rows;
//! - **the beam table** ([`table`]) for clouds out of order: each point's row from its elevation,
//!   with the table's origin offsets undone ([`beam_table`]); taken when unfolding is refused, and
//!   the report says why;
//! - **ring fields** ([`table::ring_wishes`]): rows from a `ring` value per point (PCD / PLY of
//!   the ROS drivers), ring 0 at the bottom or the top as the rings' elevations say;
//! - **organized clouds** ([`organized`]) keep their cells; their rows are put in elevation order
//!   from the `ring` field or the rows' elevations, whichever way up the file stores them; an
//!   organized `.bin` (a whole sensor image with `0, 0, 0` no-returns, row by row or column by
//!   column, as Ouster clouds converted to KITTI files are) is recognised ([`setup`]);
//!
//! The beam table comes from a rig, the sensor's own calibration file ([`calibration`]: our TOML or
//! text format, the velodyne driver's YAML, Ouster's metadata JSON), or, without either, from the
//! data ([`recover`]: the rings and columns a flat cloud shows, the sensor named where its
//! elevations match a known table; a cloud whose order cannot be recovered is refused).
//!
//! Columns come from each point's beam azimuth on every path. Points that share a cell are all kept
//! ([`placement`]): the adjacent free column on the point's side, else a further plane of the same
//! cell. Points with NaN or infinite coordinates are skipped (decision 0) and counted; more than
//! [`MAX_BAD_FRACTION`] of them refuses the cloud. Points at exactly (0, 0, 0) are no-returns
//! (skipped, counted), and so are points nearer than the sensor's minimum range where the table
//! knows it ([`BeamTable::min_range_m`]). [`OrderingReport`] gives the cell of every input point and what each step
//! placed.

pub mod beam_table;
mod buffer;
pub mod calibration;
mod input_point;
pub mod organized;
pub mod placement;
pub(crate) mod polar;
pub mod recover;
pub mod report;
pub mod setup;
pub mod table;
pub mod unfold;
mod usable;

use glam::{Affine3A, Vec3};
use sim::{OrderedCloud, SemanticClass};

pub use beam_table::{BeamTable, TableRows};
pub use buffer::CloudBuffer;
pub use calibration::{Calibration, CalibrationError};
pub use input_point::InputPoint;
pub use organized::{order_organized, order_organized_in_place, read_organized_into};
pub use placement::PointAttributes;
pub use recover::{RecoveredOrder, RecoveredSensor, RecoveryError};
pub use report::{OrderingPath, OrderingReport};
pub use setup::{KITTI_COLUMNS, OrganizedLayout, SensorSetup};
pub use unfold::UnfoldParams;
use unfold::Unfolded;
use usable::Usable;

use crate::error::{ClassifyError, Result};

/// Largest fraction of bad points (NaN or infinite coordinates) a cloud may hold; they are
/// skipped and counted. A cloud with more is refused.
pub const MAX_BAD_FRACTION: f64 = 0.01;

/// Which paths [`order_cloud`] may take.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PathChoice {
    /// Unfold where the order allows, else the beam table.
    #[default]
    Auto,
    /// Only the beam table (the order of the points is ignored).
    BeamTable,
    /// Only unfolding (refused where the order does not unfold).
    Unfold,
}

/// Orders `points_in_sensor` into the grid of `table`, by unfolding or the beam table as `choice`
/// allows; points go to the vehicle frame through `vehicle_from_sensor`. Every usable point gets a
/// cell ([`OrderingReport::cell_of_point`]).
pub fn order_cloud<P: InputPoint>(
    points_in_sensor: &[P],
    attributes: &PointAttributes<'_>,
    table: &BeamTable,
    vehicle_from_sensor: Affine3A,
    choice: PathChoice,
    params: &UnfoldParams,
) -> Result<(OrderedCloud, OrderingReport)> {
    let (mut cloud, mut report) = (CloudBuffer::default(), OrderingReport::default());
    order_cloud_into(
        points_in_sensor,
        attributes,
        table,
        vehicle_from_sensor,
        choice,
        params,
        &mut cloud,
        &mut report,
    )?;
    Ok((cloud.into_cloud(), report))
}

/// As [`order_cloud`], into `cloud` and `report`, whose buffers are reused: a sequence of frames
/// ordered one after another allocates no cloud once they are large enough, and does not rewrite
/// the fields it never fills ([`CloudBuffer`]). On an error `report` is not meaningful and the
/// cloud is the previous one.
#[allow(clippy::too_many_arguments)]
pub fn order_cloud_into<P: InputPoint>(
    points_in_sensor: &[P],
    attributes: &PointAttributes<'_>,
    table: &BeamTable,
    vehicle_from_sensor: Affine3A,
    choice: PathChoice,
    params: &UnfoldParams,
    cloud: &mut CloudBuffer,
    report: &mut OrderingReport,
) -> Result<()> {
    let rows = table.rows()?;
    let n = points_in_sensor.len();
    for (name, len) in [
        ("rings", attributes.rings.map(<[u16]>::len)),
        ("labels", attributes.labels.map(<[SemanticClass]>::len)),
        ("intensities", attributes.intensity.map(<[f32]>::len)),
        ("times", attributes.time_s.map(<[f64]>::len)),
    ] {
        if len.is_some_and(|l| l != n) {
            return Err(ClassifyError::Ordering(format!("{name} and points differ in length")));
        }
    }
    // One entry per point; [`placement::build_cloud`] sets every one of them.
    let mut cell_of_point = std::mem::take(&mut report.cell_of_point);
    cell_of_point.resize(n, None);
    *report = OrderingReport { cell_of_point, ..OrderingReport::default() };
    // Where the points may unfold, the polar pass over every point also counts the unusable ones:
    // the points are read once.
    let (usable, mut polar) = if attributes.rings.is_none() && choice != PathChoice::BeamTable {
        Usable::check_count(n)?;
        let (polar, counts) = polar::polar_counting(points_in_sensor, None);
        let usable = Usable::from_counts(points_in_sensor, counts, table.min_range_m, report)?;
        // With unusable points, the polar values of the usable ones only (rare).
        let polar = match usable.indices() {
            None => polar,
            Some(idx) => polar::polar(points_in_sensor, Some(idx)),
        };
        (usable, Some(polar))
    } else {
        (Usable::find(points_in_sensor, table.min_range_m, report)?, None)
    };
    let place = |wishes: Vec<placement::Wish>, report: &mut OrderingReport| {
        placement::place(&wishes, rows.len(), rows.cols, rows.full_turn, report)
    };
    let (cells, planes) = match (attributes.rings, choice) {
        (Some(rings), _) => {
            report.path = OrderingPath::RingField;
            let wishes =
                table::ring_wishes(points_in_sensor, &usable, rings, &rows, report).map_err(ClassifyError::Ordering)?;
            place(wishes, report)
        }
        (None, PathChoice::BeamTable) => {
            report.path = OrderingPath::BeamTable;
            place(table::table_wishes(points_in_sensor, &usable, &rows, report), report)
        }
        (None, PathChoice::Unfold | PathChoice::Auto) => {
            let polar = polar.take().unwrap_or_else(|| polar::polar(points_in_sensor, usable.indices()));
            match unfold::unfold(points_in_sensor, &usable, polar, &rows, params, report) {
                Ok(Unfolded::Wishes(wishes)) => {
                    report.path = OrderingPath::Unfolded;
                    place(wishes, report)
                }
                Ok(Unfolded::Rings { bounds, row_of_ring, column, spans_turn }) => {
                    report.path = OrderingPath::Unfolded;
                    placement::place_rings(&bounds, &row_of_ring, &column, &spans_turn, rows.len(), rows.cols, report)
                }
                Err(why) if choice == PathChoice::Auto => {
                    report.path = OrderingPath::BeamTable;
                    report.fallback = Some(why);
                    report.rings_found = 0;
                    place(table::table_wishes(points_in_sensor, &usable, &rows, report), report)
                }
                Err(why) => return Err(ClassifyError::Ordering(format!("the points do not unfold: {why}"))),
            }
        }
    };
    placement::build_cloud(
        points_in_sensor,
        attributes,
        &usable,
        &cells,
        rows.len(),
        rows.cols,
        planes,
        vehicle_from_sensor,
        cloud,
        report,
    );
    Ok(())
}

/// Orders `points_in_sensor` (with optional labels) by the beam table alone, ignoring their order
/// (the original interface; [`order_cloud`] chooses the path). Labels make the cloud's `label` and
/// `ground` fields.
pub fn order_points(
    points_in_sensor: &[Vec3],
    labels: Option<&[SemanticClass]>,
    table: &BeamTable,
    vehicle_from_sensor: Affine3A,
) -> Result<(OrderedCloud, OrderingReport)> {
    let attributes = PointAttributes { labels, ..PointAttributes::default() };
    order_cloud(
        points_in_sensor,
        &attributes,
        table,
        vehicle_from_sensor,
        PathChoice::BeamTable,
        &UnfoldParams::default(),
    )
}

/// Maps per-cell decisions back to the input points: one byte per point, 1 = ground; skipped
/// points are 0.
pub fn decisions_per_point(report: &OrderingReport, ground: &[bool]) -> Vec<u8> {
    report
        .cell_of_point
        .iter()
        .map(|c| c.map_or(0, |c| u8::from(ground.get(c as usize).copied().unwrap_or(false))))
        .collect()
}

/// Decisions per cell as one byte per input point in the input's own order (1 = ground): through
/// the ordering `report` where there is one ([`decisions_per_point`]), else cell by cell (an input
/// kept as written, one of our own files).
pub fn decisions_per_input_point(report: Option<&OrderingReport>, ground: &[bool]) -> Vec<u8> {
    match report {
        Some(r) => decisions_per_point(r, ground),
        None => ground.iter().map(|&g| u8::from(g)).collect(),
    }
}
