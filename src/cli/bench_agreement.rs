//! `groundtruth bench agreement`: scans the same scene, rig, seed and frames with two backends
//! (default `gpu` against the reference `bvh`), compares them cell by cell and checks the GPU
//! contract ([`sim::scan::AgreementContract::GPU`]). Prints one JSON object; exits non-zero when
//! the contract is broken.

use std::time::Instant;

use anyhow::Context;
use groundtruth_scenario::{ScanBackend, ScanSetup, ScanSpec};
use sim::scan::{Agreement, AgreementContract, Scanner};

/// The ego speed of `bench agreement` without `--speed-m-per-s`, metres per second (the flag's help says it).
pub const DEFAULT_SPEED_M_PER_S: f32 = 10.0;

/// Arguments of `groundtruth bench agreement`.
#[derive(clap::Args, Debug)]
#[command(mut_arg("speed_m_per_s", |a| a.help("Ego speed, metres per second (0: a standing vehicle, whose rays stay on the device; default 10)")))]
pub struct Args {
    /// Scene name or TOML file.
    #[arg(long, default_value = "city")]
    pub scene: String,
    /// Rig preset or TOML file.
    #[arg(long, default_value = "hdl64e-roof")]
    pub rig: String,
    /// Frames to compare.
    #[arg(long, default_value_t = 3)]
    pub frames: usize,
    /// Seed of the scene and of the measurement noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Ego speed (`--speed-m-per-s`).
    #[command(flatten)]
    pub speed: super::common::SpeedArgs,
    /// Measurement effects off (exact distances).
    #[arg(long)]
    pub ideal: bool,
    /// The backend under test.
    #[arg(long, default_value = "gpu")]
    pub backend: String,
    /// The reference backend.
    #[arg(long, default_value = "bvh")]
    pub reference: String,
}

/// Runs the comparison.
pub fn run(args: Args) -> anyhow::Result<()> {
    if !(1..=1000).contains(&args.frames) {
        anyhow::bail!("invalid value for `--frames`: {} (allowed: 1 ..= 1000)", args.frames);
    }
    let speed_m_per_s = args.speed.or(DEFAULT_SPEED_M_PER_S);
    let spec = ScanSpec {
        scene: args.scene.clone(),
        rig: args.rig.clone(),
        seed: args.seed,
        frames: args.frames as u64,
        speed_m_per_s: f64::from(speed_m_per_s),
        ideal: args.ideal,
        ..ScanSpec::default()
    };
    let scene = spec.load_scene().with_context(|| format!("loading scene `{}`", args.scene))?;
    let rig = spec.rig()?;
    let scan = |backend: &str| -> anyhow::Result<(Vec<sim::OrderedCloud>, f64)> {
        let backend = Some(ScanBackend::parse(backend).context("--backend")?);
        let ScanSetup { config, .. } = ScanSpec { backend, ..spec.clone() }.setup(&scene)?;
        let t0 = Instant::now();
        let scanner = Scanner::new(&scene.mesh, &rig, config)?;
        let clouds = (0..args.frames).map(|k| scanner.frame(k).cloud).collect();
        Ok((clouds, t0.elapsed().as_secs_f64()))
    };
    let (tested, tested_s) = scan(&args.backend)?;
    let (reference, reference_s) = scan(&args.reference)?;
    // The coarsest range quantum of the rig's sensors (0 with --ideal).
    let quantum = if args.ideal {
        0.0
    } else {
        rig.sensors.iter().map(|s| s.spec.measurement().range_quantum_m).fold(0.0f32, f32::max)
    };
    let mut total = Agreement::default();
    for (a, b) in tested.iter().zip(&reference) {
        total.add(&Agreement::of(a, b, quantum)?);
    }
    let verdict = AgreementContract::GPU.check(&total);
    let json = serde_json::json!({
        "scene": args.scene,
        "rig": args.rig,
        "frames": args.frames,
        "speed_m_per_s": speed_m_per_s,
        "ideal": args.ideal,
        "backend": args.backend,
        "reference": args.reference,
        "adapter": adapter(&args.backend),
        "seconds": { "backend": tested_s, "reference": reference_s },
        "agreement": total,
        "hit_miss_share": total.hit_miss_share(),
        "label_share": total.label_share(),
        "range_share": total.range_share(),
        "bit_equal_share": total.bit_equal_share(),
        "range_quantum_m": quantum,
        "contract": { "holds": verdict.is_ok(), "broken": verdict.as_ref().err() },
    });
    println!("{}", serde_json::to_string_pretty(&json)?);
    if let Err(e) = verdict {
        anyhow::bail!("the {} backend breaks the agreement contract against {}: {e}", args.backend, args.reference);
    }
    Ok(())
}

fn adapter(backend: &str) -> Option<String> {
    (backend == "gpu").then(sim::cast::gpu_adapter).and_then(Result::ok)
}
