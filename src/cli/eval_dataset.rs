//! `groundtruth eval --dataset DIR`: scores methods on a labelled recording in the SemanticKITTI
//! layout (real, or written by `groundtruth dataset`) or a nuScenes-lidarseg folder
//! ([`classifier::dataset::layout`]; its JSON says `"format": "nuscenes-lidarseg"`; a frame read
//! in another layout than its name says is listed under `"layouts"`), every frame read through the
//! real-recordings path (`--rig`, `--calibration` as `classify` takes them), under a named
//! protocol ([`classifier::dataset::protocol`]). Prints a table (pooled precision, recall, F1,
//! IoU, accuracy; the frame mean of F1; the worst frame; F1 by range band; milliseconds per
//! frame); `--json FILE` writes every number, per frame too, atomically; `--out DIR` draws each
//! frame's outcome from above per method (`DIR/METHOD/SEQ_FRAME.png`: true, false and missed
//! ground; points the protocol leaves out are not drawn).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use classifier::dataset::score::{RANGE_BANDS, band_name};
use classifier::dataset::{
    DatasetLayout, EvalOptions, FrameFormat, FrameView, MethodScore, Protocol, evaluate, report,
};
use classifier::recording::{self, InputLayout, LayoutBasis, LayoutChoice, Ordering, Recording};
use classifier::registry::{MethodOptions, ResolvedMethod};

/// What `eval --dataset` needs from the command line.
pub struct DatasetArgs<'a> {
    /// The dataset (root or one sequence).
    pub dir: &'a Path,
    /// Only these sequences.
    pub sequences: Option<Vec<String>>,
    /// Method names.
    pub methods: Vec<String>,
    /// Rig ordering the frames (name or file).
    pub rig: Option<&'a str>,
    /// The sensor's calibration file.
    pub calibration: Option<&'a Path>,
    /// Protocol name.
    pub protocol: &'a str,
    /// Ground classes replacing the protocol's.
    pub ground: Option<&'a str>,
    /// Classes left out beside the protocol's.
    pub ignore: Option<&'a str>,
    /// Sensor height for the `patchwork` protocol, metres.
    pub sensor_height_m: f32,
    /// Frames per sequence at most.
    pub max_frames: Option<usize>,
    /// JSON file.
    pub json: Option<&'a Path>,
    /// Picture folder.
    pub out: Option<&'a Path>,
    /// Model file for the learned methods.
    pub model: Option<&'a Path>,
    /// Print a line per frame.
    pub details: bool,
    /// With a bag as the dataset: the PointCloud2 topic (its clouds carry a `label` field; default:
    /// the bag's one PointCloud2 topic).
    pub topic: Option<&'a str>,
    /// The records of the dataset's `.bin` files (`--layout`).
    pub layout: Option<classifier::recording::LayoutChoice>,
}

/// Parses the class ids of `flag` (`--ground 40,44,...`, `--ignore 110`).
fn parse_classes(flag: &str, text: &str) -> anyhow::Result<Vec<u32>> {
    super::common::split_list(text)
        .iter()
        .map(|s| s.parse::<u32>().with_context(|| format!("{flag}: `{s}` is not a class id (e.g. 40,44,48)")))
        .collect()
}

/// Runs `eval --dataset`.
pub fn run(args: &DatasetArgs<'_>) -> anyhow::Result<()> {
    let mut protocol = Protocol::named(args.protocol, args.sensor_height_m)?;
    if let Some(g) = args.ground {
        protocol = protocol.with_ground(&parse_classes("--ground", g)?)?;
    }
    if let Some(i) = args.ignore {
        protocol = protocol.with_ignored(&parse_classes("--ignore", i)?)?;
    }
    if args.methods.is_empty() {
        bail!("--methods is empty; known: {}", classifier::METHODS.join(", "));
    }
    if args.max_frames == Some(0) {
        bail!("--max-frames 0: allowed 1 or more");
    }
    // Unknown methods and bad models are refused before any frame is read; each model file is
    // read once, every instance (one per sequence) built from it.
    let resolved: Vec<ResolvedMethod> = args
        .methods
        .iter()
        .map(|m| {
            let model = args.model.filter(|_| classifier::takes_model(m));
            classifier::registry::resolve(m, &MethodOptions { seed: 0, model })
        })
        .collect::<Result<_, _>>()?;
    let make = |name: &str| -> classifier::Result<Box<dyn classifier::GroundClassifier + Send>> {
        match resolved.iter().find(|r| r.name() == name) {
            Some(r) => r.build(),
            None => classifier::method_by_name(name, 0),
        }
    };
    if sim::io::ros2::is_bag(args.dir) {
        return run_bag(args, &protocol, &make);
    }
    if args.topic.is_some() {
        bail!("--topic applies to a bag (an .mcap file or a rosbag2 directory); `{}` is none", args.dir.display());
    }
    let layout = DatasetLayout::open(args.dir, args.sequences.as_deref())?;
    if layout.format == FrameFormat::NuscenesLidarseg && args.layout == Some(LayoutChoice::Kitti) {
        bail!(
            "--layout kitti: `{}` is a nuScenes-lidarseg folder, whose `.pcd.bin` sweeps are nuScenes records",
            args.dir.display()
        );
    }
    let setup = recording::sensor_setup(args.rig, args.calibration)?;
    // A dataset of ours, without --rig: each sequence ordered with its own rig and mount.
    let sequence_setups = match (args.rig, args.calibration) {
        (None, None) => super::dataset::manifest_setups(args.dir)?,
        _ => None,
    };
    if let Some(m) = &sequence_setups {
        println!(
            "{}: ordered with each sequence's rig and mount from its manifest ({} sequences)",
            args.dir.display(),
            m.len()
        );
    }
    let frames: usize =
        layout.sequences.iter().map(|s| s.frames.len().min(args.max_frames.unwrap_or(usize::MAX))).sum();
    println!(
        "dataset {}: {} sequence(s), {frames} frame(s); protocol {} (ground {}; left out {}{}; no-returns)",
        args.dir.display(),
        layout.sequences.len(),
        protocol.name,
        join(&protocol.ground),
        join(&protocol.ignored),
        protocol
            .low_vegetation_below_z_m
            .map_or(String::new(), |z| format!("; vegetation below z = {z:.3} m is ground")),
    );
    let options = EvalOptions {
        setup: &setup,
        sequence_setups: sequence_setups.as_ref(),
        protocol: &protocol,
        max_frames_per_sequence: args.max_frames,
        layout: args.layout,
    };
    // Frames whose layout is not a KITTI `.bin` taken by its name: said once each (first method).
    let mut read_as: Vec<serde_json::Value> = Vec::new();
    let sensor_from_vehicle = setup.vehicle_from_sensor.inverse();
    let scores = evaluate(&layout, &args.methods, &make, &options, |view: &FrameView<'_>| {
        let (frame_layout, basis) = view.layout;
        let plain = frame_layout == InputLayout::KittiBin && basis == LayoutBasis::Name;
        if !plain && view.method == args.methods[0] {
            if let Some(line) = super::common::layout_line(view.provenance) {
                println!("{line}");
            }
            read_as.push(serde_json::json!({
                "sequence": view.frame.sequence,
                "frame": view.frame.stem,
                "layout": frame_layout,
                "layout_by": basis,
            }));
        }
        if args.details {
            let c = &view.score.scores.0;
            println!(
                "  {:<12} {}/{}  P {:.4} R {:.4} F1 {:.4}  {:.2} ms  {}",
                view.method,
                view.frame.sequence,
                view.frame.stem,
                c.precision(),
                c.recall(),
                c.f1(),
                view.score.classify_ms,
                view.report.summary()
            );
        }
        if let Some(out) = args.out {
            picture(out, view, &protocol, &sensor_from_vehicle).map_err(|e| {
                classifier::dataset::DatasetError::Invalid {
                    flag: "--out",
                    value: out.display().to_string(),
                    allowed: format!("a writable folder ({e:#})"),
                }
            })?;
        }
        Ok(())
    })?;
    print_table(&scores);
    if let Some(path) = args.json {
        let mut doc = report(args.dir, &protocol, args.rig, args.calibration, &scores);
        // Said only where a frame was not a KITTI `.bin` taken by its name (the SemanticKITTI
        // document is as it was).
        if layout.format != FrameFormat::SemanticKitti {
            doc["format"] = serde_json::json!(layout.format);
        }
        if !read_as.is_empty() {
            doc["layouts"] = serde_json::json!(read_as);
        }
        sim::io::atomic::write_bytes_atomic(path, serde_json::to_string_pretty(&doc)?.as_bytes())?;
        println!("scores written to {}", path.display());
    }
    Ok(())
}

/// `eval --dataset BAG [--topic TOPIC]`: every PointCloud2 message of the topic (default: the bag's
/// one PointCloud2 topic) read as `classify` reads it, scored per return of its grid against its
/// own `label` field (SemanticKITTI ids, as our layouts and most labelled conversions carry them)
/// under the protocol; the vegetation rule of `patchwork` uses the height in the message's frame.
/// A bag cut short is scored up to its last whole message, with a warning (printed, and in the
/// JSON's `warnings`).
fn run_bag(
    args: &DatasetArgs<'_>,
    protocol: &Protocol,
    make: &dyn Fn(&str) -> classifier::Result<Box<dyn classifier::GroundClassifier + Send>>,
) -> anyhow::Result<()> {
    use classifier::dataset::FrameScore;
    if args.layout.is_some() {
        bail!("--layout applies to .bin files, not to a bag");
    }
    let recording = Recording::open(args.dir, args.topic)?;
    let topic = recording.topic().unwrap_or_default();
    if args.out.is_some() {
        bail!("--out (outcome pictures) applies to SemanticKITTI-layout datasets, not to bags");
    }
    let setup = recording::sensor_setup(args.rig, args.calibration)?;
    let sensor_from_vehicle = setup.vehicle_from_sensor.inverse();
    let mut methods = Vec::new();
    for m in &args.methods {
        methods.push(make(m)?);
    }
    let mut scores: Vec<MethodScore> =
        args.methods.iter().map(|m| MethodScore { method: m.clone(), frames: Vec::new() }).collect();
    let mut skipped = 0usize;
    let take = args.max_frames.unwrap_or(usize::MAX);
    let mut frames = recording.frames(Ordering::Ordered(&setup))?;
    while let Some(frame) = frames.next_frame() {
        let frame = match frame {
            Ok(f) => f,
            // Messages come in index order: past the last one asked for, the reading stops.
            Err(e) if e.message_index().is_some_and(|i| i >= take) => break,
            Err(e) if e.is_message() => {
                eprintln!("{e}; skipped");
                skipped += 1;
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        if frame.index >= take {
            break;
        }
        let labelled =
            frame.message.and_then(|m| m.decode().ok()).is_some_and(|pc| pc.fields.iter().any(|f| f.name == "label"));
        if !labelled {
            bail!("`{}` {topic} message {}: no `label` field: scoring needs labels", args.dir.display(), frame.index);
        }
        let cloud = frame.cloud;
        for (method, score) in methods.iter_mut().zip(scores.iter_mut()) {
            let t = std::time::Instant::now();
            let ground =
                method.classify(&classifier::FrameInput { index: frame.index, cloud, world_from_vehicle: None })?;
            let mut fs = FrameScore {
                sequence: topic.to_string(),
                frame: format!("{:06}", frame.index),
                classify_ms: t.elapsed().as_secs_f64() * 1e3,
                ..FrameScore::default()
            };
            for (i, &g) in ground.iter().enumerate() {
                let p = cloud.point_in_vehicle[i];
                if !p.is_finite() || p == glam::Vec3::ZERO {
                    fs.no_returns += u64::from(cloud.has_return(i));
                    continue;
                }
                let q = sensor_from_vehicle.transform_point3(p);
                fs.add(protocol.truth(cloud.label[i].0, q.z), g, q.length());
            }
            if args.details {
                let c = &fs.scores.0;
                println!(
                    "  {:<12} {topic}[{}]  P {:.4} R {:.4} F1 {:.4}",
                    score.method,
                    frame.index,
                    c.precision(),
                    c.recall(),
                    c.f1()
                );
            }
            score.frames.push(fs);
        }
    }
    if scores.first().is_none_or(|s| s.frames.is_empty()) {
        bail!("no message of `{topic}` in `{}` could be scored ({skipped} skipped)", args.dir.display());
    }
    for w in frames.warnings() {
        println!("{w}");
    }
    println!(
        "bag {} topic {topic}: {} message(s) scored, {skipped} skipped; protocol {}",
        args.dir.display(),
        scores.first().map_or(0, |s| s.frames.len()),
        protocol.name
    );
    print_table(&scores);
    if let Some(path) = args.json {
        let mut doc = report(args.dir, protocol, args.rig, args.calibration, &scores);
        if !frames.warnings().is_empty() {
            doc["warnings"] = serde_json::json!(frames.warnings());
        }
        sim::io::atomic::write_bytes_atomic(path, serde_json::to_string_pretty(&doc)?.as_bytes())?;
        println!("scores written to {}", path.display());
    }
    Ok(())
}

fn join(set: &std::collections::BTreeSet<u16>) -> String {
    set.iter().map(u16::to_string).collect::<Vec<_>>().join(",")
}

fn print_table(scores: &[MethodScore]) {
    let bands: Vec<String> = (0..RANGE_BANDS).map(|b| format!("F1 {}", band_name(b))).collect();
    println!(
        "{:<16} {:>9} {:>7} {:>7} {:>7} {:>7} {:>10} {:>14} {:>10} {:>10} {:>10} {:>10} {:>9}",
        "method",
        "precision",
        "recall",
        "F1",
        "IoU",
        "acc",
        "F1 mean",
        "worst F1",
        bands[0],
        bands[1],
        bands[2],
        bands[3],
        "ms/frame"
    );
    for s in scores {
        let p = s.pooled();
        let worst = s.worst_frame().map_or("-".to_string(), |f| format!("{:.4} {}", f.scores.0.f1(), f.frame));
        let by = s.by_range();
        println!(
            "{:<16} {:>9.4} {:>7.4} {:>7.4} {:>7.4} {:>7.4} {:>10.4} {:>14} {:>10.4} {:>10.4} {:>10.4} {:>10.4} {:>9.2}",
            s.method,
            p.precision(),
            p.recall(),
            p.f1(),
            p.iou(),
            p.accuracy(),
            s.frame_means().f1,
            worst,
            by[0].f1(),
            by[1].f1(),
            by[2].f1(),
            by[3].f1(),
            s.mean_classify_ms()
        );
    }
}

/// The frame's outcome from above: the cells the protocol scores, coloured by outcome.
fn picture(
    out: &Path,
    view: &FrameView<'_>,
    protocol: &Protocol,
    sensor_from_vehicle: &glam::Affine3A,
) -> anyhow::Result<()> {
    let mut cloud = view.cloud.clone();
    for i in 0..cloud.len() {
        let p = cloud.point_in_vehicle[i];
        if !p.is_finite() {
            continue;
        }
        match protocol.truth(cloud.label[i].0, sensor_from_vehicle.transform_point3(p).z) {
            Some(t) => cloud.ground[i] = t,
            None => cloud.point_in_vehicle[i] = glam::Vec3::NAN,
        }
    }
    let coloring = sim::picture::Coloring::Outcome { predicted_ground: view.ground };
    let img = sim::picture::render_bev(&cloud, &coloring, &sim::picture::BevOptions::default())?;
    let dir: PathBuf = out.join(view.method);
    std::fs::create_dir_all(&dir).with_context(|| format!("creating `{}`", dir.display()))?;
    sim::picture::save_png(&dir.join(format!("{}_{}.png", view.frame.sequence, view.frame.stem)), &img)?;
    Ok(())
}
