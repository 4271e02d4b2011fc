//! `groundtruth scan`: scan a scene with a rig and write ordered labelled clouds and a manifest.

use std::path::{Path, PathBuf};

use anyhow::Context;
use groundtruth_scenario::{ScanBackend, ScanSpec};
use sim::cast::Backend;
use sim::effects::weather::Weather;
use sim::io::formats::{Formats, FrameContext};
use sim::io::manifest::{FrameEntry, MANIFEST_VERSION, Manifest, SensorEntry, matrix_rows};
use sim::scan::Scanner;

/// The flags that describe the scan (refused beside `--spec`, which describes it whole).
const SPEC_FLAGS: [&str; 12] = [
    "scene",
    "rig",
    "seed",
    "frames",
    "speed_m_per_s",
    "speed",
    "yaw_rate_deg_per_s",
    "yaw_rate",
    "ideal",
    "weather",
    "snow_cover_m",
    "backend",
];

/// Arguments of `groundtruth scan`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// The whole scan as a spec file (TOML, see docs/scan-spec.md; a manifest's `spec` saved as
    /// TOML or JSON remakes its files). The flags that describe the scan (--scene, --rig, --seed,
    /// --frames, --speed-m-per-s, --yaw-rate-deg-per-s, --ideal, --weather, --snow-cover-m,
    /// --backend) are refused beside it.
    #[arg(long, conflicts_with_all = SPEC_FLAGS)]
    pub spec: Option<PathBuf>,
    /// Scene name (see `groundtruth list`: bundled, built-in, families) or TOML scene file.
    #[arg(long, default_value = "flat-objects")]
    pub scene: String,
    /// Rig preset name (see `groundtruth list`) or TOML rig file.
    #[arg(long, default_value = "vlp16-roof")]
    pub rig: String,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Seed of the scene generator and of the measurement noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Number of frames.
    #[arg(long, default_value_t = 1)]
    pub frames: usize,
    /// Ego speed, metres per second (-100 ..= 100; default 0).
    #[arg(long, allow_negative_numbers = true, conflicts_with = "speed")]
    pub speed_m_per_s: Option<f64>,
    /// Deprecated spelling of --speed-m-per-s (metres per second); removed in the next release.
    #[arg(long, allow_negative_numbers = true, hide = true)]
    pub speed: Option<f32>,
    /// Ego yaw rate, degrees per second (positive turns left; -114.59 ..= 114.59; default 0).
    #[arg(long, allow_negative_numbers = true, conflicts_with = "yaw_rate")]
    pub yaw_rate_deg_per_s: Option<f64>,
    /// Deprecated: the yaw rate in radians per second; use --yaw-rate-deg-per-s. Removed in the
    /// next release.
    #[arg(long, allow_negative_numbers = true, hide = true)]
    pub yaw_rate: Option<f32>,
    /// Turn measurement effects off (exact distances, no noise, no quantisation, no dropout).
    #[arg(long)]
    pub ideal: bool,
    /// Files to write per frame: any of pcd, pcd-ascii, ply, kitti, las (comma-separated); `mcap`
    /// writes the whole scan as a ROS 2 bag (`bag/`: rosbag2 with one MCAP file; the clouds in the
    /// `--pcd-layout`, one topic per sensor, `/tf`, `/tf_static`).
    #[arg(long, default_value = "pcd")]
    pub format: String,
    /// Layout of the organized PCD: `groundtruth` (ours: rows bottom-first, every field, NaN
    /// no-returns), `velodyne` (velodyne_pointcloud's organized PointXYZIRT: ring 0 = bottom, NaN
    /// no-returns) or `ouster` (ouster-ros: row 0 = ring 0 = the top beam, zero no-returns, `range`
    /// in millimetres). The driver layouts hold sensor-frame points for a single-sensor rig, plane 0
    /// only, plus our `label` field; the manifest's `pcd_layout` says which was written. Also the
    /// layout of the bag's clouds.
    #[arg(long, default_value = "groundtruth")]
    pub pcd_layout: String,
    /// Weather per beam: `clear` (detection thresholds only), `fog:visibility_m=V`,
    /// `rain:rate_mm_h=R` or `snow:rate_mm_h=R` (default: the scene file's `[weather]`, else none).
    /// Returns from the medium are labelled fog (150), rain (151) or snow (152).
    #[arg(long)]
    pub weather: Option<String>,
    /// Snow lying on the ground, metres deep (0 < depth <= 1): the ground raised by it, labelled
    /// terrain (72) with snow's reflectivity.
    #[arg(long)]
    pub snow_cover_m: Option<f64>,
    /// Chunk compression of the bag (`--format mcap`): `zstd` (level -5, rosbag2's `zstd_fast`
    /// preset) or `none` (larger files, no compression work).
    #[arg(long, default_value = "zstd")]
    pub bag_compression: String,
    /// Worker threads (default: all cores). Results are identical at any count.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Ray casting backend: bvh (production), parry (reference) or gpu (wgpu; the adapter as
    /// `WGPU_BACKEND` / `WGPU_ADAPTER_NAME` choose).
    #[arg(long, default_value = "bvh")]
    pub backend: String,
}

/// Parses a backend name.
pub fn parse_backend(name: &str) -> anyhow::Result<Backend> {
    Ok(ScanBackend::parse(name).context("--backend")?.to_sim())
}

impl Args {
    /// The scan these arguments describe: the `--spec` file, else the flags (the deprecated
    /// spellings say so on stderr).
    pub fn scan_spec(&self) -> anyhow::Result<ScanSpec> {
        if let Some(path) = &self.spec {
            let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
            let source = path.display().to_string();
            // A manifest's `spec` saved as JSON reads too.
            let mut spec = if text.trim_start().starts_with('{') {
                let value = serde_json::from_str(&text).with_context(|| format!("{source}: not JSON"))?;
                ScanSpec::from_json_value(value, &source)?
            } else {
                ScanSpec::from_toml_str(&text, &source)?
            };
            // The manifest says which backend made the files, given or not.
            spec.backend.get_or_insert_with(ScanBackend::default);
            return Ok(spec);
        }
        let mut spec = ScanSpec {
            scene: self.scene.clone(),
            seed: self.seed,
            rig: self.rig.clone(),
            frames: self.frames as u64,
            ideal: self.ideal,
            weather: self.weather.as_deref().map(Weather::parse).transpose().context("--weather")?,
            snow_cover_m: self.snow_cover_m,
            backend: Some(ScanBackend::parse(&self.backend).context("--backend")?),
            ..ScanSpec::default()
        };
        if let Some(v) = super::common::speed_m_per_s(self.speed_m_per_s, self.speed.map(f64::from)) {
            spec.speed_m_per_s = v;
        }
        if let Some(v) = self.yaw_rate {
            eprintln!(
                "warning: --yaw-rate (radians per second) is deprecated, use --yaw-rate-deg-per-s ({} deg/s)",
                f64::from(v).to_degrees()
            );
            spec.set_yaw_rate_rad_per_s(v);
        }
        if let Some(v) = self.yaw_rate_deg_per_s {
            spec.yaw_rate_deg_per_s = v;
        }
        spec.validate()?;
        Ok(spec)
    }
}

/// Runs `f` on a rayon pool of `threads` workers (all cores when `None`).
pub fn with_threads<T: Send>(threads: Option<usize>, f: impl FnOnce() -> T + Send) -> anyhow::Result<T> {
    match threads {
        None => Ok(f()),
        Some(n) if (1..=1024).contains(&n) => {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build()?;
            Ok(pool.install(f))
        }
        Some(n) => anyhow::bail!("invalid value for `--threads`: {n} (allowed: 1 ..= 1024)"),
    }
}

/// Runs `groundtruth scan`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let manifest = with_threads(args.threads, || scan_to_dir(&args))??;
    let returns: usize = manifest.frames.iter().map(|f| f.returns).sum();
    let ground: usize = manifest.frames.iter().map(|f| f.ground_returns).sum();
    println!(
        "scanned {} frame(s) of `{}` with `{}`: {} returns ({} ground) -> {}",
        manifest.frames.len(),
        manifest.scene,
        manifest.rig,
        returns,
        ground,
        args.out.join("manifest.json").display()
    );
    Ok(())
}

/// The rosbag2 directory of `--format mcap` inside the output directory (`bag/bag_0.mcap`).
pub const BAG_DIR: &str = "bag";

/// Scans as `args` says, writes every frame's files and the manifest into `args.out`, and returns the manifest.
pub fn scan_to_dir(args: &Args) -> anyhow::Result<Manifest> {
    let mut formats = Formats::parse(&args.format)?;
    formats.pcd_layout = sim::io::pcd::PcdLayout::parse(&args.pcd_layout)?;
    let spec = args.scan_spec()?;
    let scene = spec.load_scene().with_context(|| format!("loading scene `{}`", spec.scene))?;
    let setup = spec.setup(&scene)?;
    let (rig, config) = (setup.rig, setup.config);
    let (frame_count, weather) = (config.frames, config.weather);
    let (speed_m_per_s, yaw_rate_rad_per_s) = (config.speed_m_per_s, config.yaw_rate_rad_per_s);
    let scanner = Scanner::new(&scene.mesh, &rig, config)?;
    // Checked before anything is created: a compression this build lacks leaves nothing behind.
    let compression = match formats.mcap {
        true => Some(sim::io::ros2::BagCompression::parse(&args.bag_compression)?.check_built()?),
        false => None,
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating output directory {}", args.out.display()))?;

    let single = rig.sensors.len() == 1;
    let sensor_from_vehicle = single.then(|| rig.sensors[0].mount.vehicle_from_sensor().inverse());
    // The bag: every frame's clouds, its pose and the mounts (sim::io::ros2::scan).
    let sensor_topics = sim::io::ros2::scan::sensor_topics(&rig);
    let mut bag = match compression {
        Some(compression) => {
            let mut b = sim::io::ros2::BagWriter::create_with(&args.out.join(BAG_DIR), compression)?;
            sim::io::ros2::scan::write_static(&mut b, &sensor_topics)?;
            Some(b)
        }
        None => None,
    };
    // A pipeline: this thread casts frame k + 1 (on the rayon pool) while a writer thread encodes
    // and writes frame k; the files and their order do not depend on the timing.
    let frames = std::thread::scope(|scope| -> anyhow::Result<Vec<FrameEntry>> {
        let (sender, receiver) = std::sync::mpsc::sync_channel::<sim::scan::Frame>(1);
        let (out, formats, topics, bag) = (&args.out, &formats, &sensor_topics, &mut bag);
        let writer = scope.spawn(move || -> anyhow::Result<Vec<FrameEntry>> {
            let mut entries = Vec::new();
            for frame in receiver {
                let ctx = FrameContext { index: frame.index, sensor_from_vehicle };
                let mut files = sim::io::formats::write_frame(out, &frame.cloud, &ctx, formats)?;
                if let Some(b) = bag.as_mut() {
                    let written = sim::io::ros2::scan::write_frame(
                        b,
                        &frame.cloud,
                        topics,
                        formats.pcd_layout,
                        frame.start_time_s,
                        &frame.world_from_vehicle,
                    )?;
                    for (topic, points) in written {
                        files.push(sim::io::formats::WrittenFile {
                            file: format!("{BAG_DIR}/{BAG_DIR}_0.mcap"),
                            format: format!("mcap:{topic}"),
                            points,
                        });
                    }
                }
                let file = files.first().map(|f| f.file.clone()).unwrap_or_default();
                entries.push(FrameEntry {
                    index: frame.index,
                    file,
                    rows: frame.cloud.rows * frame.cloud.planes,
                    cols: frame.cloud.cols,
                    returns: frame.cloud.returns(),
                    ground_returns: frame.cloud.ground_returns(),
                    start_time_s: frame.start_time_s,
                    vehicle_pose: frame.vehicle_pose,
                    world_from_vehicle: matrix_rows(&frame.world_from_vehicle),
                    files,
                });
            }
            Ok(entries)
        });
        // Frames in order; with a device caster the next frames are cast while this one is
        // measured (`Scanner::scan_frames`). A failed writer has dropped the receiver: stop
        // casting and report its error.
        let cast = scanner.scan_frames(0..frame_count, |mut frame| -> anyhow::Result<()> {
            crate::cli::common::check_device(scanner.caster())?;
            spec.vary(&mut frame.cloud, frame.index)?;
            sender.send(frame).map_err(|_| anyhow::anyhow!("the writer stopped"))
        });
        drop(sender);
        let entries = writer.join().map_err(|_| anyhow::anyhow!("the writer thread panicked"))??;
        cast.map(|()| entries)
    })?;
    if let Some(b) = bag {
        b.finish()?;
    }
    let layout = scanner.layout();
    let sensors = rig
        .sensors
        .iter()
        .enumerate()
        .map(|(id, s)| {
            let p = &scanner.patterns()[id];
            SensorEntry {
                id,
                name: s.name.clone(),
                model: s.spec.model_name(),
                rows: p.rows,
                columns: p.cols,
                vehicle_from_sensor: matrix_rows(&s.mount.vehicle_from_sensor()),
                mount: s.mount,
                measurement: scanner.measurements()[id],
                merged_row_of_ring: layout.row_of[id].clone(),
            }
        })
        .collect();
    let manifest = Manifest {
        version: MANIFEST_VERSION,
        generator: format!("groundtruth {}", env!("CARGO_PKG_VERSION")),
        scene: if spec.scene.is_empty() { spec.family.clone().unwrap_or_default() } else { spec.scene.clone() },
        rig: spec.rig.clone(),
        seed: spec.seed,
        ideal: spec.ideal,
        speed_m_per_s,
        yaw_rate_rad_per_s,
        weather: weather.filter(|_| !spec.ideal).map(|w| w.spec()),
        frame_period_s: scanner.frame_period_s(),
        kitti_frame: if single { "sensor" } else { "vehicle" }.to_string(),
        pcd_layout: formats.pcd_layout.name().to_string(),
        planes: scanner.planes(),
        ordering: sim::layout::ORDERING.to_string(),
        sensors,
        frames,
        spec: Some(serde_json::to_value(&spec)?),
    };
    manifest.write(Path::new(&args.out))?;
    Ok(manifest)
}
