//! `groundtruth classify`: classifies the ground points of scanned clouds (a scan directory with
//! its manifest, a directory of `.pcd` / `.bin` files, or one file) and writes one decision file per
//! frame, plus an outcome picture where the input carries labels.
//!
//! Output per frame, in `--out`: `frame_NNNNNN.ground`, one byte per point in the input's point
//! order, 1 = ground, 0 = not. For an organized PCD that is every cell of the grid in the file's
//! order (all echo planes), no-return cells included (always 0). An organized PCD of another tool
//! (no `# groundtruth` line: a ROS driver's, top-first or bottom-first, with or without `ring`, NaN
//! or zero no-returns) keeps its cells and has its rows put in elevation order first
//! ([`classifier::ordering::organized`]); a file whose way up cannot be told is refused. An
//! unorganized PCD, or a PLY, is ordered as a KITTI file is, or from its `ring` field where it has
//! one. Such files hold sensor-frame points (as the drivers
//! write them): `--rig` gives the mount that takes them to the vehicle frame (else they stay as
//! they are). For a KITTI `.bin` it is every point of
//! the file in file order; the points are first put into ring x column order ([`classifier::ordering`]):
//! by scan unfolding where the file is in scan order (as KITTI's and ours are), else from the beam
//! table of `--rig` (a single-sensor rig, with its origin offsets; default: the HDL-64E nominal
//! table with 2170 columns, as real KITTI frames hold up to about 2,160 points per laser). Every point gets a cell (a shared cell keeps its second point on a
//! further plane); only points with NaN or infinite coordinates are skipped (0, counted in the
//! output; a file with more than 1 % of them is refused). The path taken and the counts are printed.
//! Where the input has labels (PCD label field, KITTI `.label` beside the `.bin`), also
//! `frame_NNNNNN.png`: a bird's-eye view coloured by outcome (true ground, false ground, missed
//! ground, true non-ground).
//! Frames are classified in order; poses for `grid` / `grid-no-cluster` come from the manifest
//! (without one, each frame is its own map).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use classifier::FrameInput;
use classifier::ordering::{
    CloudBuffer, OrderingReport, PointAttributes, SensorSetup, decisions_per_point, read_organized_into,
};
use glam::{Affine3A, Mat4};
use sim::OrderedCloud;

use crate::input_bytes::InputBytes;

/// Arguments of `groundtruth classify`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Method name (see `groundtruth list`).
    #[arg(long)]
    method: String,
    /// A scan directory (with manifest.json), a directory of .pcd / .bin files, or one such file.
    #[arg(long)]
    input: PathBuf,
    /// Output directory (created).
    #[arg(long)]
    out: PathBuf,
    /// Rig whose beam table orders KITTI .bin input (single-sensor rigs).
    #[arg(long)]
    rig: Option<String>,
    /// The sensor's own calibration (per-laser elevations and offsets): our .toml or .txt, the
    /// velodyne driver's .yaml, Ouster's metadata .json (see `classifier::ordering::calibration`).
    #[arg(long)]
    calibration: Option<PathBuf>,
    /// Seed of randomized methods (RANSAC).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Trained model file for `mcdaniel` or `learned` (`groundtruth train`; default: the bundled
    /// model).
    #[arg(long)]
    model: Option<PathBuf>,
    /// With a bag (`.mcap` or a rosbag2 directory) as `--input`: the PointCloud2 topic to classify
    /// (missing or wrong: the bag's PointCloud2 topics are listed).
    #[arg(long)]
    topic: Option<String>,
}

struct InputFrame {
    index: usize,
    path: PathBuf,
    pose: Option<Affine3A>,
}

fn frame_index_from_name(path: &Path, fallback: usize) -> usize {
    path.file_stem()
        .and_then(|s| s.to_str())
        .and_then(|s| s.strip_prefix("frame_"))
        .and_then(|s| s.parse().ok())
        .unwrap_or(fallback)
}

fn list_inputs(input: &Path) -> anyhow::Result<Vec<InputFrame>> {
    if input.is_file() {
        return Ok(vec![InputFrame { index: frame_index_from_name(input, 0), path: input.to_path_buf(), pose: None }]);
    }
    if !input.is_dir() {
        bail!("input `{}` is neither a file nor a directory", input.display());
    }
    if input.join("manifest.json").is_file() {
        let m = sim::io::manifest::Manifest::read(input)?;
        return Ok(m
            .frames
            .iter()
            .map(|f| {
                let rows = f.world_from_vehicle;
                let mat = Mat4::from_cols_array_2d(&rows).transpose();
                InputFrame { index: f.index, path: input.join(&f.file), pose: Some(Affine3A::from_mat4(mat)) }
            })
            .collect());
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(input)
        .with_context(|| format!("reading directory `{}`", input.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("pcd" | "ply" | "bin")))
        .collect();
    files.sort();
    if files.is_empty() {
        bail!("no .pcd or .bin files in `{}`", input.display());
    }
    Ok(files
        .into_iter()
        .enumerate()
        .map(|(k, p)| InputFrame { index: frame_index_from_name(&p, k), path: p, pose: None })
        .collect())
}

/// The sensor setup that orders files from other tools (`--rig`, `--calibration`; see
/// [`classifier::ordering::SensorSetup`]), the rig given by name or file.
pub(crate) fn sensor_setup(rig: Option<&str>, calibration: Option<&Path>) -> anyhow::Result<SensorSetup> {
    let rig_value = rig.map(super::common::load_rig).transpose()?;
    SensorSetup::new(rig_value.as_ref(), calibration).with_context(|| match rig {
        Some(name) => format!("rig `{name}`"),
        None => "the sensor setup".to_string(),
    })
}

/// Reads and orders frames one after another, keeping its buffers (the file's bytes, its points,
/// the cloud and the ordering report) from frame to frame: a sequence of frames of one sensor
/// allocates nothing after the first (measured: a fresh 128 x 2,048 cloud cost more than its
/// filling, in page faults).
#[derive(Default)]
pub(crate) struct FrameReader {
    /// The file's bytes.
    bytes: InputBytes,
    /// A KITTI `.label`'s bytes.
    label_bytes: InputBytes,
    /// A KITTI file's records.
    flat: sim::io::kitti::KittiPoints,
    /// A PCD as the file holds it (ordered from here where it is not organized).
    file_cloud: OrderedCloud,
    /// The cloud to classify.
    cloud: CloudBuffer,
    /// What ordering did, for input from other tools.
    report: OrderingReport,
    /// Whether `report` belongs to the last frame (input from other tools).
    ordered: bool,
}

impl FrameReader {
    /// The last frame's cloud.
    pub fn cloud(&self) -> &OrderedCloud {
        self.cloud.cloud()
    }

    /// What ordering did with the last frame, for input from other tools (cell of every input
    /// point); `None` for our own files.
    pub fn report(&self) -> Option<&OrderingReport> {
        self.ordered.then_some(&self.report)
    }

    /// Reads `path` and orders it; returns the milliseconds spent reading the file (the rest is
    /// ordering; for a driver's organized PCD, decoded in order, only the file's read and the header).
    pub fn read(&mut self, path: &Path, setup: &SensorSetup) -> anyhow::Result<f64> {
        let t0 = std::time::Instant::now();
        self.ordered = false;
        match path.extension().and_then(|e| e.to_str()) {
            Some("pcd") => {
                let FrameReader { bytes, file_cloud, cloud, report, ordered, .. } = self;
                let bytes = bytes.load(path)?;
                let frame = sim::io::pcd::PcdFrame::parse(path, bytes)?;
                let (read_ms, from_another_tool) = order_pcd(path, &frame, setup, file_cloud, cloud, report, t0)?;
                *ordered = from_another_tool;
                Ok(read_ms)
            }
            Some("bin") => {
                let label = path.with_extension("label");
                let bytes = self.bytes.load(path)?;
                let label_bytes = match label.is_file() {
                    true => Some((label.as_path(), self.label_bytes.load(&label)?)),
                    false => None,
                };
                // The records are ordered where the file's bytes lie (no decoding copy) where
                // they can be; the points are decoded otherwise.
                let records = sim::io::kitti::records_or_points_into(path, bytes, label_bytes, &mut self.flat)?;
                let read_ms = t0.elapsed().as_secs_f64() * 1e3;
                let flat = &self.flat;
                let labels = flat.labels.as_deref();
                let ordered = match records {
                    // Scan-ordered, shuffled or organized (an Ouster image with zero no-returns).
                    Some(records) => setup.order_kitti(records, labels, &mut self.cloud, &mut self.report),
                    None => {
                        let records: Vec<[f32; 4]> =
                            flat.points.iter().zip(&flat.intensity).map(|(p, &i)| [p.x, p.y, p.z, i]).collect();
                        setup.order_kitti(&records, labels, &mut self.cloud, &mut self.report)
                    }
                };
                ordered.with_context(|| format!("ordering `{}`", path.display()))?;
                self.ordered = true;
                Ok(read_ms)
            }
            Some("ply") => {
                let (c, has_ring) = sim::io::ply::read_with_ring(path)?;
                let read_ms = t0.elapsed().as_secs_f64() * 1e3;
                let labels = c.label.iter().any(|l| l.0 != 0).then_some(c.label.as_slice());
                let rings = has_ring.then_some(c.ring.as_slice());
                let attributes =
                    PointAttributes { intensity: Some(&c.intensity), labels, time_s: Some(&c.time_s), rings };
                setup
                    .order_flat(&c.point_in_vehicle, &attributes, &mut self.cloud, &mut self.report)
                    .with_context(|| format!("ordering `{}`", path.display()))?;
                self.ordered = true;
                Ok(read_ms)
            }
            _ => bail!("`{}`: unsupported file type (expected .pcd, .ply or .bin)", path.display()),
        }
    }
}

impl FrameReader {
    /// Reads a PCD held in `bytes` (a bag's PointCloud2 as PCD bytes; `name` names it in errors)
    /// and orders it as [`FrameReader::read`] orders a `.pcd` file; returns the milliseconds of
    /// the parse.
    pub fn read_pcd_bytes(&mut self, name: &Path, bytes: &[u8], setup: &SensorSetup) -> anyhow::Result<f64> {
        let t0 = std::time::Instant::now();
        let frame = sim::io::pcd::PcdFrame::parse(name, bytes)?;
        let (read_ms, ordered) =
            order_pcd(name, &frame, setup, &mut self.file_cloud, &mut self.cloud, &mut self.report, t0)?;
        self.ordered = ordered;
        Ok(read_ms)
    }
}

/// Orders a parsed PCD `frame` into `cloud`: a driver's organized cloud has its rows put in order
/// as it is decoded; our own layout (or several echo planes) is taken as it is; an unorganized
/// cloud is ordered as a KITTI file is, or from its `ring` field. Returns the milliseconds of the
/// read (since `t0`) and whether the cloud came from another tool (then `report` holds what
/// ordering did).
#[allow(clippy::too_many_arguments)]
fn order_pcd(
    path: &Path,
    frame: &sim::io::pcd::PcdFrame<'_>,
    setup: &SensorSetup,
    file_cloud: &mut OrderedCloud,
    cloud: &mut CloudBuffer,
    report: &mut OrderingReport,
    t0: std::time::Instant,
) -> anyhow::Result<(f64, bool)> {
    let (info, (rows, _, planes)) = (frame.info(), frame.shape());
    if info.organized && !info.ours && planes == 1 {
        // A driver's organized cloud: its rows are put in order as it is decoded, so `read_ms` is
        // the file's read and the header, the rest counts as ordering.
        let read_ms = t0.elapsed().as_secs_f64() * 1e3;
        if let Some(n) = setup.calibrated_lasers
            && n != rows
        {
            bail!("`{}` has {rows} rows but the calibration file {n} lasers", path.display());
        }
        read_organized_into(frame, setup.vehicle_from_sensor, cloud.cloud_mut(), report)
            .with_context(|| format!("ordering the rows of `{}`", path.display()))?;
        return Ok((read_ms, true));
    }
    let info = frame.read_into(file_cloud, None, Affine3A::IDENTITY)?;
    let read_ms = t0.elapsed().as_secs_f64() * 1e3;
    if info.ours || file_cloud.planes > 1 {
        std::mem::swap(cloud.cloud_mut(), file_cloud);
        return Ok((read_ms, false));
    }
    // An unorganized PCD: ordered as a KITTI file is.
    let c = &*file_cloud;
    let labels = c.label.iter().any(|l| l.0 != 0).then_some(c.label.as_slice());
    let rings = info.has_ring.then_some(c.ring.as_slice());
    let attributes = PointAttributes { intensity: Some(&c.intensity), labels, time_s: Some(&c.time_s), rings };
    setup
        .order_flat(&c.point_in_vehicle, &attributes, cloud, report)
        .with_context(|| format!("ordering `{}`", path.display()))?;
    Ok((read_ms, true))
}

/// Runs `groundtruth classify`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut method = super::common::method(&args.method, args.seed, args.model.as_deref())?;
    if sim::io::ros2::is_bag(&args.input) {
        let setup = sensor_setup(args.rig.as_deref(), args.calibration.as_deref())?;
        return super::classify_bag::run(&args.input, args.topic.as_deref(), &args.out, &setup, method.as_mut());
    }
    if args.topic.is_some() {
        bail!("--topic applies to a bag (an .mcap file or a rosbag2 directory); `{}` is none", args.input.display());
    }
    let frames = list_inputs(&args.input)?;
    let setup = sensor_setup(args.rig.as_deref(), args.calibration.as_deref())?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating `{}`", args.out.display()))?;
    let mut reader = FrameReader::default();
    for f in &frames {
        reader.read(&f.path, &setup)?;
        let (cloud, report) = (reader.cloud(), reader.report());
        if let Some(r) = report {
            println!(
                "{}: ordered into {} x {} x {}: {}",
                f.path.display(),
                cloud.rows,
                cloud.cols,
                cloud.planes,
                r.summary()
            );
        }
        let ground = method
            .classify(&FrameInput { index: f.index, cloud, world_from_vehicle: f.pose })
            .with_context(|| format!("classifying `{}`", f.path.display()))?;
        let bytes: Vec<u8> = match report {
            None => ground.iter().map(|&g| u8::from(g)).collect(),
            Some(r) => decisions_per_point(r, &ground),
        };
        let stem = format!("frame_{:06}", f.index);
        sim::io::atomic::write_bytes_atomic(&args.out.join(format!("{stem}.ground")), &bytes)?;
        let labelled = cloud.label.iter().any(|l| l.0 != 0);
        if labelled {
            let coloring = sim::picture::Coloring::Outcome { predicted_ground: &ground };
            let img = sim::picture::render_bev(cloud, &coloring, &sim::picture::BevOptions::default())?;
            sim::picture::save_png(&args.out.join(format!("{stem}.png")), &img)?;
        }
        let ground_count = bytes.iter().filter(|&&b| b == 1).count();
        let skipped = report.map_or(0, |r| r.skipped);
        println!("{stem}: {} points, {ground_count} ground, {skipped} bad points skipped", bytes.len());
    }
    Ok(())
}
