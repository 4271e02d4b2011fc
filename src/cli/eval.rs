//! `groundtruth eval`, one mode per invocation:
//!
//! - `eval scene --scene S --rig R`: scans a scene with a rig, classifies every frame with each
//!   method and prints one row per method (`acc FPR precision recall F1 IoU`, pooled over all
//!   returns of all frames), like Table I of Nitsch et al. With `--json FILE` the same numbers are
//!   written atomically as `{"methods": {NAME: {"acc", "fpr", "precision", "recall", "f1", "iou"}}}`;
//!   `--details` also prints the per-frame means and the breakdown by class and range band.
//! - `eval dataset --input DIR`: scores methods on a labelled recording ([`super::eval_dataset`]).
//! - `eval paper mcdaniel`: McDaniel et al.'s own evaluation ([`super::eval_paper`]).
//!
//! The flat spellings of the previous release (`eval --scene`, `eval --dataset DIR`, `eval --paper
//! mcdaniel`) are still read, with a deprecation message on stderr.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::Context;
use classifier::metrics::range_band_name;
use classifier::{Evaluation, FrameInput, Scores};

/// The methods of Table I, `eval`'s default on a scene.
const TABLE_METHODS: &str = "nitsch,nitsch-0.7,nitsch-no-cluster,nitsch-no-cluster-0.7,ransac,grid,grid-no-cluster";

/// `eval --dataset`'s default methods.
const DATASET_METHODS: &str = "nitsch";

/// Arguments of `groundtruth eval`: one mode per invocation (`eval scene`, `eval dataset`,
/// `eval paper`), so a flag of another mode is a usage error. The flat spellings of earlier
/// releases (`eval --scene`, `eval --dataset DIR`, `eval --paper mcdaniel`) still work for one
/// release, with a deprecation message.
#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    mode: Option<Mode>,
    #[command(flatten)]
    legacy: LegacyArgs,
}

/// `eval`'s modes.
#[derive(clap::Subcommand, Debug)]
enum Mode {
    /// Scan a scene with a rig and score methods on every return (Table I of Nitsch et al.).
    Scene(SceneArgs),
    /// Score methods on a labelled recording (SemanticKITTI layout, real or ours, or a bag).
    Dataset(DatasetModeArgs),
    /// A paper's own evaluation (`mcdaniel`: Tables I-III and the ROC figure of seed 002).
    Paper(PaperModeArgs),
}

/// `groundtruth eval scene`.
#[derive(clap::Args, Debug)]
struct SceneArgs {
    /// Scene name or TOML file.
    #[arg(long)]
    scene: String,
    /// Rig name or TOML file.
    #[arg(long)]
    rig: String,
    /// Comma-separated method names (see `groundtruth list`; default: the Table I set).
    #[arg(long, default_value = TABLE_METHODS)]
    methods: String,
    /// Number of frames to scan.
    #[arg(long, default_value_t = 5)]
    frames: usize,
    /// Seed of the scene, the scan noise and RANSAC.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Ego speed, metres per second.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    speed_m_per_s: f32,
    /// Turn measurement effects off.
    #[arg(long)]
    ideal: bool,
    /// Weather per beam: `clear`, `fog:visibility_m=V`, `rain:rate_mm_h=R` or `snow:rate_mm_h=R`
    /// (default: the scene file's `[weather]`, else none; docs/weather.md). Particles are never
    /// ground: a method that calls them ground loses precision.
    #[arg(long)]
    weather: Option<String>,
    /// Snow lying on the ground, metres (`0 < depth <= 1`; labelled terrain, i.e. ground).
    #[arg(long)]
    snow_cover_m: Option<f64>,
    #[command(flatten)]
    report: ReportArgs,
}

/// What `eval scene` and `eval dataset` both take: where the scores go, how much is printed, and
/// the model of the methods that take one.
#[derive(clap::Args, Debug)]
struct ReportArgs {
    /// Write the scores to this JSON file (atomically; `eval dataset`: per frame too).
    #[arg(long)]
    json: Option<PathBuf>,
    /// Also print the details: per-frame means and the breakdown by class and range band (`eval
    /// dataset`: a line per frame).
    #[arg(long)]
    details: bool,
    /// Trained model file for `mcdaniel` or `learned` (`groundtruth train`; default: the bundled
    /// model), given to the methods of --methods that take one.
    #[arg(long)]
    model: Option<PathBuf>,
}

/// `groundtruth eval dataset`.
#[derive(clap::Args, Debug)]
struct DatasetModeArgs {
    /// The labelled recording: `DIR/sequences/NN/{velodyne,labels}`, one sequence's folder, a
    /// nuScenes-lidarseg folder (`lidar/NAME.pcd.bin` with `lidarseg/NAME_lidarseg.bin`), or a bag
    /// (`.mcap` or rosbag2 directory) whose clouds carry a `label` field.
    #[arg(long)]
    input: PathBuf,
    /// Comma-separated method names (see `groundtruth list`).
    #[arg(long, default_value = DATASET_METHODS)]
    methods: String,
    /// Only these sequences (comma-separated folder names).
    #[arg(long)]
    sequences: Option<String>,
    /// The rig whose beam table and mount order the frames (as `classify --rig`).
    #[arg(long)]
    rig: Option<String>,
    /// The sensor's own calibration file (as `classify --calibration`).
    #[arg(long)]
    calibration: Option<PathBuf>,
    /// The protocol (`semantickitti`, `patchworkpp`, `patchwork`).
    #[arg(long, default_value = "semantickitti")]
    protocol: String,
    /// Ground class ids replacing the protocol's (comma-separated SemanticKITTI ids, or WADS's 110
    /// and 111).
    #[arg(long)]
    ground: Option<String>,
    /// Class ids left out of the scores beside the protocol's (comma-separated; e.g. 110, WADS's
    /// falling snow).
    #[arg(long)]
    ignore: Option<String>,
    /// With `--protocol patchwork`: the sensor's height above the ground, metres.
    #[arg(long, default_value_t = 1.73)]
    sensor_height_m: f32,
    /// With a bag: the PointCloud2 topic.
    #[arg(long)]
    topic: Option<String>,
    /// The records of the dataset's `.bin` files (default: by name and content: a `.bin` holding
    /// nuScenes records is read as one, and a line says so).
    #[arg(long, value_enum)]
    layout: Option<super::common::LayoutArg>,
    /// Score at most this many frames per sequence.
    #[arg(long)]
    max_frames: Option<usize>,
    /// Draw each frame's outcome per method into this folder (none by default).
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    report: ReportArgs,
}

/// The papers whose own evaluation `eval paper` runs.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum Paper {
    /// McDaniel et al., forests: Tables I-III and the ROC figure.
    Mcdaniel,
}

/// `groundtruth eval paper`.
#[derive(clap::Args, Debug)]
struct PaperModeArgs {
    /// Which paper.
    paper: Paper,
    /// Seed of the scenes and the scan noise.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Turn measurement effects off.
    #[arg(long)]
    ideal: bool,
    /// Where the figures go.
    #[arg(long, default_value = "out/paper-mcdaniel")]
    out: PathBuf,
    /// Write every number to this JSON file.
    #[arg(long)]
    json: Option<PathBuf>,
}

/// The flat spellings of earlier releases (`eval --scene`, `--dataset`, `--paper`), hidden from the
/// help and turned into a mode with a deprecation message.
#[derive(clap::Args, Debug)]
struct LegacyArgs {
    #[arg(long, hide = true, required_unless_present_any = ["paper", "dataset"], conflicts_with = "dataset")]
    scene: Option<String>,
    #[arg(long, hide = true, required_unless_present_any = ["paper", "dataset"])]
    rig: Option<String>,
    #[arg(long, hide = true, conflicts_with_all = ["scene", "rig", "methods", "frames", "speed", "details", "dataset"])]
    paper: Option<String>,
    #[arg(long, hide = true, conflicts_with_all = ["frames", "speed", "ideal"])]
    dataset: Option<PathBuf>,
    #[arg(long, hide = true, requires = "dataset")]
    sequences: Option<String>,
    #[arg(long, hide = true, requires = "dataset")]
    calibration: Option<PathBuf>,
    #[arg(long, hide = true, default_value = "semantickitti", requires = "dataset")]
    protocol: String,
    #[arg(long, hide = true, requires = "dataset")]
    ground: Option<String>,
    #[arg(long, hide = true, default_value_t = 1.73, requires = "dataset")]
    sensor_height: f32,
    #[arg(long, hide = true, requires = "dataset")]
    topic: Option<String>,
    #[arg(long, hide = true, requires = "dataset")]
    max_frames: Option<usize>,
    #[arg(long, hide = true)]
    out: Option<PathBuf>,
    #[arg(long, hide = true)]
    methods: Option<String>,
    #[arg(long, hide = true, default_value_t = 5)]
    frames: usize,
    #[arg(long, hide = true, default_value_t = 0)]
    seed: u64,
    #[arg(long, hide = true, default_value_t = 10.0, allow_negative_numbers = true)]
    speed: f32,
    #[arg(long, hide = true)]
    ideal: bool,
    #[arg(long, hide = true)]
    json: Option<PathBuf>,
    #[arg(long, hide = true)]
    details: bool,
    #[arg(long, hide = true, conflicts_with = "paper")]
    model: Option<PathBuf>,
}

impl LegacyArgs {
    /// The mode the flat spelling asks for, with the deprecation message printed; the checks of the
    /// earlier release (flags that apply to another mode) are kept.
    fn into_mode(self) -> anyhow::Result<Mode> {
        let deprecated = |old: &str, new: &str| {
            eprintln!(
                "warning: `groundtruth eval {old}` is deprecated and will be removed in the next release; use `groundtruth eval {new}`"
            );
        };
        if let Some(paper) = self.paper {
            deprecated("--paper NAME", "paper NAME");
            let paper = match paper.as_str() {
                "mcdaniel" => Paper::Mcdaniel,
                other => anyhow::bail!("--paper `{other}`: known papers: mcdaniel"),
            };
            let out = self.out.unwrap_or_else(|| PathBuf::from("out/paper-mcdaniel"));
            return Ok(Mode::Paper(PaperModeArgs { paper, seed: self.seed, ideal: self.ideal, out, json: self.json }));
        }
        if let Some(input) = self.dataset {
            deprecated("--dataset DIR", "dataset --input DIR");
            return Ok(Mode::Dataset(DatasetModeArgs {
                input,
                methods: self.methods.unwrap_or_else(|| DATASET_METHODS.to_string()),
                sequences: self.sequences,
                rig: self.rig,
                calibration: self.calibration,
                protocol: self.protocol,
                ground: self.ground,
                ignore: None,
                sensor_height_m: self.sensor_height,
                topic: self.topic,
                layout: None,
                max_frames: self.max_frames,
                out: self.out,
                report: ReportArgs { json: self.json, details: self.details, model: self.model },
            }));
        }
        deprecated("--scene S --rig R", "scene --scene S --rig R");
        if self.out.is_some() {
            anyhow::bail!("--out applies to --paper and --dataset");
        }
        let (Some(scene), Some(rig)) = (self.scene, self.rig) else {
            anyhow::bail!("--scene and --rig are required (or --paper mcdaniel)");
        };
        Ok(Mode::Scene(SceneArgs {
            scene,
            rig,
            methods: self.methods.unwrap_or_else(|| TABLE_METHODS.to_string()),
            frames: self.frames,
            seed: self.seed,
            speed_m_per_s: self.speed,
            ideal: self.ideal,
            weather: None,
            snow_cover_m: None,
            report: ReportArgs { json: self.json, details: self.details, model: self.model },
        }))
    }
}

/// Runs `groundtruth eval`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mode = match args.mode {
        Some(mode) => mode,
        None => args.legacy.into_mode()?,
    };
    match mode {
        Mode::Scene(a) => run_scene(&a),
        Mode::Dataset(a) => super::eval_dataset::run(&super::eval_dataset::DatasetArgs {
            dir: &a.input,
            sequences: a.sequences.as_deref().map(super::common::split_list),
            methods: super::common::split_list(&a.methods),
            rig: a.rig.as_deref(),
            calibration: a.calibration.as_deref(),
            protocol: &a.protocol,
            ground: a.ground.as_deref(),
            ignore: a.ignore.as_deref(),
            sensor_height_m: a.sensor_height_m,
            max_frames: a.max_frames,
            json: a.report.json.as_deref(),
            out: a.out.as_deref(),
            model: a.report.model.as_deref(),
            details: a.report.details,
            topic: a.topic.as_deref(),
            layout: a.layout.map(Into::into),
        }),
        Mode::Paper(a) => {
            let Paper::Mcdaniel = a.paper;
            super::eval_paper::run(&super::eval_paper::PaperArgs {
                seed: a.seed,
                ideal: a.ideal,
                out: a.out,
                json: a.json,
            })
        }
    }
}

/// Runs `groundtruth eval scene`.
fn run_scene(args: &SceneArgs) -> anyhow::Result<()> {
    let (scene_name, rig_name) = (&args.scene, &args.rig);
    let names = super::common::split_list(&args.methods);
    if names.is_empty() {
        anyhow::bail!("--methods is empty; known: {}", classifier::METHODS.join(", "));
    }
    if let Some(model) = &args.report.model
        && !names.iter().any(|n| super::common::takes_model(n))
    {
        anyhow::bail!(
            "--model `{}` applies to `mcdaniel` and `learned`, which --methods does not name",
            model.display()
        );
    }
    // Refuse unknown names before scanning.
    for n in &names {
        super::common::method(n, args.seed, args.report.model.as_deref().filter(|_| super::common::takes_model(n)))?;
    }
    let frames = super::common::scan_spec(&groundtruth_scenario::ScanSpec {
        scene: scene_name.clone(),
        rig: rig_name.clone(),
        seed: args.seed,
        frames: args.frames as u64,
        speed_m_per_s: f64::from(args.speed_m_per_s),
        ideal: args.ideal,
        weather: args.weather.as_deref().map(sim::effects::weather::Weather::parse).transpose().context("--weather")?,
        snow_cover_m: args.snow_cover_m,
        ..Default::default()
    })?;
    let weather = args.weather.as_deref().map(|w| format!(" weather {w}")).unwrap_or_default();
    println!("scene {scene_name} rig {rig_name} frames {} seed {}{weather}", frames.len(), args.seed);
    println!("{:<24} {:>7} {:>7} {:>9} {:>7} {:>7} {:>7}", "method", "acc", "FPR", "precision", "recall", "F1", "IoU");
    let mut json: BTreeMap<String, Scores> = BTreeMap::new();
    for name in &names {
        let mut method = super::common::method(
            name,
            args.seed,
            args.report.model.as_deref().filter(|_| super::common::takes_model(name)),
        )?;
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
        if args.report.details {
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
    if let Some(path) = &args.report.json {
        let text = serde_json::to_string_pretty(&serde_json::json!({ "methods": json }))?;
        sim::io::atomic::write_bytes_atomic(path, text.as_bytes())?;
    }
    Ok(())
}
