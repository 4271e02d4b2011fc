//! `groundtruth bench classify`: scans a scene with a rig and times one method per frame on one
//! thread, printing one JSON object: frames, grid size, and mean / min milliseconds per frame for
//! features, clustering (candidates, clustering and cluster rules) and the whole classification.
//! Methods that do not report stages (ransac, grid) give only the total.
//!
//! With `--input FILE|DIR` it times the whole path on files instead (`.pcd` and `.bin`, a directory's
//! files in name order): read, order (unfolding or the beam table of `--rig`, as `classify` does)
//! and classify, each file `--repeats` times, and prints per file the grid, the ordering path and
//! its counts, the file's layout and what decided it (`layout`: `kitti-bin`, `nuscenes-bin`, `pcd`,
//! ...; `layout_by`: `name`, `content` or `flag`), and mean / min milliseconds of `read_ms`, `order_ms`, `classify_ms` and `total_ms`,
//! plus the same over all files. A driver's organized PCD has its rows put in order as it is
//! decoded: its `read_ms` is the file's mapping and header, its `order_ms` the decoding in order.
//! Run it under `taskset -c 0` for one core.

use std::time::Instant;

use anyhow::Context;
use classifier::FrameInput;
use classifier::recording::{self, FrameReader, Ordering, Recording};

/// The rig scanned when `--rig` is not given.
const SCANNED_RIG: &str = "os1-128-roof";

/// Arguments of `groundtruth bench classify`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Method name.
    #[arg(long, default_value = "nitsch")]
    method: String,
    /// Scene name or TOML file.
    #[arg(long, default_value = "city")]
    scene: String,
    /// Rig name or TOML file: the scanned rig (default `os1-128-roof`), or with `--input` the
    /// sensor of the files; without it, files are ordered on the sensor recovered from their data,
    /// as `classify` does without `--rig`.
    #[arg(long)]
    rig: Option<String>,
    /// Frames to scan.
    #[arg(long, default_value_t = 3)]
    frames: usize,
    /// Times each frame is classified (the fastest counts toward `min`).
    #[arg(long, default_value_t = 5)]
    repeats: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Time real files instead of a scan: a `.pcd` / `.ply` / `.las` / `.bin` file or a directory of
    /// them, or a ROS 2 bag (`.mcap` or rosbag2 directory; `--topic`, or its one PointCloud2 topic).
    #[arg(long)]
    input: Option<std::path::PathBuf>,
    /// With `--input`: the records of headerless `.bin` files (as `classify --layout`; default: by
    /// name and content). Each file's layout and what decided it are in the JSON.
    #[arg(long, value_enum)]
    layout: Option<super::common::LayoutArg>,
    /// With a bag as `--input`: the PointCloud2 topic.
    #[arg(long)]
    topic: Option<String>,
    /// With `--input`: the sensor's calibration file, as `classify --calibration`.
    #[arg(long)]
    calibration: Option<std::path::PathBuf>,
    /// Trained model file for `mcdaniel` or `learned` (default: the bundled model).
    #[arg(long)]
    model: Option<std::path::PathBuf>,
    /// Worker threads of methods that run stages in parallel (`mcdaniel`; 0 = all cores). Nitsch,
    /// RANSAC and grid run on one thread whatever this says.
    #[arg(long, default_value_t = 0)]
    threads: usize,
}

fn stats(v: &[f64]) -> serde_json::Value {
    if v.is_empty() {
        serde_json::Value::Null
    } else {
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        serde_json::json!({ "mean": mean, "min": min })
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Times read + order + classify on a bag's messages: each repeat is one pass over the bag (the
/// MCAP read and its chunks' decompression included), and per message `read_ms` (the CDR decode
/// and the PointCloud2's header; a driver's organized cloud is decoded in order as it is ordered),
/// `order_ms` and `classify_ms`; `total_ms` per message is the pass's time over its messages.
fn run_bag(args: &Args, recording: &Recording) -> anyhow::Result<()> {
    let topic = recording.topic().unwrap_or_default();
    let rig = args.rig.as_deref();
    let setup = recording::sensor_setup(rig, args.calibration.as_deref())?;
    let mut method = super::common::method(&args.method, args.seed, args.model.as_deref())?;
    let (mut read, mut order, mut cls, mut per_message) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut messages, mut warnings) = (0, Vec::new());
    for _ in 0..args.repeats.max(1) {
        let t_pass = Instant::now();
        let mut frames = recording.frames(Ordering::Ordered(&setup))?;
        let mut count = 0usize;
        let mut t0 = Instant::now();
        while let Some(frame) = frames.next_frame() {
            let frame = frame?;
            let t2 = Instant::now();
            method.classify(&FrameInput { index: frame.index, cloud: frame.cloud, world_from_vehicle: None })?;
            cls.push(ms(t2));
            // The CDR decode and the message's header count as reading, as a file's read does.
            read.push(frame.read_ms);
            order.push((t2 - t0).as_secs_f64() * 1e3 - frame.read_ms);
            count += 1;
            t0 = Instant::now();
        }
        messages = count;
        warnings = frames.warnings().to_vec();
        per_message.push(ms(t_pass) / messages.max(1) as f64);
    }
    let out = serde_json::json!({
        "method": args.method,
        "input": recording.path().display().to_string(),
        "topic": topic,
        "rig": rig,
        "messages": messages,
        "repeats": args.repeats.max(1),
        "threads": 1,
        "read_ms": stats(&read),
        "order_ms": stats(&order),
        "classify_ms": stats(&cls),
        "total_ms": stats(&per_message),
        "warnings": warnings,
    });
    println!("{}", serde_json::to_string_pretty(&out)?);
    Ok(())
}

/// Times read + order + classify on files.
fn run_files(args: &Args, recording: &Recording) -> anyhow::Result<()> {
    let input = recording.path();
    let files: Vec<std::path::PathBuf> = recording.files().iter().map(|f| f.path.clone()).collect();
    let rig = args.rig.as_deref();
    let setup = recording::sensor_setup(rig, args.calibration.as_deref())?;
    let repeats = args.repeats.max(1);
    let mut method = super::common::method(&args.method, args.seed, args.model.as_deref())?;
    let (mut all_read, mut all_order, mut all_cls, mut all_total) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut per_file = Vec::new();
    let mut all_stages: Vec<(&'static str, Vec<f64>)> = Vec::new();
    // One reader for every file and repeat, as `classify` reads a sequence: buffers are reused.
    let mut reader = FrameReader::default();
    reader.set_layout_choice(recording.layout_choice());
    for (index, path) in files.iter().enumerate() {
        let (mut read, mut order, mut cls, mut total) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut file_stages: Vec<(&'static str, Vec<f64>)> = Vec::new();
        let mut last = None;
        for _ in 0..repeats {
            let t0 = Instant::now();
            let read_ms = reader.read(path, &setup)?;
            let t2 = Instant::now();
            let out = method.classify(&FrameInput { index, cloud: reader.cloud(), world_from_vehicle: None })?;
            let bytes = classifier::ordering::decisions_per_input_point(reader.report(), &out);
            cls.push(ms(t2));
            total.push(ms(t0));
            for (name, s) in method.named_stage_times() {
                match file_stages.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, v)) => v.push(s * 1e3),
                    None => file_stages.push((name, vec![s * 1e3])),
                }
            }
            read.push(read_ms);
            order.push((t2 - t0).as_secs_f64() * 1e3 - read_ms);
            last = Some((bytes.iter().filter(|&&b| b == 1).count(), bytes.len()));
        }
        let (ground, points) = last.expect("one repeat");
        let frame = &reader;
        let (layout, layout_by) = frame.layout();
        let mut entry = serde_json::json!({
            "file": path.display().to_string(),
            "layout": layout,
            "layout_by": layout_by,
            "points": points,
            "ground": ground,
            "rows": frame.cloud().rows,
            "cols": frame.cloud().cols,
            "planes": frame.cloud().planes,
            "ordering": frame.report().map(|r| serde_json::to_value(r).unwrap_or_default()),
            "read_ms": stats(&read),
            "order_ms": stats(&order),
            "classify_ms": stats(&cls),
            "total_ms": stats(&total),
        });
        for (name, v) in &file_stages {
            entry[format!("{name}_ms")] = stats(v);
        }
        for (name, v) in file_stages {
            match all_stages.iter_mut().find(|(n, _)| *n == name) {
                Some((_, all)) => all.extend(v),
                None => all_stages.push((name, v)),
            }
        }
        per_file.push(entry);
        all_read.extend(read);
        all_order.extend(order);
        all_cls.extend(cls);
        all_total.extend(total);
    }
    let mut out = serde_json::json!({
        "method": args.method,
        "input": input.display().to_string(),
        "rig": rig,
        "files": per_file.len(),
        "repeats": repeats,
        "threads": 1,
        "read_ms": stats(&all_read),
        "order_ms": stats(&all_order),
        "classify_ms": stats(&all_cls),
        "total_ms": stats(&all_total),
        "per_file": per_file,
    });
    for (name, v) in &all_stages {
        out[format!("{name}_ms")] = stats(v);
    }
    println!("{}", serde_json::to_string_pretty(&out)?);
    Ok(())
}

/// Runs the classification benchmark and prints one JSON object.
pub fn run(args: Args) -> anyhow::Result<()> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(args.threads).build().context("starting the thread pool")?;
    pool.install(|| run_in_pool(&args))
}

/// The benchmark inside the thread pool of `--threads`.
fn run_in_pool(args: &Args) -> anyhow::Result<()> {
    if let Some(input) = &args.input {
        let recording = Recording::open(input, args.topic.as_deref())?.with_layout(args.layout.map(Into::into))?;
        if recording.topic().is_some() {
            return run_bag(args, &recording);
        }
        return run_files(args, &recording);
    }
    if args.layout.is_some() {
        anyhow::bail!("--layout applies to files given with --input");
    }
    let frames = super::common::scan_spec(&groundtruth_scenario::ScanSpec {
        scene: args.scene.clone(),
        rig: args.rig.clone().unwrap_or_else(|| SCANNED_RIG.to_string()),
        seed: args.seed,
        frames: args.frames as u64,
        ..Default::default()
    })?;
    let mut method = super::common::method(&args.method, args.seed, args.model.as_deref())?;
    let repeats = args.repeats.max(1);
    let mut total = Vec::new();
    // Stage name -> milliseconds per classification, in pipeline order.
    let mut stages: Vec<(&'static str, Vec<f64>)> = Vec::new();
    for f in &frames {
        for _ in 0..repeats {
            let input = FrameInput { index: f.index, cloud: &f.cloud, world_from_vehicle: Some(f.world_from_vehicle) };
            let t = Instant::now();
            let out = method.classify(&input)?;
            total.push(t.elapsed().as_secs_f64() * 1e3);
            std::hint::black_box(out);
            for (name, s) in method.named_stage_times() {
                match stages.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, v)) => v.push(s * 1e3),
                    None => stages.push((name, vec![s * 1e3])),
                }
            }
        }
    }
    let first = &frames[0].cloud;
    let mut out = serde_json::json!({
        "method": args.method,
        "scene": args.scene,
        "rig": args.rig.as_deref().unwrap_or(SCANNED_RIG),
        "frames": frames.len(),
        "repeats": repeats,
        "rows": first.rows,
        "cols": first.cols,
        "planes": first.planes,
        "returns": first.returns(),
        "threads": if method.named_stage_times().len() > 2 { rayon::current_num_threads() } else { 1 },
        "total_ms": stats(&total),
    });
    for (name, v) in &stages {
        out[format!("{name}_ms")] = stats(v);
    }
    println!("{}", serde_json::to_string_pretty(&out)?);
    Ok(())
}
