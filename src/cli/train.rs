//! `groundtruth train`: trains a learning method (McDaniel et al.'s linear SVM) on scans of one or
//! more scenes and writes the model as a small JSON file (atomically), e.g.
//! `groundtruth train --method mcdaniel --scene forest-moderate,forest-dense --rig utm30lx-nodding --out model.json`.
//! The vehicle stands at the scene's origin (one nod of the nodding laser is one frame, as in
//! the paper); every frame's min-z candidates with their ground truth form the training set.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};
use classifier::mcdaniel::{self, FeatureParams, TrainParams};

/// Arguments of `groundtruth train`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Method to train (`mcdaniel`, the only learning method).
    #[arg(long, default_value = "mcdaniel")]
    method: String,
    /// Comma-separated scene names or TOML files to train on.
    #[arg(long)]
    scene: String,
    /// Rig name or TOML file.
    #[arg(long)]
    rig: String,
    /// Model file to write (JSON).
    #[arg(long)]
    out: PathBuf,
    /// Seed of the scenes and the scan noise.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Frames per scene (1 ..= 100).
    #[arg(long, default_value_t = 1)]
    frames: usize,
    /// Turn measurement effects off.
    #[arg(long)]
    ideal: bool,
}

/// Runs `groundtruth train`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.method != "mcdaniel" {
        bail!("--method `{}`: only `mcdaniel` is trained (the other methods have no learned parameters)", args.method);
    }
    if !(1..=100).contains(&args.frames) {
        bail!("--frames {}: allowed 1 ..= 100", args.frames);
    }
    let scenes = super::common::split_list(&args.scene);
    if scenes.is_empty() {
        bail!("--scene is empty: name at least one scene (comma-separated)");
    }
    super::common::load_rig(&args.rig)?;
    let params = FeatureParams::default();
    let mut sets = Vec::new();
    for scene in &scenes {
        let frames = super::common::scan_standing(scene, &args.rig, args.seed, args.frames, args.ideal)?;
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
        "scenes": scenes, "rig": args.rig, "seed": args.seed, "frames": args.frames, "ideal": args.ideal,
    });
    let t = Instant::now();
    let model = mcdaniel::train(&sets, &TrainParams { trained_on, ..Default::default() })
        .with_context(|| format!("training on {}", scenes.join(", ")))?;
    let seconds = t.elapsed().as_secs_f64();
    model.save(&args.out)?;
    println!("trained in {seconds:.3} s; model written to {}", args.out.display());
    Ok(())
}
