//! The file formats read as frames: one reader ([`FrameReader`]) for every layout
//! ([`InputLayout`]), ordered for classification with a [`SensorSetup`] or read as stored.
//!
//! - PCD: a driver's organized cloud (no `# groundtruth` line, one plane) has its rows put in
//!   elevation order as it is decoded ([`crate::ordering::organized`]); our own layout (or several
//!   echo planes) is taken as it is; an unorganized cloud is ordered as a KITTI file is, or from its
//!   `ring` field.
//! - KITTI `.bin` (and its `.label`): ordered where the file's bytes lie, by scan unfolding or the
//!   beam table ([`SensorSetup::order_kitti`]).
//! - nuScenes `.pcd.bin` (or a `.bin` whose bytes give the layout away, or `--layout nuscenes`:
//!   [`InputLayout::decide`]): ordered from its ring field, as a PCD's `ring` is.
//! - No-returns: an unorganized PCD or PointCloud2 holds them as NaN points (PCL's convention; a
//!   message declaring `is_dense = false`, or one declaring `is_dense = true` that holds NaNs
//!   anyway, which is counted for a warning): they are read as no-returns (decision 0, kept in
//!   place), not as bad data. A KITTI file's NaNs stay bad data.
//! - PLY, LAS: ordered from their points as an unorganized cloud is (their `ring` where they have
//!   one).
//! - A bag's PointCloud2 message: decoded by the PCD reader straight from the message's data
//!   ([`sim::io::ros2::pointcloud2::frame`]) and ordered as a PCD file is.
//! - A labelled dataset's frame (a SemanticKITTI `.bin` with its `.label`, a nuScenes sweep with
//!   its lidarseg labels: [`crate::dataset::DatasetLayout`]): read in file order with its classes
//!   ([`LabelledFrame::read_points`]) and ordered as a `.bin` is, its classes carried through
//!   ordering as the cloud's labels ([`FrameReader::read_labelled`]).

use std::path::Path;
use std::time::Instant;

use glam::Affine3A;
use sim::OrderedCloud;
use sim::io::pcd::PcdFrame;
use sim::io::ros2::BagCloud;

use super::bytes::InputBytes;
use super::{InputLayout, LayoutBasis, LayoutChoice, Provenance, RecordingError};
use crate::dataset::{DatasetError, FramePoints, LabelledFrame};
use crate::ordering::{CloudBuffer, OrderingReport, PointAttributes, SensorSetup, read_organized_into};

/// Reads and orders frames one after another, keeping its buffers (the file's bytes, its points,
/// the cloud and the ordering report) from frame to frame: a sequence of frames of one sensor
/// allocates nothing after the first (measured: a fresh 128 x 2,048 cloud cost more than its
/// filling, in page faults).
#[derive(Default)]
pub struct FrameReader {
    /// The file's bytes.
    bytes: InputBytes,
    /// A KITTI `.label`'s bytes.
    label_bytes: InputBytes,
    /// A KITTI file's records.
    flat: sim::io::kitti::KittiPoints,
    /// A nuScenes file's points and rings.
    nuscenes: sim::io::nuscenes::NuscenesPoints,
    /// The layout `--layout` names for `.bin` files.
    choice: Option<LayoutChoice>,
    /// The last file's layout and what decided it.
    decided: Option<(InputLayout, LayoutBasis)>,
    /// NaN points of the last unorganized PCD or message, read as no-returns.
    nan_no_returns: usize,
    /// Bytes after the declared records of the last binary PCD file read.
    trailing_bytes: usize,
    /// Whether the last message declared `is_dense = true`.
    declared_dense: bool,
    /// A PCD as the file holds it (ordered from here where it is not organized).
    file_cloud: OrderedCloud,
    /// The cloud to classify.
    cloud: CloudBuffer,
    /// What ordering did, for input from other tools.
    report: OrderingReport,
    /// Whether `report` belongs to the last frame (input from other tools).
    ordered: bool,
    /// The last labelled frame's points, classes and rings in file order.
    labelled: Option<FramePoints>,
}

impl FrameReader {
    /// The last frame's cloud.
    pub fn cloud(&self) -> &OrderedCloud {
        self.cloud.cloud()
    }

    /// What ordering did with the last frame, for input from other tools (cell of every input
    /// point); `None` for our own files and for frames read as stored.
    pub fn report(&self) -> Option<&OrderingReport> {
        self.ordered.then_some(&self.report)
    }

    /// The last frame's points in file order with their classes, for a labelled dataset's frame
    /// ([`FrameReader::read_labelled`]); `None` for other frames.
    pub fn labelled_points(&self) -> Option<&FramePoints> {
        self.labelled.as_ref()
    }

    /// Reads headerless `.bin` files in `choice` (`--layout`) rather than by name and content.
    pub fn set_layout_choice(&mut self, choice: Option<LayoutChoice>) {
        self.choice = choice;
    }

    /// The last file's layout and what decided it (a bag's message: PointCloud2, by name).
    pub fn layout(&self) -> (InputLayout, LayoutBasis) {
        self.decided.unwrap_or((InputLayout::PointCloud2, LayoutBasis::Name))
    }

    /// NaN points of the last unorganized PCD or message, read as no-returns (0 for other layouts).
    pub fn nan_no_returns(&self) -> usize {
        self.nan_no_returns
    }

    /// Bytes after the records the header declares in the last binary PCD file read (left
    /// unread, as PCL leaves them).
    pub fn trailing_bytes(&self) -> usize {
        self.trailing_bytes
    }

    /// Whether the last message declared itself dense (`is_dense = true`; false for files).
    pub fn declared_dense(&self) -> bool {
        self.declared_dense
    }

    /// Takes `cloud` as the last frame's, unordered (a frame read as stored).
    pub(crate) fn set_cloud(&mut self, cloud: OrderedCloud) {
        *self.cloud.cloud_mut() = cloud;
        self.ordered = false;
    }

    /// Forgets what the last frame said (its report, layout, NaN count, density, labelled points)
    /// before the next is read.
    fn forget_last_frame(&mut self) {
        self.ordered = false;
        self.nan_no_returns = 0;
        self.trailing_bytes = 0;
        self.declared_dense = false;
        self.decided = None;
        self.labelled = None;
    }

    /// Reads `path` and orders it; returns the milliseconds spent reading the file (the rest is
    /// ordering; for a driver's organized PCD, decoded in order, only the file's read and the header).
    pub fn read(&mut self, path: &Path, setup: &SensorSetup) -> Result<f64, RecordingError> {
        let t0 = Instant::now();
        self.forget_last_frame();
        let by_name = InputLayout::of_file(path)?;
        if by_name.is_raw() {
            return self.read_raw(path, setup, t0);
        }
        self.decided = Some(InputLayout::decide(path, &[], self.choice)?);
        match by_name {
            InputLayout::Pcd => {
                let FrameReader { bytes, file_cloud, cloud, report, ordered, nan_no_returns, trailing_bytes, .. } =
                    self;
                let bytes = bytes.load(path)?;
                let frame = PcdFrame::parse(path, bytes)?;
                let read = order_pcd(path, &frame, setup, file_cloud, cloud, report, t0)?;
                *ordered = read.from_another_tool;
                *nan_no_returns = read.nan_no_returns;
                *trailing_bytes = frame.trailing_bytes();
                Ok(read.read_ms)
            }
            layout @ (InputLayout::Ply | InputLayout::Las) => {
                // Our own PLY and LAS files hold vehicle-frame points with their rings.
                let (mut c, has_ring, ours) = match layout {
                    InputLayout::Ply => {
                        let bytes = self.bytes.load(path)?;
                        let (c, has_ring) = sim::io::ply::read_bytes_with_ring(path, bytes)?;
                        (c, has_ring, sim::io::ply::written_by_us(bytes))
                    }
                    _ => {
                        let (c, ours) = sim::io::las::read_with_origin(path)?;
                        (c, ours, ours)
                    }
                };
                if ours {
                    to_sensor_frame(path, &mut c, setup)?;
                }
                let read_ms = t0.elapsed().as_secs_f64() * 1e3;
                order_flat_cloud(path, &c, has_ring, setup, &mut self.cloud, &mut self.report)?;
                self.ordered = true;
                Ok(read_ms)
            }
            _ => Err(RecordingError::Unsupported { path: path.to_path_buf() }),
        }
    }

    /// Reads a headerless `.bin` (`t0`: when the read began) in the layout its name, its bytes or
    /// `--layout` give ([`InputLayout::decide`]) and orders it: KITTI records where its bytes lie
    /// ([`SensorSetup::order_kitti`]), nuScenes points from their rings.
    fn read_raw(&mut self, path: &Path, setup: &SensorSetup, t0: Instant) -> Result<f64, RecordingError> {
        let ordering = |error| RecordingError::Ordering { what: format!("`{}`", path.display()), error };
        let FrameReader { bytes, label_bytes, flat, nuscenes, cloud, report, choice, decided, ordered, .. } = self;
        let bytes = bytes.load(path)?;
        let (layout, basis) = InputLayout::decide(path, bytes, *choice)?;
        *decided = Some((layout, basis));
        if layout == InputLayout::NuscenesBin {
            sim::io::nuscenes::points_from_bytes_into(path, bytes, nuscenes)?;
            let read_ms = t0.elapsed().as_secs_f64() * 1e3;
            let attributes = PointAttributes {
                intensity: Some(&nuscenes.intensity),
                rings: Some(&nuscenes.rings),
                ..PointAttributes::default()
            };
            setup.order_flat(&nuscenes.points, &attributes, cloud, report).map_err(ordering)?;
            *ordered = true;
            return Ok(read_ms);
        }
        let label = path.with_extension("label");
        let label_bytes = match label.is_file() {
            true => Some((label.as_path(), label_bytes.load(&label)?)),
            false => None,
        };
        // The records are ordered where the file's bytes lie (no decoding copy) where they can be;
        // the points are decoded otherwise.
        let records = sim::io::kitti::records_or_points_into(path, bytes, label_bytes, flat)?;
        let read_ms = t0.elapsed().as_secs_f64() * 1e3;
        let labels = flat.labels.as_deref();
        let result = match records {
            // Scan-ordered, shuffled or organized (an Ouster image with zero no-returns).
            Some(records) => setup.order_kitti(records, labels, cloud, report),
            None => {
                let records: Vec<[f32; 4]> =
                    flat.points.iter().zip(&flat.intensity).map(|(p, &i)| [p.x, p.y, p.z, i]).collect();
                setup.order_kitti(&records, labels, cloud, report)
            }
        };
        result.map_err(ordering)?;
        *ordered = true;
        Ok(read_ms)
    }

    /// Reads a bag's PointCloud2 message (`provenance` names it in errors) straight from its data
    /// and orders it as [`FrameReader::read`] orders a `.pcd` file (with `setup`), or keeps it as
    /// stored (`None`: the message's own grid and point order, as the PCD of the same cloud is
    /// read). Returns the milliseconds of the decode (the CDR and the header; the rest is
    /// ordering). A message that cannot be read is a [`RecordingError::Message`].
    pub fn read_message(
        &mut self,
        provenance: &Provenance,
        message: &BagCloud,
        setup: Option<&SensorSetup>,
    ) -> Result<f64, RecordingError> {
        let t0 = Instant::now();
        self.forget_last_frame();
        let bad = |reason: String| RecordingError::Message {
            bag: provenance.file.clone(),
            topic: provenance.topic.clone().unwrap_or_default(),
            index: message.index,
            reason,
        };
        let name = provenance.name();
        let name = name.as_path();
        let cloud = message.decode().map_err(bad)?;
        self.declared_dense = cloud.is_dense;
        let frame =
            sim::io::ros2::pointcloud2::frame(name, &cloud, message.groundtruth_comment.as_deref()).map_err(bad)?;
        let Some(setup) = setup else {
            frame.read_into(self.cloud.cloud_mut(), None, Affine3A::IDENTITY).map_err(|e| bad(e.to_string()))?;
            return Ok(t0.elapsed().as_secs_f64() * 1e3);
        };
        let FrameReader { file_cloud, cloud, report, .. } = self;
        let read = order_pcd(name, &frame, setup, file_cloud, cloud, report, t0).map_err(|e| bad(e.to_string()))?;
        self.ordered = read.from_another_tool;
        self.nan_no_returns = read.nan_no_returns;
        Ok(read.read_ms)
    }

    /// Reads the labelled frame `frame` in file order with its classes (SemanticKITTI ids) and, for
    /// nuScenes records, its rings ([`LabelledFrame::read_points`]: a SemanticKITTI `.bin` in the
    /// layout `--layout` names, else the one its name and bytes give) and orders it with `setup`:
    /// KITTI records where they lie ([`SensorSetup::order_kitti`]), nuScenes records from their
    /// rings ([`SensorSetup::order_flat`]), the classes carried through ordering as the cloud's
    /// labels; `None` keeps it as stored (`1 x N` in file order, [`stored_cloud`]). The points stay
    /// at [`FrameReader::labelled_points`]. Returns the milliseconds of the read (the rest is
    /// ordering). Refused, as [`RecordingError::Dataset`]: what the read refuses; a frame ordering
    /// refuses ([`DatasetError::Classify`], naming the `.bin`).
    pub fn read_labelled(&mut self, frame: &LabelledFrame, setup: Option<&SensorSetup>) -> Result<f64, RecordingError> {
        let t0 = Instant::now();
        self.forget_last_frame();
        let points = frame.read_points(self.choice).map_err(Box::new)?;
        let read_ms = t0.elapsed().as_secs_f64() * 1e3;
        self.decided = Some(points.layout);
        match setup {
            Some(setup) => {
                let FramePoints { records, rings, classes, .. } = &points;
                let FrameReader { cloud, report, .. } = self;
                match rings {
                    // A nuScenes sweep: ordered from its rings, as `classify` orders it.
                    Some(rings) => {
                        let attributes = PointAttributes {
                            intensity: None,
                            labels: Some(classes),
                            time_s: None,
                            rings: Some(rings),
                        };
                        setup.order_flat(records, &attributes, cloud, report)
                    }
                    None => setup.order_kitti(records, Some(classes), cloud, report),
                }
                .map_err(|source| Box::new(DatasetError::Classify { path: frame.bin.clone(), source }))?;
                self.ordered = true;
            }
            None => self.set_cloud(stored_cloud(&points)),
        }
        self.labelled = Some(points);
        Ok(read_ms)
    }
}

/// A labelled frame's points as stored: a `1 x N` grid in file order (no-returns and non-finite
/// points as NaN), with their intensity, classes (ground where the class is) and rings where the
/// records have them.
pub fn stored_cloud(points: &FramePoints) -> OrderedCloud {
    let mut cloud = OrderedCloud::empty(1, points.records.len(), 1);
    for (i, (rec, &class)) in points.records.iter().zip(&points.classes).enumerate() {
        let p = glam::Vec3::new(rec[0], rec[1], rec[2]);
        let hit = p.is_finite();
        cloud.point_in_vehicle[i] = if hit { p } else { glam::Vec3::NAN };
        cloud.range_m[i] = if hit { p.length() } else { f32::NAN };
        cloud.intensity[i] = rec[3];
        cloud.ring[i] = points.rings.as_ref().map_or(0, |r| r[i]);
        cloud.column[i] = i as u32;
        cloud.sensor[i] = 0;
        cloud.label[i] = class;
        cloud.ground[i] = hit && class.is_ground();
    }
    cloud
}

/// Reads `path` as the file holds it, unordered: an organized PCD keeps its grid (`HEIGHT x WIDTH`,
/// its rows in the file's order), every other file is a `1 x N` grid in file order (a KITTI `.bin`
/// with its `.label` where there is one, a nuScenes file with its rings).
pub fn read_as_stored(path: &Path) -> Result<OrderedCloud, RecordingError> {
    read_as_stored_as(path, None).map(|(cloud, _)| cloud)
}

/// As [`read_as_stored`], a headerless `.bin` read in `choice` (`--layout`, `layout=`) where
/// given, else in the layout its name and bytes give ([`InputLayout::decide`]); also returns the
/// layout and what decided it.
pub fn read_as_stored_as(
    path: &Path,
    choice: Option<LayoutChoice>,
) -> Result<(OrderedCloud, (InputLayout, LayoutBasis)), RecordingError> {
    let by_name = InputLayout::of_file(path)?;
    if by_name.is_raw() {
        let bytes = std::fs::read(path).map_err(|e| sim::SimError::io(path, e))?;
        let decided = InputLayout::decide(path, &bytes, choice)?;
        let cloud = match decided.0 {
            InputLayout::NuscenesBin => sim::io::nuscenes::cloud_from_bytes(path, &bytes)?,
            _ => {
                let label = path.with_extension("label");
                let label_bytes = match label.is_file() {
                    true => Some(std::fs::read(&label).map_err(|e| sim::SimError::io(&label, e))?),
                    false => None,
                };
                sim::io::kitti::read_bytes(path, &bytes, label_bytes.as_deref().map(|b| (label.as_path(), b)))?
            }
        };
        return Ok((cloud, decided));
    }
    let decided = InputLayout::decide(path, &[], choice)?;
    let cloud = match by_name {
        InputLayout::Pcd => sim::io::pcd::read(path)?,
        InputLayout::Ply => sim::io::ply::read(path)?,
        InputLayout::Las => sim::io::las::read(path)?,
        _ => return Err(RecordingError::Unsupported { path: path.to_path_buf() }),
    };
    Ok((cloud, decided))
}

/// Orders an unorganized cloud `c` read from `path` (its points, intensity, labels, times, and its
/// rings where `has_ring`) into `cloud`.
/// Moves the points of `c`, a frame our writer stored in the vehicle frame (PLY, LAS), into the
/// frame of the rig's sensor, where its beam table orders them; ordering moves them back. Without
/// a rig the sensor's mount is not known: refused, saying so.
fn to_sensor_frame(path: &Path, c: &mut OrderedCloud, setup: &SensorSetup) -> Result<(), RecordingError> {
    if setup.recover || setup.calibrated_lasers.is_some() && setup.vehicle_from_sensor == glam::Affine3A::IDENTITY {
        return Err(RecordingError::Ordering {
            what: format!("`{}`", path.display()),
            error: crate::ClassifyError::Ordering(
                "written by groundtruth in the vehicle frame: give the scan's rig (`--rig`, the manifest's `rig`) \
                 so that its points can be moved into the sensor's frame, or classify the scan's PCD or KITTI files"
                    .into(),
            ),
        });
    }
    let sensor_from_vehicle = setup.vehicle_from_sensor.inverse();
    for p in c.point_in_vehicle.iter_mut().filter(|p| p.is_finite()) {
        *p = sensor_from_vehicle.transform_point3(*p);
    }
    Ok(())
}

fn order_flat_cloud(
    path: &Path,
    c: &OrderedCloud,
    has_ring: bool,
    setup: &SensorSetup,
    cloud: &mut CloudBuffer,
    report: &mut OrderingReport,
) -> Result<(), RecordingError> {
    let labels = c.label.iter().any(|l| l.0 != 0).then_some(c.label.as_slice());
    let rings = has_ring.then_some(c.ring.as_slice());
    let attributes = PointAttributes { intensity: Some(&c.intensity), labels, time_s: Some(&c.time_s), rings };
    setup
        .order_flat(&c.point_in_vehicle, &attributes, cloud, report)
        .map_err(|error| RecordingError::Ordering { what: format!("`{}`", path.display()), error })
}

/// What [`order_pcd`] did: the milliseconds of the read, whether the cloud came from another tool
/// (then the report holds what ordering did), and the NaN points of an unorganized cloud read as
/// no-returns.
struct PcdRead {
    read_ms: f64,
    from_another_tool: bool,
    nan_no_returns: usize,
}

/// Orders a parsed PCD `frame` into `cloud`: a driver's organized cloud has its rows put in order
/// as it is decoded; our own layout (or several echo planes) is taken as it is; an unorganized
/// cloud is ordered as a KITTI file is, or from its `ring` field, its NaN points read as
/// no-returns (`0, 0, 0`: decision 0, kept in place), as PCL and the drivers write them.
#[allow(clippy::too_many_arguments)]
fn order_pcd(
    path: &Path,
    frame: &PcdFrame<'_>,
    setup: &SensorSetup,
    file_cloud: &mut OrderedCloud,
    cloud: &mut CloudBuffer,
    report: &mut OrderingReport,
    t0: Instant,
) -> Result<PcdRead, RecordingError> {
    let (info, (rows, _, planes)) = (frame.info(), frame.shape());
    if info.organized && !info.ours && planes == 1 {
        // A driver's organized cloud: its rows are put in order as it is decoded, so `read_ms` is
        // the file's read and the header, the rest counts as ordering.
        let read_ms = t0.elapsed().as_secs_f64() * 1e3;
        if let Some(lasers) = setup.calibrated_lasers
            && lasers != rows
        {
            return Err(RecordingError::CalibrationRows { name: path.display().to_string(), rows, lasers });
        }
        read_organized_into(frame, setup.vehicle_from_sensor, cloud.cloud_mut(), report)
            .map_err(|error| RecordingError::Ordering { what: format!("the rows of `{}`", path.display()), error })?;
        return Ok(PcdRead { read_ms, from_another_tool: true, nan_no_returns: 0 });
    }
    let info = frame.read_into(file_cloud, None, Affine3A::IDENTITY)?;
    let read_ms = t0.elapsed().as_secs_f64() * 1e3;
    if info.ours || file_cloud.planes > 1 {
        std::mem::swap(cloud.cloud_mut(), file_cloud);
        return Ok(PcdRead { read_ms, from_another_tool: false, nan_no_returns: 0 });
    }
    // An unorganized PCD: its NaN points are no-returns; ordered as a KITTI file is.
    let nan_no_returns = nan_points_to_no_returns(file_cloud);
    order_flat_cloud(path, file_cloud, info.has_ring, setup, cloud, report)?;
    Ok(PcdRead { read_ms, from_another_tool: true, nan_no_returns })
}

/// Puts every point of `cloud` with a NaN or infinite coordinate at `0, 0, 0` (a no-return, which
/// ordering skips and counts as such); returns how many there were.
fn nan_points_to_no_returns(cloud: &mut OrderedCloud) -> usize {
    let mut count = 0;
    for p in &mut cloud.point_in_vehicle {
        if !p.is_finite() {
            *p = glam::Vec3::ZERO;
            count += 1;
        }
    }
    count
}
