//! `groundtruth bench raycast`: ray casting speed of a caster backend on a scene or mesh, with the
//! rays of a rig or of a raw ray file. Prints one JSON object.
//!
//! Sources of geometry: `--scene NAME` (the scene library through `common::load_scene_full`, or
//! `fixture-terrain`, the 1.3 M-triangle benchmark terrain of `sim::cast::fixture`) or
//! `--mesh FILE.ply` (binary or ASCII PLY, read by `sim::scene::ply::read_mesh`).
//! Sources of rays: `--rig NAME` (every sensor's firing pattern placed by its mount, range limited to
//! the sensor's maximum range, the vehicle on the scene's ground at the origin, moving 1 m along +x per
//! frame), `--rig fixture-128x2048` (the fixture LiDAR, unlimited range) or `--rays FILE` (raw
//! little-endian `f32` records `ox oy oz dx dy dz`, 24 bytes each, cast with unlimited range or
//! `--max-range-m`; the same rays are cast once per frame).

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::cli::common::FIXTURE_TERRAIN;
use anyhow::{Context, bail};
use glam::{Affine3A, Vec3};
use sim::cast::{Backend, Beam, BeamSet, Ray, fixture};

/// Rig name of the benchmark fixture LiDAR.
const FIXTURE_RIG: &str = "fixture-128x2048";
/// Bytes per record of a ray file.
const RAY_RECORD_BYTES: usize = 24;
/// Largest accepted frame count.
const MAX_FRAMES: usize = 10_000;
/// Largest accepted ray count (all frames together).
const MAX_RAYS: usize = 1 << 31;

/// Arguments of `groundtruth bench raycast`.
#[derive(clap::Args, Debug)]
#[command(group(clap::ArgGroup::new("geometry").required(true).args(["scene", "mesh"])))]
#[command(group(clap::ArgGroup::new("source").required(true).args(["rig", "rays"])))]
pub struct Args {
    /// Scene name or TOML file (or `fixture-terrain`, the 1.3 M-triangle benchmark terrain).
    #[arg(long)]
    scene: Option<String>,
    /// A PLY triangle mesh to cast against.
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// Rig name or TOML file (or `fixture-128x2048`, the benchmark LiDAR).
    #[arg(long)]
    rig: Option<String>,
    /// Raw ray file: little-endian f32 records `ox oy oz dx dy dz` (24 bytes per ray).
    #[arg(long)]
    rays: Option<PathBuf>,
    /// Frames to cast (1..=10000).
    #[arg(long, default_value_t = 4)]
    frames: usize,
    /// Worker threads (0 = all cores).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Caster backend.
    #[arg(long, value_enum, default_value_t = BackendArg::Bvh)]
    backend: BackendArg,
    /// Seed of a procedural scene.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Range limit for `--rays` files, metres (default: unlimited).
    #[arg(long)]
    max_range_m: Option<f32>,
}

/// The `--backend` values.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum BackendArg {
    /// obvhs BVH (production).
    Bvh,
    /// parry3d BVH (reference).
    Parry,
    /// wgpu compute shaders (feature `gpu`; the adapter as `WGPU_BACKEND` / `WGPU_ADAPTER_NAME` choose).
    Gpu,
}

/// Runs the benchmark and prints one JSON object.
pub fn run(a: Args) -> anyhow::Result<()> {
    if a.frames == 0 || a.frames > MAX_FRAMES {
        bail!("invalid value for `--frames`: {} (allowed: 1 ..= {MAX_FRAMES})", a.frames);
    }
    if let Some(r) = a.max_range_m
        && !(r.is_finite() && r > 0.0)
    {
        bail!("invalid value for `--max-range-m`: {r} (allowed: finite, > 0)");
    }
    let (mesh, ego_ground_z_m, geometry) = match (&a.scene, &a.mesh) {
        (Some(s), _) => {
            let l = crate::cli::common::load_scene_full(s, a.seed)
                .with_context(|| format!("scene `{s}` (the benchmark also knows `{FIXTURE_TERRAIN}`)"))?;
            (l.mesh, l.ego_ground_z_m, s.clone())
        }
        (None, Some(p)) => (sim::scene::ply::read_mesh(p)?, 0.0, p.display().to_string()),
        (None, None) => bail!("give --scene NAME or --mesh FILE.ply"),
    };
    // Ray files cast the same rays every frame (a standing sensor); rigs move 1 m per frame and are
    // cast from poses (rays made by the caster: on the device for the GPU).
    let source = match (&a.rig, &a.rays) {
        (Some(r), _) if r == FIXTURE_RIG => Source::Beams(fixture::lidar_beams(), fixture::lidar_poses(a.frames)),
        (Some(r), _) => rig_beams(r, a.frames, ego_ground_z_m)
            .with_context(|| format!("rig `{r}` (the benchmark also knows `{FIXTURE_RIG}`)"))?,
        (None, Some(p)) => {
            let one = read_ray_file(p, a.max_range_m.unwrap_or(f32::INFINITY))?;
            if one.len().saturating_mul(a.frames) > MAX_RAYS {
                bail!("{}: {} rays x {} frames is more than {MAX_RAYS} rays", p.display(), one.len(), a.frames);
            }
            Source::Rays(one)
        }
        (None, None) => bail!("give --rig NAME or --rays FILE"),
    };
    let ray_count = match &source {
        Source::Rays(one) => one.len() * a.frames,
        Source::Beams(beams, poses) => beams.beams().len() * beams.frames_in(poses),
    };
    let backend = match a.backend {
        BackendArg::Bvh => Backend::Bvh,
        BackendArg::Parry => Backend::Parry,
        BackendArg::Gpu => Backend::Gpu,
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(a.threads).build().context("starting the thread pool")?;
    let threads = pool.current_num_threads();
    let t0 = Instant::now();
    let caster = pool.install(|| backend.build(&mesh))?;
    let build_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let cpu0 = process_cpu_s();
    // Frame by frame, as a scan casts: a standing sensor's rays under one key, so a device backend
    // keeps them and uploads them once; a moving rig's beams from each frame's pose, as many frames
    // per call as a scan's pipeline casts together.
    let key = sim::cast::new_ray_set_key();
    let hits: Vec<Option<sim::cast::Hit>> = pool.install(|| match &source {
        // Frame by frame; the hits of the first frame are kept as they come (a copy of all hits
        // into one vector grown by doubling was 5-10 % of the casting time of a 4 M-ray frame).
        Source::Rays(one) => {
            let mut hits = caster.cast_all_resident(key, one);
            for _ in 1..a.frames {
                hits.extend(caster.cast_all_resident(key, one));
            }
            hits
        }
        Source::Beams(beams, poses) => {
            poses.chunks(beams.frames_per_call()).flat_map(|p| caster.cast_beams(beams, p)).collect()
        }
    });
    let cast_s = t1.elapsed().as_secs_f64();
    crate::cli::common::check_device(caster.as_ref())?;
    let cast_cpu_s = process_cpu_s().zip(cpu0).map(|(b, a)| b - a);
    let hit_count = hits.iter().filter(|h| h.is_some()).count();
    let json = serde_json::json!({
        "backend": backend.name(),
        "geometry": geometry,
        "source": a.rig.clone().unwrap_or_else(|| a.rays.as_ref().map(|p| p.display().to_string()).unwrap_or_default()),
        "triangles": mesh.len(),
        "frames": a.frames,
        "threads": threads,
        "rays": ray_count,
        "hits": hit_count,
        "build_s": build_s,
        "cast_s": cast_s,
        "rays_per_s": ray_count as f64 / cast_s.max(1e-12),
        // CPU time of the whole process while casting (Linux; null elsewhere): on a shared,
        // loaded machine, rays per CPU-second per thread shows the speed the wall clock hides.
        "cast_cpu_s": cast_cpu_s,
        "rays_per_cpu_s": cast_cpu_s.filter(|&c| c > 0.0).map(|c| ray_count as f64 / c),
        "device": caster.device_stats().map(|d| device_json(&d, ray_count)),
    });
    println!("{json}");
    Ok(())
}

/// A device backend's counters and the split of its time: the kernel, the copies of rays up and
/// results down on the device (timestamp queries; null where the adapter has none), and the host's
/// time waiting for the device.
fn device_json(d: &sim::cast::DeviceStats, rays: usize) -> serde_json::Value {
    serde_json::json!({
        "adapter": adapter(),
        "batches": d.batches,
        "upload_bytes": d.upload_bytes,
        "readback_bytes": d.readback_bytes,
        "resident_uploads": d.resident_uploads,
        "cpu_fallbacks": d.cpu_fallbacks,
        "kernel_s": d.kernel_s,
        "upload_s": d.upload_s,
        "readback_s": d.readback_s,
        "kernel_rays_per_s": d.kernel_s.filter(|&k| k > 0.0).map(|k| rays as f64 / k),
        "host_wait_s": d.wait_s,
        "host_call_s": d.wall_s,
    })
}

/// The GPU adapter's description, or null.
fn adapter() -> Option<String> {
    sim::cast::gpu_adapter().ok()
}

/// User + system CPU seconds of this process so far (Linux `/proc/self/stat`), or `None`.
fn process_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let fields: Vec<&str> = stat.get(stat.rfind(')')? + 2..)?.split(' ').collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// What a benchmark casts: the same rays every frame, or beams placed by one pose per frame.
enum Source {
    Rays(Vec<Ray>),
    Beams(BeamSet, Vec<Affine3A>),
}

/// The beams of rig `name` in the vehicle frame (each sensor's firings placed by its mount, range
/// limited to the sensor's maximum range) and the vehicle's pose in each of `frames` frames: on the
/// ground at `(frame * 1 m, 0, ego_ground_z_m)`.
fn rig_beams(name: &str, frames: usize, ego_ground_z_m: f32) -> anyhow::Result<Source> {
    let rig = crate::cli::common::load_rig(name)?;
    let mut beams = Vec::new();
    for s in &rig.sensors {
        let vehicle_from_sensor = s.mount.vehicle_from_sensor();
        let t_max_m = s.spec.measurement().max_range_m;
        for f in s.spec.pattern().firings.iter().flatten() {
            let origin_in_sensor = vehicle_from_sensor.transform_point3(f.origin_in_sensor);
            let dir_in_sensor = vehicle_from_sensor.transform_vector3(f.dir_in_sensor).normalize();
            beams.push(Beam { origin_in_sensor, dir_in_sensor, t_max_m, pose: 0, pose_blend: 0.0, side_offset: 0.0 });
        }
    }
    if beams.len().saturating_mul(frames) > MAX_RAYS {
        bail!("rig `{name}`: {} rays x {frames} frames is more than {MAX_RAYS} rays", beams.len());
    }
    let poses = (0..frames)
        .map(|k| Affine3A::from_translation(Vec3::new(k as f32 * fixture::FRAME_STEP_M, 0.0, ego_ground_z_m)))
        .collect();
    Ok(Source::Beams(BeamSet::new(beams, 1).with_context(|| format!("rig `{name}`"))?, poses))
}

/// Reads a raw ray file (see the module doc); directions are normalised, so `t` is metres.
fn read_ray_file(path: &Path, t_max: f32) -> anyhow::Result<Vec<Ray>> {
    let bytes = std::fs::read(path).with_context(|| format!("reading ray file {}", path.display()))?;
    parse_rays(&bytes, t_max).map_err(|m| anyhow::anyhow!("{}: {m}", path.display()))
}

/// Parses raw ray records; the error message says which record is wrong and why.
fn parse_rays(bytes: &[u8], t_max: f32) -> Result<Vec<Ray>, String> {
    if bytes.is_empty() {
        return Err("no rays (empty file)".into());
    }
    if !bytes.len().is_multiple_of(RAY_RECORD_BYTES) {
        return Err(format!(
            "length {} bytes is not a multiple of {RAY_RECORD_BYTES} (records of 6 little-endian f32: ox oy oz dx dy dz)",
            bytes.len()
        ));
    }
    bytes
        .chunks_exact(RAY_RECORD_BYTES)
        .enumerate()
        .map(|(i, rec)| {
            let v: Vec<f32> = rec.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
            if v.iter().any(|x| !x.is_finite()) {
                return Err(format!("ray {i} has a non-finite value {v:?}"));
            }
            let dir = Vec3::new(v[3], v[4], v[5]);
            let len = dir.length();
            if !(len.is_finite() && len > 1e-20) {
                return Err(format!("ray {i} has a zero direction"));
            }
            Ok(Ray { origin: Vec3::new(v[0], v[1], v[2]), dir: dir / len, t_max })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(v: [f32; 6]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    #[test]
    fn parses_and_normalises_rays() {
        let mut b = record([1.0, 2.0, 3.0, 0.0, 0.0, -2.0]);
        b.extend(record([0.0, 0.0, 0.0, 3.0, 4.0, 0.0]));
        let rays = parse_rays(&b, 50.0).unwrap();
        assert_eq!(rays.len(), 2);
        assert_eq!(rays[0].origin, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(rays[0].dir, Vec3::new(0.0, 0.0, -1.0));
        assert!((rays[1].dir - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-6);
        assert_eq!(rays[1].t_max, 50.0);
    }

    #[test]
    fn refuses_bad_records() {
        let good = record([0.0, 0.0, 1.0, 1.0, 0.0, 0.0]);
        assert!(parse_rays(&good[..23], 1.0).unwrap_err().contains("not a multiple of 24"));
        assert!(parse_rays(&[], 1.0).unwrap_err().contains("empty"));
        let mut b = good.clone();
        b.extend(record([0.0, f32::NAN, 0.0, 1.0, 0.0, 0.0]));
        assert!(parse_rays(&b, 1.0).unwrap_err().contains("ray 1 has a non-finite"));
        assert!(
            parse_rays(&record([0.0, 0.0, 0.0, 0.0, 0.0, 0.0]), 1.0)
                .unwrap_err()
                .contains("ray 0 has a zero direction")
        );
    }
}
