//! `groundtruth eval`: scans a scene with a rig, classifies every frame with each method and prints
//! one row per method (`acc FPR precision recall F1 IoU`, pooled over all returns of all frames),
//! like Table I of Nitsch et al. With `--json FILE` the same numbers are written atomically as
//! `{"methods": {NAME: {"acc", "fpr", "precision", "recall", "f1", "iou"}}}`; `--details` also
//! prints the per-frame means and the breakdown by class and range band.
//!
//! `--paper mcdaniel` runs McDaniel et al.'s own evaluation instead ([`super::eval_paper`]);
//! `--dataset DIR` scores methods on a labelled recording in the SemanticKITTI layout
//! ([`super::eval_dataset`]).

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::Context;
use classifier::metrics::range_band_name;
use classifier::{Evaluation, FrameInput, Scores};
use sim::scan::ScanConfig;

/// The methods of Table I, `eval`'s default on a scene.
const TABLE_METHODS: &str = "nitsch,nitsch-0.7,nitsch-no-cluster,nitsch-no-cluster-0.7,ransac,grid,grid-no-cluster";

/// `eval --dataset`'s default methods.
const DATASET_METHODS: &str = "nitsch";

/// Arguments of `groundtruth eval`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene name or TOML file.
    #[arg(long, required_unless_present_any = ["paper", "dataset"], conflicts_with = "dataset")]
    scene: Option<String>,
    /// Rig name or TOML file (with `--dataset`: the rig whose beam table and mount order the
    /// frames, as `classify --rig`).
    #[arg(long, required_unless_present_any = ["paper", "dataset"])]
    rig: Option<String>,
    /// Run a paper's own evaluation instead (`mcdaniel`: Tables I-III and the ROC figure of seed 002).
    #[arg(long, conflicts_with_all = ["scene", "rig", "methods", "frames", "speed", "details", "dataset"])]
    paper: Option<String>,
    /// Score methods on a labelled recording in the SemanticKITTI layout
    /// (`DIR/sequences/NN/{velodyne,labels}` or one sequence's folder), real or ours.
    #[arg(long, conflicts_with_all = ["frames", "speed", "ideal"])]
    dataset: Option<PathBuf>,
    /// With `--dataset`: only these sequences (comma-separated folder names).
    #[arg(long, requires = "dataset")]
    sequences: Option<String>,
    /// With `--dataset`: the sensor's own calibration file (as `classify --calibration`).
    #[arg(long, requires = "dataset")]
    calibration: Option<PathBuf>,
    /// With `--dataset`: the protocol (`semantickitti`, `patchworkpp`, `patchwork`).
    #[arg(long, default_value = "semantickitti", requires = "dataset")]
    protocol: String,
    /// With `--dataset`: ground class ids replacing the protocol's (comma-separated SemanticKITTI ids).
    #[arg(long, requires = "dataset")]
    ground: Option<String>,
    /// With `--dataset --protocol patchwork`: the sensor's height above the ground, metres.
    #[arg(long, default_value_t = 1.73, requires = "dataset")]
    sensor_height: f32,
    /// With `--dataset BAG` (an `.mcap` or rosbag2 directory): the PointCloud2 topic (its clouds
    /// carry a `label` field).
    #[arg(long, requires = "dataset")]
    topic: Option<String>,
    /// With `--dataset`: score at most this many frames per sequence.
    #[arg(long, requires = "dataset")]
    max_frames: Option<usize>,
    /// Output directory: `--paper`'s figures (default `out/paper-mcdaniel`), `--dataset`'s outcome
    /// pictures (none by default).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Comma-separated method names (see `groundtruth list`; default: the Table I set, with
    /// `--dataset` `nitsch`).
    #[arg(long)]
    methods: Option<String>,
    /// Number of frames to scan.
    #[arg(long, default_value_t = 5)]
    frames: usize,
    /// Seed of the scene, the scan noise and RANSAC.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Ego speed, metres per second.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    speed: f32,
    /// Turn measurement effects off.
    #[arg(long)]
    ideal: bool,
    /// Write the scores to this JSON file.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Also print per-frame means and the breakdown by class and range band.
    #[arg(long)]
    details: bool,
    /// Trained model file for `mcdaniel` or `learned` (`groundtruth train`; default: the bundled
    /// model), given to the methods of --methods that take one.
    #[arg(long, conflicts_with = "paper")]
    model: Option<PathBuf>,
}

/// Runs `groundtruth eval`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if let Some(paper) = &args.paper {
        if paper != "mcdaniel" {
            anyhow::bail!("--paper `{paper}`: known papers: mcdaniel");
        }
        let paper_args = super::eval_paper::PaperArgs {
            seed: args.seed,
            ideal: args.ideal,
            out: args.out.clone().unwrap_or_else(|| PathBuf::from("out/paper-mcdaniel")),
            json: args.json.clone(),
        };
        return super::eval_paper::run(&paper_args);
    }
    if let Some(dir) = &args.dataset {
        let methods = super::common::split_list(args.methods.as_deref().unwrap_or(DATASET_METHODS));
        return super::eval_dataset::run(&super::eval_dataset::DatasetArgs {
            dir,
            sequences: args.sequences.as_deref().map(super::common::split_list),
            methods,
            rig: args.rig.as_deref(),
            calibration: args.calibration.as_deref(),
            protocol: &args.protocol,
            ground: args.ground.as_deref(),
            sensor_height_m: args.sensor_height,
            max_frames: args.max_frames,
            json: args.json.as_deref(),
            out: args.out.as_deref(),
            model: args.model.as_deref(),
            details: args.details,
            topic: args.topic.as_deref(),
        });
    }
    if args.out.is_some() {
        anyhow::bail!("--out applies to --paper and --dataset");
    }
    let (Some(scene_name), Some(rig_name)) = (&args.scene, &args.rig) else {
        anyhow::bail!("--scene and --rig are required (or --paper mcdaniel)");
    };
    let names = super::common::split_list(args.methods.as_deref().unwrap_or(TABLE_METHODS));
    if names.is_empty() {
        anyhow::bail!("--methods is empty; known: {}", classifier::METHODS.join(", "));
    }
    if let Some(model) = &args.model
        && !names.iter().any(|n| super::common::takes_model(n))
    {
        anyhow::bail!(
            "--model `{}` applies to `mcdaniel` and `learned`, which --methods does not name",
            model.display()
        );
    }
    // Refuse unknown names before scanning.
    for n in &names {
        super::common::method(n, args.seed, args.model.as_deref().filter(|_| super::common::takes_model(n)))?;
    }
    let scene = super::common::load_scene_full(scene_name, args.seed)?;
    let rig = super::common::load_rig(rig_name)?;
    let config = ScanConfig {
        seed: args.seed,
        frames: args.frames,
        speed_m_per_s: args.speed,
        ideal: args.ideal,
        ego_z_m: scene.ego_ground_z_m,
        ..Default::default()
    };
    let frames = sim::scan::scan(&scene.mesh, &rig, &config).context("scanning")?;
    println!("scene {scene_name} rig {rig_name} frames {} seed {}", frames.len(), args.seed);
    println!("{:<24} {:>7} {:>7} {:>9} {:>7} {:>7} {:>7}", "method", "acc", "FPR", "precision", "recall", "F1", "IoU");
    let mut json: BTreeMap<String, Scores> = BTreeMap::new();
    for name in &names {
        let mut method =
            super::common::method(name, args.seed, args.model.as_deref().filter(|_| super::common::takes_model(name)))?;
        let mut eval = Evaluation::default();
        for f in &frames {
            let input = FrameInput { index: f.index, cloud: &f.cloud, world_from_vehicle: Some(f.world_from_vehicle) };
            let ground = method.classify(&input).with_context(|| format!("{name}: frame {}", f.index))?;
            eval.add_frame(&f.cloud, &ground);
        }
        let s = eval.pooled.scores();
        println!(
            "{:<24} {:>7.4} {:>7.4} {:>9.4} {:>7.4} {:>7.4} {:>7.4}",
            name, s.acc, s.fpr, s.precision, s.recall, s.f1, s.iou
        );
        if args.details {
            let m = eval.per_frame_mean();
            println!(
                "  per-frame mean           {:>7.4} {:>7.4} {:>9.4} {:>7.4} {:>7.4} {:>7.4}",
                m.acc, m.fpr, m.precision, m.recall, m.f1, m.iou
            );
            for (id, c) in &eval.by_class {
                let called = c.tp + c.fp;
                println!(
                    "  class {:<18} points {:>8} called ground {:>8}",
                    Evaluation::class_name(*id),
                    c.total(),
                    called
                );
            }
            for (b, c) in eval.by_range.iter().enumerate() {
                let s = c.scores();
                println!(
                    "  range {:<10} points {:>8} acc {:.4} FPR {:.4} F1 {:.4}",
                    range_band_name(b),
                    c.total(),
                    s.acc,
                    s.fpr,
                    s.f1
                );
            }
        }
        json.insert(name.clone(), s);
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&serde_json::json!({ "methods": json }))?;
        sim::io::atomic::write_bytes_atomic(path, text.as_bytes())?;
    }
    Ok(())
}
