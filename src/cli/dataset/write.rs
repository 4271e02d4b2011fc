//! Writing a dataset: every sequence checked first (scene, rig, mount, trajectory inside the
//! scene), then the directory claimed, then this shard's frames written (see the parent module).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use glam::{DAffine3, DQuat, EulerRot};
use groundtruth_scenario::{ScanBackend, ScanSpec};
use rayon::prelude::*;
use sim::io::atomic::write_bytes_atomic;
use sim::motion::{Trajectory, VehiclePose};
use sim::scan::{ScanConfig, Scanner};

use super::config::{DatasetConfig, SequenceConfig};
use crate::cli::shard::{Shard, stable_key};

/// Manifest file name in the dataset root.
pub const MANIFEST: &str = "manifest.json";
/// Label config file name in the dataset root.
pub const LABEL_CONFIG: &str = "groundtruth.yaml";
/// Manifest format version.
const MANIFEST_VERSION: u32 = 1;

/// A sequence ready to scan.
pub(crate) struct Prepared {
    /// Its configuration.
    pub config: SequenceConfig,
    /// Its rig, mount and noise overrides applied.
    pub rig: sim::Rig,
    /// Its scan.
    pub scan: ScanConfig,
}

/// Loads and checks every sequence; nothing is written.
pub(crate) fn prepare(config: &DatasetConfig) -> anyhow::Result<Vec<Prepared>> {
    let mut out = Vec::with_capacity(config.sequences.len());
    for (k, s) in config.sequences.iter().enumerate() {
        let at = format!("sequences[{k}]");
        let scene = s.spec.load_scene().with_context(|| format!("`{at}.scene`"))?;
        let setup = s.spec.setup(&scene).with_context(|| format!("`{at}`"))?;
        let (rig, scan) = (setup.rig, setup.config);
        let period_s = frame_period_s(&rig)?;
        check_inside(&scene.mesh, &scan, period_s, &at)?;
        out.push(Prepared { config: s.clone(), rig, scan });
    }
    Ok(out)
}

/// Applies a sequence's random dropout and intensity scale to frame `k` (its noise scale is in
/// the rig already).
pub(crate) fn vary(cloud: &mut sim::OrderedCloud, s: &SequenceConfig, k: usize) -> anyhow::Result<()> {
    Ok(s.spec.vary(cloud, k)?)
}

/// The rig's frame period (its slowest sensor), seconds.
fn frame_period_s(rig: &sim::Rig) -> anyhow::Result<f64> {
    Ok(rig.sensors.iter().map(|s| s.spec.pattern().frame_period_s).fold(0.0, f64::max))
}

/// Refuses a trajectory whose vehicle leaves the scene's x-y extent during the sequence.
fn check_inside(mesh: &sim::SceneMesh, scan: &ScanConfig, period_s: f64, at: &str) -> anyhow::Result<()> {
    let Some((lo, hi)) = mesh.bounds() else { bail!("`{at}.scene`: the scene has no triangles") };
    let trajectory = trajectory(scan);
    for k in 0..=scan.frames {
        let t = k as f64 * period_s;
        let (x, y, _) = trajectory.planar(t);
        let inside = x >= f64::from(lo.x) && x <= f64::from(hi.x) && y >= f64::from(lo.y) && y <= f64::from(hi.y);
        if !inside {
            bail!(
                "`{at}`: the trajectory leaves the scene at {t:.2} s (frame {k}): the vehicle is at ({x:.1}, {y:.1}) m, \
                 the scene spans x {:.1} ..= {:.1} m, y {:.1} ..= {:.1} m (shorten `frames`, lower `speed_m_per_s` or \
                 change the waypoints)",
                lo.x,
                hi.x,
                lo.y,
                hi.y
            );
        }
    }
    Ok(())
}

/// The trajectory of a scan configuration.
fn trajectory(scan: &ScanConfig) -> Trajectory {
    Trajectory {
        speed_m_per_s: f64::from(scan.speed_m_per_s),
        yaw_rate_rad_per_s: f64::from(scan.yaw_rate_rad_per_s),
        waypoints_m: scan.waypoints_m.clone(),
    }
}

/// The manifest: the configuration, its id and per-sequence facts (the same bytes from every shard).
fn manifest(config: &DatasetConfig, prepared: &[Prepared]) -> anyhow::Result<serde_json::Value> {
    let mut sequences = Vec::new();
    for p in prepared {
        let spec = ScanSpec { backend: Some(ScanBackend::from_sim(p.scan.backend)), ..p.config.spec.clone() };
        sequences.push(serde_json::json!({
            "id": p.config.id,
            "folder": format!("sequences/{:02}", p.config.id),
            "frames": p.config.frames,
            "frame_period_s": frame_period_s(&p.rig)?,
            "points_frame": if p.rig.sensors.len() == 1 { "sensor" } else { "vehicle" },
            // Each sensor's mount as scanned (the override applied), for readers of the dataset.
            "mounts": p.rig.sensors.iter().map(|s| s.mount).collect::<Vec<_>>(),
            // The full description the sequence was scanned from.
            "spec": spec,
        }));
    }
    Ok(serde_json::json!({
        "format": "groundtruth SemanticKITTI-layout dataset",
        "version": MANIFEST_VERSION,
        "id": stable_key(&config.canonical()),
        "generator": format!("groundtruth {}", env!("CARGO_PKG_VERSION")),
        "name": config.name,
        "label_config": LABEL_CONFIG,
        "frames": config.sequences.iter().map(|s| s.frames).sum::<u64>(),
        // `bvh` (the reproducible reference) or `gpu` (within the agreement contract).
        "backend": prepared.first().map_or("bvh", |p| p.scan.backend.name()),
        "config": config,
        "sequences": sequences,
    }))
}

/// Refuses a directory holding another dataset's manifest; writes this one's (and the label
/// config) otherwise.
fn claim(dir: &Path, manifest: &serde_json::Value, label_yaml: &str) -> anyhow::Result<()> {
    let path = dir.join(MANIFEST);
    if path.is_file() {
        let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
        let old: serde_json::Value = serde_json::from_str(&text)
            .with_context(|| format!("--out {}: {MANIFEST} is not a dataset manifest", dir.display()))?;
        if old.get("id") != manifest.get("id") {
            bail!(
                "--out {}: holds another dataset (`{}`, id {}; this one is {}); choose another --out",
                dir.display(),
                old.get("name").and_then(|v| v.as_str()).unwrap_or("?"),
                old.get("id").and_then(|v| v.as_str()).unwrap_or("?"),
                manifest["id"].as_str().unwrap_or("?")
            );
        }
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    write_bytes_atomic(&path, serde_json::to_string_pretty(manifest)?.as_bytes())?;
    write_bytes_atomic(&dir.join(LABEL_CONFIG), label_yaml.as_bytes())?;
    Ok(())
}

/// `world_from_vehicle` of a pose in double precision.
fn world_from_vehicle(p: &VehiclePose) -> DAffine3 {
    let rot = DQuat::from_euler(EulerRot::ZYX, p.yaw_rad, p.pitch_rad, p.roll_rad);
    DAffine3::from_rotation_translation(rot, glam::DVec3::new(p.x_m, p.y_m, p.z_m))
}

/// A 3 x 4 row-major line of a rigid transform.
fn row_major(t: &DAffine3) -> String {
    let (m, p) = (t.matrix3, t.translation);
    let v = [
        m.x_axis.x, m.y_axis.x, m.z_axis.x, p.x, m.x_axis.y, m.y_axis.y, m.z_axis.y, p.y, m.x_axis.z, m.y_axis.z,
        m.z_axis.z, p.z,
    ];
    v.iter().map(|x| format!("{:.9e}", if *x == 0.0 { 0.0 } else { *x })).collect::<Vec<_>>().join(" ")
}

/// `calib.txt`: identity P0-P3 and `Tr` (parent module docs).
const CALIB: &str = "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nP1: 1 0 0 0 0 1 0 0 0 0 1 0\nP2: 1 0 0 0 0 1 0 0 0 0 1 0\n\
P3: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 1 0 0 0 0 1 0 0 0 0 1 0\n";

/// What a run did (printed as JSON).
#[derive(serde::Serialize)]
pub struct Summary {
    out: PathBuf,
    shard: String,
    frames_in_shard: u64,
    frames_written: u64,
    frames_skipped: u64,
    points_written: u64,
    seconds: f64,
    frames_per_s: f64,
    peak_rss_mb: f64,
}

/// Peak resident memory of this process (`VmHWM`), MB; 0 where `/proc` has none.
fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find_map(|l| l.strip_prefix("VmHWM:").map(|v| v.trim().trim_end_matches("kB").trim().to_string()))
        })
        .and_then(|v| v.parse::<f64>().ok())
        .map_or(0.0, |kb| kb / 1024.0)
}

/// The rosbag2 directory of a sequence whose `formats` has `mcap` (`sequences/NN/bag/`).
pub const BAG_DIR: &str = "bag";

/// Checks everything, claims `out` and writes this shard's frames.
pub fn generate(
    config: &DatasetConfig,
    out: &Path,
    shard: Shard,
    resume: bool,
    backend: sim::cast::Backend,
) -> anyhow::Result<Summary> {
    let t0 = Instant::now();
    if shard != Shard::ALL
        && let Some(s) = config.sequences.iter().find(|s| s.formats.iter().any(|f| f == "mcap"))
    {
        bail!(
            "sequence {}: `formats` has `mcap`, a bag of the whole sequence, which one shard cannot write; run it without --shard, or drop mcap",
            s.id
        );
    }
    let mut prepared = prepare(config)?;
    for p in &mut prepared {
        p.scan.backend = backend;
    }
    let manifest = manifest(config, &prepared)?;
    claim(out, &manifest, &super::labels::yaml(&config.split_or_default()))?;
    let mut summary = Summary {
        out: out.to_path_buf(),
        shard: shard.to_string(),
        frames_in_shard: 0,
        frames_written: 0,
        frames_skipped: 0,
        points_written: 0,
        seconds: 0.0,
        frames_per_s: 0.0,
        peak_rss_mb: 0.0,
    };
    // Sequences, and the frames within each, run in parallel (rayon): a run waits on no serial
    // part but the claim and the manifest. Every frame's files are the same bytes in any order.
    let firsts: Vec<u64> = prepared
        .iter()
        .scan(0u64, |first, p| {
            let f = *first;
            *first += p.config.frames;
            Some(f)
        })
        .collect();
    let counts = prepared
        .par_iter()
        .zip(firsts.par_iter())
        .map(|(p, &first)| write_sequence(p, out, shard, first, resume))
        .collect::<anyhow::Result<Vec<Counts>>>()?;
    for c in counts {
        summary.frames_in_shard += c.in_shard;
        summary.frames_written += c.written;
        summary.frames_skipped += c.skipped;
        summary.points_written += c.points;
    }
    summary.seconds = t0.elapsed().as_secs_f64();
    summary.frames_per_s = summary.frames_written as f64 / summary.seconds.max(1e-9);
    summary.peak_rss_mb = peak_rss_mb();
    Ok(summary)
}

/// Writes one sequence's text files and this shard's frames of it (`first`: the global number of
/// its frame 0).
fn write_sequence(p: &Prepared, out: &Path, shard: Shard, first: u64, resume: bool) -> anyhow::Result<Counts> {
    let s = &p.config;
    let seq = out.join("sequences").join(format!("{:02}", s.id));
    let scene = s.spec.load_scene()?;
    let scanner = Scanner::new(&scene.mesh, &p.rig, p.scan.clone())?;
    let single = p.rig.sensors.len() == 1;
    let vehicle_from_sensor = p.rig.sensors[0].mount.vehicle_from_sensor();
    let cloud_from_vehicle = single.then(|| vehicle_from_sensor.inverse());
    let vehicle_from_cloud =
        if single { DAffine3::from_mat4(glam::Mat4::from(vehicle_from_sensor).as_dmat4()) } else { DAffine3::IDENTITY };
    let mut dirs = vec![seq.join("velodyne"), seq.join("labels")];
    dirs.extend(s.formats.iter().filter(|f| *f != "mcap").map(|f| seq.join(f)));
    for d in &dirs {
        std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
    }
    // Poses and times of every frame (the same bytes from every shard).
    let world_from_cloud = |k: usize| world_from_vehicle(&scanner.frame_start_pose(k)) * vehicle_from_cloud;
    let cloud0_from_world = world_from_cloud(0).inverse();
    let frames = s.frames as usize;
    let poses: String = (0..frames).map(|k| row_major(&(cloud0_from_world * world_from_cloud(k))) + "\n").collect();
    let period = scanner.frame_period_s();
    let times: String = (0..frames).map(|k| format!("{:.6e}\n", k as f64 * period)).collect();
    write_bytes_atomic(&seq.join("poses.txt"), poses.as_bytes())?;
    write_bytes_atomic(&seq.join("times.txt"), times.as_bytes())?;
    write_bytes_atomic(&seq.join("calib.txt"), CALIB.as_bytes())?;
    // The bag (`formats` has `mcap`): the whole sequence in our layout, written with every frame;
    // a resumed run keeps a finished bag and otherwise rescans the sequence's frames for it.
    let bag_dir = seq.join(BAG_DIR);
    let topics = sim::io::ros2::scan::sensor_topics(&p.rig);
    let mut bag = match s.formats.iter().any(|f| f == "mcap") && !(resume && bag_dir.join("metadata.yaml").is_file()) {
        true => {
            let mut b = sim::io::ros2::BagWriter::create(&bag_dir)?;
            sim::io::ros2::scan::write_static(&mut b, &topics)?;
            Some(b)
        }
        false => None,
    };
    let write_frame = |k: usize, frame: &sim::scan::Frame| -> anyhow::Result<u64> {
        let stem = format!("{k:06}");
        let (bin_bytes, label_bytes, n) = sim::io::kitti::encode(&frame.cloud, cloud_from_vehicle.as_ref())?;
        write_bytes_atomic(&seq.join("velodyne").join(format!("{stem}.bin")), &bin_bytes)?;
        for f in s.formats.iter().filter(|f| *f != "mcap") {
            let path = seq.join(f).join(format!("{stem}.{f}"));
            let format = sim::io::formats::Format::parse_field(f, "formats")?;
            sim::io::formats::write_file(&path, &frame.cloud, format, sim::io::pcd::PcdLayout::Groundtruth, None)?;
        }
        // Last: the frame is complete once its `.label` exists.
        write_bytes_atomic(&seq.join("labels").join(format!("{stem}.label")), &label_bytes)?;
        Ok(n as u64)
    };
    // A scanned frame checked against device faults and given the sequence's variations.
    let finish_frame = |frame: &mut sim::scan::Frame| -> anyhow::Result<()> {
        crate::cli::common::check_device(scanner.caster())?;
        vary(&mut frame.cloud, s, frame.index)
    };
    let scan_frame = |k: usize| -> anyhow::Result<sim::scan::Frame> {
        let mut frame = scanner.frame(k);
        finish_frame(&mut frame)?;
        Ok(frame)
    };
    let mine: Vec<usize> = (0..frames).filter(|&k| shard.contains(first + k as u64)).collect();
    let done = |k: usize| {
        let stem = format!("{k:06}");
        seq.join("labels").join(format!("{stem}.label")).is_file()
            && seq.join("velodyne").join(format!("{stem}.bin")).is_file()
    };
    let mut counts = Counts { in_shard: mine.len() as u64, ..Counts::default() };
    match bag.as_mut() {
        // A device caster: the frames cast ahead in a pipeline (several per device call), each
        // written on the pool while the next ones are measured.
        None if scanner.caster().prefers_frames() => {
            let todo: Vec<usize> = mine.iter().copied().filter(|&k| !(resume && done(k))).collect();
            counts.skipped = (mine.len() - todo.len()) as u64;
            let written = std::sync::Mutex::new(Vec::new());
            // Frames waiting to be written at most (beyond it this thread writes the frame itself),
            // so a slow disk cannot pile up frames in memory.
            let (pending, max_pending) = (std::sync::atomic::AtomicUsize::new(0), 2 * rayon::current_num_threads());
            let cast = rayon::scope(|scope| {
                scanner.scan_frames(todo.iter().copied(), |mut frame| -> anyhow::Result<()> {
                    finish_frame(&mut frame)?;
                    let (written, write_frame, pending) = (&written, &write_frame, &pending);
                    let write = move |frame: sim::scan::Frame| {
                        let result = write_frame(frame.index, &frame);
                        written.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(result);
                    };
                    if pending.load(std::sync::atomic::Ordering::Relaxed) >= max_pending {
                        write(frame);
                    } else {
                        pending.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        scope.spawn(move |_| {
                            write(frame);
                            pending.fetch_sub(1, std::sync::atomic::Ordering::Relaxed);
                        });
                    }
                    Ok(())
                })
            });
            let points = written
                .into_inner()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .into_iter()
                .collect::<anyhow::Result<Vec<u64>>>()?;
            cast?;
            counts.written = points.len() as u64;
            counts.points = points.iter().sum();
        }
        // Frames in parallel, each written as it is made.
        None => {
            let todo: Vec<usize> = mine.iter().copied().filter(|&k| !(resume && done(k))).collect();
            counts.skipped = (mine.len() - todo.len()) as u64;
            let points =
                todo.par_iter().map(|&k| write_frame(k, &scan_frame(k)?)).collect::<anyhow::Result<Vec<u64>>>()?;
            counts.written = points.len() as u64;
            counts.points = points.iter().sum();
        }
        // The bag takes the frames in order: cast in parallel a batch at a time, then write.
        Some(b) => {
            for batch in mine.chunks(rayon::current_num_threads().max(1) * 2) {
                let made = batch.par_iter().map(|&k| scan_frame(k)).collect::<anyhow::Result<Vec<_>>>()?;
                for (&k, frame) in batch.iter().zip(&made) {
                    counts.points += write_frame(k, frame)?;
                    counts.written += 1;
                    sim::io::ros2::scan::write_frame(
                        b,
                        &frame.cloud,
                        &topics,
                        sim::io::pcd::PcdLayout::Groundtruth,
                        frame.start_time_s,
                        &frame.world_from_vehicle,
                    )?;
                }
            }
        }
    }
    if let Some(b) = bag {
        b.finish()?;
    }
    Ok(counts)
}

/// What one sequence's run did.
#[derive(Default)]
struct Counts {
    in_shard: u64,
    written: u64,
    skipped: u64,
    points: u64,
}
