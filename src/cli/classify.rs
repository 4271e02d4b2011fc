//! `groundtruth classify`: classifies the ground points of scanned clouds (a scan directory with
//! its manifest, a directory of `.pcd` / `.bin` files, or one file) and writes one decision file per
//! frame, plus an outcome picture where the input carries labels.
//!
//! Output per frame, in `--out`: `frame_NNNNNN.ground`, one byte per point in the input's point
//! order, 1 = ground, 0 = not. For an organized PCD that is every cell of the grid in grid order
//! (all echo planes), no-return cells included (always 0). For a KITTI `.bin` it is every point of
//! the file in file order; the points are first put into ring x column order ([`classifier::ordering`])
//! from the beam table of `--rig` (a single-sensor rig; default: the HDL-64E table with 2083
//! columns), and points that ordering drops (a second point in a taken cell) are 0.
//! Where the input has labels (PCD label field, KITTI `.label` beside the `.bin`), also
//! `frame_NNNNNN.png`: a bird's-eye view coloured by outcome (true ground, false ground, missed
//! ground, true non-ground).
//! Frames are classified in order; poses for `grid` / `grid-no-cluster` come from the manifest
//! (without one, each frame is its own map).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use classifier::ordering::{BeamTable, order_points};
use classifier::{FrameInput, method_by_name};
use glam::{Affine3A, Mat4};
use sim::OrderedCloud;

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
    /// Seed of randomized methods (RANSAC).
    #[arg(long, default_value_t = 0)]
    seed: u64,
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
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("pcd" | "bin")))
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

/// The beam table of a single-sensor rig, with its mount.
fn rig_table(name: &str) -> anyhow::Result<(BeamTable, Affine3A)> {
    let rig = super::common::load_rig(name)?;
    if rig.sensors.len() != 1 {
        bail!("rig `{name}` has {} sensors; ordering a KITTI file needs a single-sensor rig", rig.sensors.len());
    }
    let s = &rig.sensors[0];
    let pattern = s.spec.pattern();
    let az = &pattern.col_azimuth_rad;
    if az.len() < 2 {
        bail!("rig `{name}`: the sensor has fewer than 2 columns");
    }
    let step = (az[0] - az[az.len() - 1]) / (az.len() - 1) as f32;
    let full_turn = (step * az.len() as f32 - std::f32::consts::TAU).abs() < 1.5 * step;
    let table = BeamTable {
        elevations_rad: pattern.row_elevation_rad.clone(),
        cols: pattern.cols,
        azimuth_left_rad: az[0],
        azimuth_step_rad: step,
        full_turn,
    };
    // KITTI files of a single-sensor rig hold sensor-frame points.
    Ok((table, s.mount.vehicle_from_sensor()))
}

/// Reads a frame: the cloud to classify and, for KITTI, the cell of each input point.
fn read_frame(path: &Path, rig: Option<&str>) -> anyhow::Result<(OrderedCloud, Option<Vec<Option<u32>>>)> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("pcd") => Ok((sim::io::pcd::read(path)?, None)),
        Some("bin") => {
            let label = path.with_extension("label");
            let flat = sim::io::kitti::read(path, label.is_file().then_some(label.as_path()))?;
            let (table, vehicle_from_sensor) = match rig {
                Some(r) => rig_table(r)?,
                None => (BeamTable::hdl64e(2083), Affine3A::IDENTITY),
            };
            let labels = label.is_file().then_some(flat.label.as_slice());
            let (cloud, report) = order_points(&flat.point_in_vehicle, labels, &table, vehicle_from_sensor)
                .with_context(|| format!("ordering `{}`", path.display()))?;
            println!(
                "{}: ordered {} of {} points into {} x {} ({} cell collisions, {} outside the beam table)",
                path.display(),
                report.placed,
                report.cell_of_point.len(),
                cloud.rows,
                cloud.cols,
                report.collisions,
                report.outside
            );
            Ok((cloud, Some(report.cell_of_point)))
        }
        _ => bail!("`{}`: unsupported file type (expected .pcd or .bin)", path.display()),
    }
}

/// Runs `groundtruth classify`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut method = method_by_name(&args.method, args.seed)?;
    let frames = list_inputs(&args.input)?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating `{}`", args.out.display()))?;
    for f in &frames {
        let (cloud, cell_of_point) = read_frame(&f.path, args.rig.as_deref())?;
        let ground = method
            .classify(&FrameInput { index: f.index, cloud: &cloud, world_from_vehicle: f.pose })
            .with_context(|| format!("classifying `{}`", f.path.display()))?;
        let bytes: Vec<u8> = match &cell_of_point {
            None => ground.iter().map(|&g| u8::from(g)).collect(),
            Some(cells) => cells.iter().map(|c| c.map_or(0, |c| u8::from(ground[c as usize]))).collect(),
        };
        let stem = format!("frame_{:06}", f.index);
        sim::io::atomic::write_bytes_atomic(&args.out.join(format!("{stem}.ground")), &bytes)?;
        let labelled = cloud.label.iter().any(|l| l.0 != 0);
        if labelled {
            let coloring = sim::picture::Coloring::Outcome { predicted_ground: &ground };
            let img = sim::picture::render_bev(&cloud, &coloring, &sim::picture::BevOptions::default())?;
            sim::picture::save_png(&args.out.join(format!("{stem}.png")), &img)?;
        }
        let ground_count = bytes.iter().filter(|&&b| b == 1).count();
        println!("{stem}: {} points, {ground_count} ground", bytes.len());
    }
    Ok(())
}
