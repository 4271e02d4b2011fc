//! `groundtruth bench scan`: what a full frame (rays, casting, effects, labels, ordered cloud) costs
//! against casting the same rays bare. Prints one JSON object.
//!
//! Bare: the frame's rays, generated beforehand, cast with `cast_batch` per row in parallel. Full:
//! `Scanner::frame_into` into a reused cloud. A standing vehicle's rays are the same in every frame,
//! so the scanner builds them once (in `Scanner::new`); `--speed-m-per-s` makes the vehicle move so that
//! every full frame builds its rays at each shot's own pose.

use std::time::Instant;

use anyhow::Context;
use groundtruth_scenario::{ScanSetup, ScanSpec};
use rayon::prelude::*;
use sim::cast::Hit;
use sim::scan::Scanner;

/// The ego speed of `bench scan` without `--speed-m-per-s`, metres per second (the flag's help says it).
pub const DEFAULT_SPEED_M_PER_S: f32 = 0.0;

/// Arguments of `groundtruth bench scan`.
#[derive(clap::Args, Debug)]
#[command(mut_arg("speed_m_per_s", |a| a.help("Ego speed, metres per second (0: a standing vehicle; default 0)")))]
pub struct Args {
    /// Scene name or TOML file.
    #[arg(long, default_value = "flat-objects")]
    pub scene: String,
    /// Rig preset or TOML file.
    #[arg(long, default_value = "os1-128-roof")]
    pub rig: String,
    /// Frames to time (each timed both ways; the fastest run counts).
    #[arg(long, default_value_t = 5)]
    pub frames: usize,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed of the scene and the scan.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Ego speed (`--speed-m-per-s`).
    #[command(flatten)]
    pub speed: super::common::SpeedArgs,
    /// Also time full frames in these weathers (`fog:visibility_m=50 snow:rate_mm_h=2 ...`),
    /// interleaved with the plain frame: `weather[].added` is the share of time they add.
    #[arg(long, num_args = 1..)]
    pub weather: Vec<String>,
}

/// Runs the benchmark.
pub fn run(args: Args) -> anyhow::Result<()> {
    if !(1..=1000).contains(&args.frames) {
        anyhow::bail!("invalid value for `--frames`: {} (allowed: 1 ..= 1000)", args.frames);
    }
    let threads = args.threads;
    let speed_m_per_s = args.speed.or(DEFAULT_SPEED_M_PER_S);
    let json = super::scan::with_threads(threads, || bench(&args, speed_m_per_s))??;
    println!("{json}");
    Ok(())
}

/// The timings of `args`'s scan at `speed_m_per_s` (the flag's value, either spelling).
fn bench(args: &Args, speed_m_per_s: f32) -> anyhow::Result<serde_json::Value> {
    let spec = ScanSpec {
        scene: args.scene.clone(),
        rig: args.rig.clone(),
        seed: args.seed,
        speed_m_per_s: f64::from(speed_m_per_s),
        ..ScanSpec::default()
    };
    let scene = spec.load_scene().with_context(|| format!("loading scene `{}`", args.scene))?;
    let t0 = Instant::now();
    let ScanSetup { config, rig } = spec.setup(&scene)?;
    let prepared = sim::scan::PreparedScene::new(&scene.mesh, config.backend)?;
    let scanner = Scanner::with_prepared(&scene.mesh, &rig, config.clone(), &prepared)?;
    let setup_s = t0.elapsed().as_secs_f64();
    let mut weathers = args
        .weather
        .iter()
        .map(|text| {
            let w = sim::effects::weather::Weather::parse(text)?;
            let s = Scanner::with_prepared(
                &scene.mesh,
                &rig,
                ScanSpec { weather: Some(w), ..spec.clone() }.setup(&scene)?.config,
                &prepared,
            )?;
            Ok((w, s, f64::INFINITY, 0usize))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;

    let rows = scanner.rows();
    let all_rays: Vec<_> = (0..rows).map(|r| scanner.row_rays(0, r).rays).collect();
    let rays: usize = all_rays.iter().map(Vec::len).sum();
    let (mut bare_s, mut full_s) = (f64::INFINITY, f64::INFINITY);
    let mut cloud = sim::OrderedCloud::default();
    let mut returns = 0;
    for _ in 0..args.frames {
        let t = Instant::now();
        let hits: usize = all_rays
            .par_iter()
            .map(|r| {
                let mut out: Vec<Option<Hit>> = vec![None; r.len()];
                scanner.caster().cast_batch(r, &mut out);
                out.iter().filter(|h| h.is_some()).count()
            })
            .sum();
        bare_s = bare_s.min(t.elapsed().as_secs_f64());
        std::hint::black_box(hits);
        let t = Instant::now();
        scanner.frame_into(0, &mut cloud);
        full_s = full_s.min(t.elapsed().as_secs_f64());
        returns = cloud.returns();
        for (_, s, best, weather_returns) in &mut weathers {
            let t = Instant::now();
            s.frame_into(0, &mut cloud);
            *best = best.min(t.elapsed().as_secs_f64());
            *weather_returns = cloud.returns();
        }
    }
    let weather: Vec<serde_json::Value> = weathers
        .iter()
        .map(|(w, _, best, weather_returns)| {
            serde_json::json!({
                "weather": w.spec(),
                "full_frame_ms": best * 1e3,
                "added": best / full_s - 1.0,
                "returns": weather_returns,
            })
        })
        .collect();
    Ok(serde_json::json!({
        "bench": "scan",
        "scene": args.scene,
        "rig": args.rig,
        "triangles": scene.mesh.len(),
        "threads": rayon::current_num_threads(),
        "speed_m_per_s": speed_m_per_s,
        "rays": rays,
        "returns": returns,
        "setup_s": setup_s,
        "bare_cast_ms": bare_s * 1e3,
        "full_frame_ms": full_s * 1e3,
        "overhead": full_s / bare_s - 1.0,
        "rays_per_s_full": rays as f64 / full_s,
        "weather": weather,
    }))
}
