//! `groundtruth classify`: classifies the ground points of scanned clouds (a scan directory with
//! its manifest, a directory of `.pcd` / `.ply` / `.las` / `.bin` / `.pcd.bin` files, one file, or a bag: see
//! [`super::classify_bag`]) and writes one decision file per frame, plus an outcome picture where
//! the input carries labels. Frames are read by [`classifier::recording`].
//!
//! Output per frame, in `--out`: `frame_NNNNNN.ground`, one byte per point in the input's point
//! order, 1 = ground, 0 = not. For an organized PCD that is every cell of the grid in the file's
//! order (all echo planes), no-return cells included (always 0). An organized PCD of another tool
//! (no `# groundtruth` line: a ROS driver's, top-first or bottom-first, with or without `ring`, NaN
//! or zero no-returns) keeps its cells and has its rows put in elevation order first
//! ([`classifier::ordering::organized`]); a file whose way up cannot be told is refused. An
//! unorganized PCD, or a PLY or LAS, is ordered as a KITTI file is, or from its `ring` field where it has
//! one. Such files hold sensor-frame points (as the drivers
//! write them): `--rig` gives the mount that takes them to the vehicle frame (else they stay as
//! they are). For a KITTI `.bin` it is every point of
//! the file in file order; the points are first put into ring x column order ([`classifier::ordering`]):
//! by scan unfolding where the file is in scan order (as KITTI's and ours are), else from the beam
//! table of `--rig` (a single-sensor rig, with its origin offsets). Without `--rig` or
//! `--calibration` the sensor's rings and columns are recovered from the file (ring-major or
//! firing order, single or dual returns) and the sensor is named where its elevations match a
//! known table (`matched: hdl32e` in the printed summary; a real KITTI frame matches the HDL-64E
//! and keeps the nominal table with 2170 columns), else ordered as an unnamed sensor; a file in
//! neither order is refused ([`classifier::ordering::recover`]). Every point gets a cell (a shared cell keeps its second point on a
//! further plane); only points with NaN or infinite coordinates are skipped (0, counted in the
//! output; a file with more than 1 % of them is refused). The path taken and the counts are printed.
//! A nuScenes `.pcd.bin` (x y z intensity ring per point) is ordered from its ring field; a `.bin`
//! whose bytes are nuScenes records (their length, or a whole ring number as every point's fifth
//! value) is read as one, and `--layout kitti|nuscenes` names the layout outright; for those, a line
//! says which layout and why (`by its name`, `by its content`, `by --layout`). NaN points of an
//! unorganized PCD or PointCloud2 are no-returns (decision 0), not bad points.
//! Where the input has labels (PCD label field, KITTI `.label` beside the `.bin`), also
//! `frame_NNNNNN.png`: a bird's-eye view coloured by outcome (true ground, false ground, missed
//! ground, true non-ground).
//! Frames are classified in order; poses for `grid` / `grid-no-cluster` come from the manifest
//! (without one, each frame is its own map).

use std::path::PathBuf;

use anyhow::Context;
use classifier::FrameInput;
use classifier::recording::{self, Ordering, Recording};

/// Arguments of `groundtruth classify`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Method name (see `groundtruth list`).
    #[arg(long)]
    method: String,
    /// A scan directory (with manifest.json), a directory of .pcd / .ply / .las / .bin files, one
    /// such file, or a ROS 2 bag (an .mcap file or a rosbag2 directory).
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
    /// The records of headerless `.bin` files (default: by name, `.pcd.bin` = nuScenes, and by
    /// content, a `.bin` whose bytes are nuScenes records is read as one; the choice is printed).
    #[arg(long, value_enum)]
    layout: Option<super::common::LayoutArg>,
    /// With a bag (`.mcap` or a rosbag2 directory) as `--input`: the PointCloud2 topic to classify
    /// (default: the bag's one PointCloud2 topic; with several, or a wrong one, they are listed).
    #[arg(long)]
    topic: Option<String>,
}

/// Runs `groundtruth classify`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut method = super::common::method(&args.method, args.seed, args.model.as_deref())?;
    let recording = Recording::open(&args.input, args.topic.as_deref())?.with_layout(args.layout.map(Into::into))?;
    let setup = recording::sensor_setup(args.rig.as_deref(), args.calibration.as_deref())?;
    if recording.topic().is_some() {
        return super::classify_bag::run(&recording, &args.out, &setup, method.as_mut());
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating `{}`", args.out.display()))?;
    let mut frames = recording.frames(Ordering::Ordered(&setup))?;
    while let Some(frame) = frames.next_frame() {
        let f = frame?;
        let (cloud, report, path) = (f.cloud, f.report, &f.provenance.file);
        if let Some(line) = super::common::layout_line(f.provenance) {
            println!("{line}");
        }
        if let Some(r) = report {
            println!("{}: {}", path.display(), r.grid_line(cloud.rows, cloud.cols, cloud.planes));
        }
        let ground = method
            .classify(&FrameInput { index: f.index, cloud, world_from_vehicle: f.world_from_vehicle })
            .with_context(|| format!("classifying `{}`", path.display()))?;
        let bytes = f.decisions_per_point(&ground);
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
    for w in frames.warnings() {
        eprintln!("{w}");
    }
    Ok(())
}
