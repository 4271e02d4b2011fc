//! `groundtruth train`: trains a learning method and writes its model as a JSON file (atomically).
//!
//! - `--method mcdaniel` (McDaniel et al.'s linear SVM) on scans of one or more scenes, e.g.
//!   `groundtruth train --method mcdaniel --scene forest-moderate,forest-dense --rig utm30lx-nodding --out model.json`.
//!   The vehicle stands at the scene's origin (one nod of the nodding laser is one frame, as in
//!   the paper); every frame's min-z candidates with their ground truth form the training set.
//! - `--method learned` (gradient-boosted oblivious trees) from a dataset file (`--config`) or a
//!   dataset on disk (`--dataset`): see [`super::train_learned`].

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};
use classifier::mcdaniel::{self, FeatureParams, TrainParams};

/// Arguments of `groundtruth train`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Method to train: `mcdaniel` or `learned`.
    #[arg(long, default_value = "mcdaniel")]
    method: String,
    /// `mcdaniel`: comma-separated scene names or TOML files to train on.
    #[arg(long)]
    scene: Option<String>,
    /// `mcdaniel`: rig name or TOML file; `learned --dataset`: the rig of a dataset without our
    /// manifest.
    #[arg(long)]
    rig: Option<String>,
    /// `learned`: a dataset file (its sequences, and a `[generate]` table's, scanned in memory).
    #[arg(long, conflicts_with_all = ["dataset", "scene"])]
    config: Option<PathBuf>,
    /// `learned`: a dataset written by `groundtruth dataset`.
    #[arg(long, conflicts_with = "scene")]
    dataset: Option<PathBuf>,
    /// `learned`: boosting rounds (trees).
    #[arg(long)]
    trees: Option<usize>,
    /// `learned`: tree depth.
    #[arg(long)]
    depth: Option<usize>,
    /// `learned`: learning rate.
    #[arg(long)]
    eta: Option<f64>,
    /// `learned`: returns drawn from each training frame.
    #[arg(long)]
    samples_per_frame: Option<usize>,
    /// `learned`: every this many frames one is held out (0: none).
    #[arg(long)]
    validation_every: Option<usize>,
    /// Worker threads (default: all cores); the model is the same at any count.
    #[arg(long)]
    threads: Option<usize>,
    /// Model file to write (JSON).
    #[arg(long)]
    out: PathBuf,
    /// Seed of the scenes and the scan noise (`learned`: of the sampling and the library).
    #[arg(long)]
    seed: Option<u64>,
    /// Frames per scene (1 ..= 100).
    #[arg(long, default_value_t = 1)]
    frames: usize,
    /// Turn measurement effects off.
    #[arg(long)]
    ideal: bool,
}

/// Runs `groundtruth train`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.method == "learned" {
        if args.scene.is_some() {
            bail!("--scene applies to `mcdaniel`; `learned` trains from --config D.toml or --dataset DIR");
        }
        return super::train_learned::run(&super::train_learned::LearnedArgs {
            config: args.config.as_deref(),
            dataset: args.dataset.as_deref(),
            rig: args.rig.as_deref(),
            out: &args.out,
            overrides: super::dataset::generate::TrainSection {
                method: None,
                trees: args.trees,
                depth: args.depth,
                eta: args.eta,
                samples_per_frame: args.samples_per_frame,
                validation_every: args.validation_every,
                seed: args.seed,
            },
            threads: args.threads,
        });
    }
    if args.method != "mcdaniel" {
        bail!(
            "--method `{}`: the trained methods are `mcdaniel` and `learned` (the others have no learned parameters)",
            args.method
        );
    }
    if args.config.is_some() || args.dataset.is_some() {
        bail!("--config and --dataset apply to `learned`; `mcdaniel` trains on --scene with --rig");
    }
    let (Some(scene_list), Some(rig)) = (&args.scene, &args.rig) else {
        bail!("`mcdaniel` needs --scene and --rig");
    };
    let seed = args.seed.unwrap_or(0);
    if !(1..=100).contains(&args.frames) {
        bail!("--frames {}: allowed 1 ..= 100", args.frames);
    }
    let scenes = super::common::split_list(scene_list);
    if scenes.is_empty() {
        bail!("--scene is empty: name at least one scene (comma-separated)");
    }
    super::common::load_rig(rig)?;
    let params = FeatureParams::default();
    let mut sets = Vec::new();
    for scene in &scenes {
        let frames = super::common::scan_standing(scene, rig, seed, args.frames, args.ideal)?;
        for f in &frames {
            let set = mcdaniel::candidates(&f.cloud, &params, None)
                .with_context(|| format!("features of `{scene}` frame {}", f.index))?;
            let ground = set.ground.iter().filter(|&&g| g).count();
            println!(
                "{scene} frame {}: {} returns, {} min-z candidates ({ground} ground, {} non-ground)",
                f.index,
                f.cloud.returns(),
                set.len(),
                set.len() - ground
            );
            sets.push(set);
        }
    }
    let trained_on = serde_json::json!({
        "scenes": scenes, "rig": rig, "seed": seed, "frames": args.frames, "ideal": args.ideal,
    });
    let t = Instant::now();
    let model = mcdaniel::train(&sets, &TrainParams { trained_on, ..Default::default() })
        .with_context(|| format!("training on {}", scenes.join(", ")))?;
    let seconds = t.elapsed().as_secs_f64();
    model.save(&args.out)?;
    println!("trained in {seconds:.3} s; model written to {}", args.out.display());
    Ok(())
}
