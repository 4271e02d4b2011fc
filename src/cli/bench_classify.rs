//! `groundtruth bench classify`: scans a scene with a rig and times one method per frame on one
//! thread, printing one JSON object: frames, grid size, and mean / min milliseconds per frame for
//! features, clustering (candidates, clustering and cluster rules) and the whole classification.
//! Methods that do not report stages (ransac, grid) give only the total.

use std::time::Instant;

use anyhow::Context;
use classifier::{FrameInput, method_by_name};
use sim::scan::ScanConfig;

/// Arguments of `groundtruth bench classify`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Method name.
    #[arg(long, default_value = "nitsch")]
    method: String,
    /// Scene name or TOML file.
    #[arg(long, default_value = "city")]
    scene: String,
    /// Rig name or TOML file.
    #[arg(long, default_value = "os1-128-roof")]
    rig: String,
    /// Frames to scan.
    #[arg(long, default_value_t = 3)]
    frames: usize,
    /// Times each frame is classified (the fastest counts toward `min`).
    #[arg(long, default_value_t = 5)]
    repeats: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

/// Runs the classification benchmark and prints one JSON object.
pub fn run(args: Args) -> anyhow::Result<()> {
    let scene = super::common::load_scene_full(&args.scene, args.seed)?;
    let rig = super::common::load_rig(&args.rig)?;
    let config =
        ScanConfig { seed: args.seed, frames: args.frames, ego_z_m: scene.ego_ground_z_m, ..Default::default() };
    let frames = sim::scan::scan(&scene.mesh, &rig, &config).context("scanning")?;
    let mut method = method_by_name(&args.method, args.seed)?;
    let repeats = args.repeats.max(1);
    let (mut feat, mut clus, mut total) = (Vec::new(), Vec::new(), Vec::new());
    for f in &frames {
        for _ in 0..repeats {
            let input = FrameInput { index: f.index, cloud: &f.cloud, world_from_vehicle: Some(f.world_from_vehicle) };
            let t = Instant::now();
            let out = method.classify(&input)?;
            total.push(t.elapsed().as_secs_f64() * 1e3);
            std::hint::black_box(out);
            if let Some(s) = method.stage_times() {
                feat.push(s.features_s * 1e3);
                clus.push(s.clustering_s * 1e3);
            }
        }
    }
    let stats = |v: &[f64]| {
        if v.is_empty() {
            serde_json::Value::Null
        } else {
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let min = v.iter().copied().fold(f64::INFINITY, f64::min);
            serde_json::json!({ "mean": mean, "min": min })
        }
    };
    let first = &frames[0].cloud;
    let out = serde_json::json!({
        "method": args.method,
        "scene": args.scene,
        "rig": args.rig,
        "frames": frames.len(),
        "repeats": repeats,
        "rows": first.rows,
        "cols": first.cols,
        "planes": first.planes,
        "returns": first.returns(),
        "threads": 1,
        "features_ms": stats(&feat),
        "clustering_ms": stats(&clus),
        "total_ms": stats(&total),
    });
    println!("{}", serde_json::to_string_pretty(&out)?);
    Ok(())
}
