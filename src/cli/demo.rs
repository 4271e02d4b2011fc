//! `groundtruth demo`: the main job on a built-in default. Scans a scene with a rig (files in every
//! format), reads the clouds back, classifies ground with each method asked for (`learned` and
//! `nitsch` by default: the most accurate method beside the paper's), scores them against the
//! ground truth and draws the pictures a user looks at first.

use std::path::PathBuf;

use anyhow::Context;
use classifier::{Evaluation, FrameInput, method_by_name};
use sim::io::manifest::affine_from_rows;
use sim::picture::{BevOptions, Coloring, render_bev, save_png};

/// The ego speed of `demo` without `--speed-m-per-s`, metres per second (the flag's help says it).
pub const DEFAULT_SPEED_M_PER_S: f32 = 5.0;

/// Arguments of `groundtruth demo`.
#[derive(clap::Args, Debug)]
#[command(mut_arg("speed_m_per_s", |a| a.help("Ego speed, metres per second (default 5)")))]
pub struct Args {
    /// Output directory.
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Scene name or TOML file.
    #[arg(long, default_value = "city")]
    pub scene: String,
    /// Rig preset or TOML file.
    #[arg(long, default_value = "hdl64e-roof")]
    pub rig: String,
    /// Classification methods, comma-separated (see `groundtruth list`); each is scored and drawn.
    #[arg(long, alias = "method", value_delimiter = ',', default_value = "learned,nitsch")]
    pub methods: Vec<String>,
    /// Frames to scan.
    #[arg(long, default_value_t = 3)]
    pub frames: usize,
    /// Ego speed (`--speed-m-per-s`).
    #[command(flatten)]
    pub speed: super::common::SpeedArgs,
    /// Seed of the scene and the noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

/// Runs the demo.
pub fn run(args: Args) -> anyhow::Result<()> {
    let speed_m_per_s = args.speed.or(DEFAULT_SPEED_M_PER_S);
    if args.methods.is_empty() {
        anyhow::bail!("--methods: name at least one method (see `groundtruth list`)");
    }
    let mut methods = Vec::new();
    for name in &args.methods {
        if methods.iter().any(|(n, _)| n == name) {
            anyhow::bail!("--methods: `{name}` is named twice");
        }
        methods.push((name.clone(), method_by_name(name, args.seed)?));
    }
    let scan_dir = args.out.join("scan");
    let class_dir = args.out.join("classified");
    let scan_args = super::scan::Args {
        spec: None,
        scene: args.scene.clone(),
        rig: args.rig.clone(),
        out: scan_dir.clone(),
        seed: args.seed,
        frames: args.frames,
        speed_m_per_s: Some(f64::from(speed_m_per_s)),
        speed: None,
        yaw_rate_deg_per_s: None,
        yaw_rate: None,
        ideal: false,
        format: "pcd,ply,kitti,las".into(),
        pcd_layout: "groundtruth".into(),
        bag_compression: "zstd".into(),
        weather: None,
        snow_cover_m: None,
        threads: None,
        backend: "bvh".into(),
    };
    let manifest = super::scan::scan_to_dir(&scan_args)?;
    println!(
        "1. scanned `{}` with `{}`: {} frame(s) -> {}",
        args.scene,
        args.rig,
        manifest.frames.len(),
        scan_dir.display()
    );

    let clouds = manifest
        .frames
        .iter()
        .map(|f| Ok((f, sim::io::pcd::read(&scan_dir.join(&f.file))?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let opts = BevOptions::default();
    if let Some((_, cloud)) = clouds.first() {
        save_png(&args.out.join("scan_class.png"), &render_bev(cloud, &Coloring::Class, &opts)?)?;
    }
    let mut scores = serde_json::Map::new();
    let mut table = Vec::new();
    for (name, method) in &mut methods {
        let dir = class_dir.join(name.as_str());
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let mut eval = Evaluation::default();
        for (f, cloud) in &clouds {
            let input =
                FrameInput { index: f.index, cloud, world_from_vehicle: Some(affine_from_rows(&f.world_from_vehicle)) };
            let ground = method.classify(&input).with_context(|| format!("{name}: classifying frame {}", f.index))?;
            eval.add_frame(cloud, &ground);
            let bytes: Vec<u8> = ground.iter().map(|&g| u8::from(g)).collect();
            sim::io::atomic::write_bytes_atomic(&dir.join(format!("frame_{:06}.ground", f.index)), &bytes)?;
            if f.index == manifest.frames[0].index {
                let outcome = Coloring::Outcome { predicted_ground: &ground };
                save_png(&args.out.join(format!("outcome_{name}.png")), &render_bev(cloud, &outcome, &opts)?)?;
            }
        }
        let s = eval.pooled.scores();
        table.push((name.clone(), s, eval.pooled.total()));
        scores.insert(name.clone(), serde_json::to_value(s)?);
    }
    println!("2. classified with {} -> {}/<method>/", args.methods.join(", "), class_dir.display());
    println!("3. scores against the ground truth ({} points):", table.first().map_or(0, |t| t.2));
    println!(
        "   {:<10} {:>7} {:>7} {:>9} {:>7} {:>7} {:>7}",
        "method", "acc", "FPR", "precision", "recall", "F1", "IoU"
    );
    for (name, s, _) in &table {
        println!(
            "   {:<10} {:>7.4} {:>7.4} {:>9.4} {:>7.4} {:>7.4} {:>7.4}",
            name, s.acc, s.fpr, s.precision, s.recall, s.f1, s.iou
        );
    }
    let json = serde_json::json!({ "scene": args.scene, "rig": args.rig, "methods": scores });
    sim::io::atomic::write_bytes_atomic(&args.out.join("eval.json"), serde_json::to_string_pretty(&json)?.as_bytes())?;

    let scene_png = args.out.join("scene.png");
    super::render_scene::run(&super::render::Args {
        scene: Some(args.scene.clone()),
        input: None,
        frame: 0,
        view: "bev".into(),
        color: "class".into(),
        seed: args.seed,
        out: scene_png.clone(),
    })?;
    println!(
        "4. pictures: {} (scene from above), {} (scan by class), {} (true / false / missed ground, per method)",
        scene_png.display(),
        args.out.join("scan_class.png").display(),
        args.out.join("outcome_<method>.png").display()
    );
    Ok(())
}
