//! `groundtruth train --method learned`: the learned method's model from our own scans.
//!
//! Frames come from a dataset file (`--config D.toml`: its sequences, with a `[generate]` table
//! drawn, scanned in memory, nothing written) or a dataset `groundtruth dataset` wrote
//! (`--dataset DIR`, whose `manifest.json` names each sequence's rig and mount). Either way every
//! frame takes the path a user's recording takes: its KITTI records (sensor frame) are ordered by
//! [`classifier::ordering::SensorSetup::order_kitti`] with the sequence's rig, so the model learns
//! on the grids it will meet; a dataset's frames are read through the recordings' reader
//! ([`classifier::recording::Recording::from_dataset`]), as `eval dataset` reads them. Every
//! second sequence is read in its sensor frame (the mount not applied), as a recording is read
//! without `--rig`: the model meets tilted and raised frames as well as level vehicle frames. Frames are scanned and their features computed in parallel; the
//! training set is assembled in frame order, so the model does not depend on the thread count.
//! Parameters: the file's `[train]` table, then the command line's flags.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, bail};
use classifier::learned::Extractor;
use classifier::learned::train::{TrainParams, TrainingSet, train};
use classifier::ordering::{CloudBuffer, OrderingReport, SensorSetup};
use classifier::recording::{Ordering, Recording};
use rayon::prelude::*;
use sim::SemanticClass;

use super::dataset::config::DatasetConfig;
use super::dataset::generate::TrainSection;

/// What `train --method learned` needs from the command line.
pub struct LearnedArgs<'a> {
    /// A dataset file to scan in memory.
    pub config: Option<&'a Path>,
    /// A dataset written by `groundtruth dataset`.
    pub dataset: Option<&'a Path>,
    /// Rig of a dataset without a manifest.
    pub rig: Option<&'a str>,
    /// The model file to write.
    pub out: &'a Path,
    /// Overrides of the training parameters.
    pub overrides: TrainSection,
    /// Worker threads.
    pub threads: Option<usize>,
}

/// One frame's ordered, labelled cloud, made as a user's recording would be read.
fn frame_through_the_real_path(
    records: &[[f32; 4]],
    labels: &[u32],
    setup: &SensorSetup,
    buffer: &mut CloudBuffer,
    report: &mut OrderingReport,
) -> anyhow::Result<()> {
    let classes: Vec<SemanticClass> = labels.iter().map(|&l| SemanticClass((l & 0xFFFF) as u16)).collect();
    setup.order_kitti(records, Some(&classes), buffer, report)?;
    Ok(())
}

fn records_of(bin: &[u8]) -> Vec<[f32; 4]> {
    bin.chunks_exact(16)
        .map(|c| std::array::from_fn(|k| f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]])))
        .collect()
}

fn labels_of(label: &[u8]) -> Vec<u32> {
    label.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// The setup that reads sequence number `sequence`: every second one in its sensor frame (no
/// mount applied, as a recording read without `--rig`), ordered by the rig's table. (Reading
/// them without the rig, rings recovered, half in firing order, over all 12 roof rigs: measured in
/// docs/learned.md, not the bundled model.)
fn in_frame_of(setup: SensorSetup, sequence: usize) -> SensorSetup {
    if sequence % 2 == 1 { SensorSetup { vehicle_from_sensor: glam::Affine3A::IDENTITY, ..setup } } else { setup }
}

/// The training parameters: defaults, then `section`, then `overrides`.
fn params(section: Option<&TrainSection>, overrides: &TrainSection, threads: Option<usize>) -> TrainParams {
    let mut p = TrainParams { threads, ..TrainParams::default() };
    for s in section.into_iter().chain(std::iter::once(overrides)) {
        p.trees = s.trees.unwrap_or(p.trees);
        p.depth = s.depth.unwrap_or(p.depth);
        p.eta = s.eta.unwrap_or(p.eta);
        p.samples_per_frame = s.samples_per_frame.unwrap_or(p.samples_per_frame);
        p.validation_every = s.validation_every.unwrap_or(p.validation_every);
        p.seed = s.seed.unwrap_or(p.seed);
    }
    p
}

/// A frame's contribution, computed on a worker.
fn contribution(
    records: &[[f32; 4]],
    labels: &[u32],
    setup: &SensorSetup,
    (ordinal, sequence): (u64, usize),
    params: &TrainParams,
) -> anyhow::Result<TrainingSet> {
    let (mut buffer, mut report) = (CloudBuffer::default(), OrderingReport::default());
    frame_through_the_real_path(records, labels, setup, &mut buffer, &mut report)?;
    contribution_of(buffer.cloud(), (ordinal, sequence), params)
}

/// One ordered, labelled frame's part of the training set (frame `ordinal` of sequence number
/// `sequence`).
fn contribution_of(
    cloud: &sim::OrderedCloud,
    (ordinal, sequence): (u64, usize),
    params: &TrainParams,
) -> anyhow::Result<TrainingSet> {
    let mut extractor = Extractor::new()?;
    let mut set = TrainingSet::default();
    let held_out = params.validation_every > 0 && sequence % params.validation_every == 0;
    set.add_frame(&mut extractor, cloud, ordinal, held_out, params)?;
    Ok(set)
}

/// The frames of a dataset file, scanned in memory.
fn from_config(path: &Path, params: &TrainParams) -> anyhow::Result<(TrainingSet, serde_json::Value)> {
    let config = DatasetConfig::load(path, false)?;
    let prepared = super::dataset::write::prepare(&config)?;
    for (k, p) in prepared.iter().enumerate() {
        if p.rig.sensors.len() != 1 {
            bail!("`sequences[{k}].rig` `{}`: the learned method trains on single-sensor rigs", p.config.rig);
        }
    }
    // Frame ordinals in file order.
    let mut first = Vec::with_capacity(prepared.len());
    let mut total = 0u64;
    for p in &prepared {
        first.push(total);
        total += p.config.frames;
    }
    println!("{}: {} sequences, {total} frames", path.display(), prepared.len());
    let parts: Vec<anyhow::Result<Vec<TrainingSet>>> = prepared
        .par_iter()
        .zip(&first)
        .enumerate()
        .map(|(sequence, (p, &first))| {
            let s = &p.config;
            // Any scene a dataset file takes: a bundled scene, a file or a family with its params.
            let scene = s.spec.load_scene().with_context(|| format!("`sequences[{sequence}].scene`"))?;
            let scanner = sim::scan::Scanner::new(&scene.mesh, &p.rig, p.scan.clone())?;
            let setup = in_frame_of(SensorSetup::new(Some(&p.rig), None)?, sequence);
            let sensor_from_vehicle = p.rig.sensors[0].mount.vehicle_from_sensor().inverse();
            let mut sets = Vec::with_capacity(s.frames as usize);
            for k in 0..s.frames as usize {
                let mut frame = scanner.frame(k);
                super::dataset::write::vary(&mut frame.cloud, s, k)?;
                let (bin, label, _) = sim::io::kitti::encode(&frame.cloud, Some(&sensor_from_vehicle))?;
                sets.push(
                    contribution(&records_of(&bin), &labels_of(&label), &setup, (first + k as u64, sequence), params)
                        .with_context(|| format!("sequence {} frame {k}", s.id))?,
                );
            }
            Ok(sets)
        })
        .collect();
    let mut set = TrainingSet::default();
    for part in parts {
        for s in part? {
            set.append(s);
        }
    }
    let trained_on = serde_json::json!({
        "config": path.display().to_string(),
        "sequences": config.sequences.len(),
        "frames": total,
        "scenes": config
            .sequences
            .iter()
            .map(|s| s.spec.family.clone().unwrap_or_else(|| s.scene.clone()))
            .collect::<std::collections::BTreeSet<_>>(),
        "rigs": config.sequences.iter().map(|s| s.rig.clone()).collect::<std::collections::BTreeSet<_>>(),
    });
    Ok((set, trained_on))
}

/// The frames of a dataset on disk.
fn from_dataset(
    dir: &Path,
    rig: Option<&str>,
    params: &TrainParams,
) -> anyhow::Result<(TrainingSet, serde_json::Value)> {
    // Each sequence's setup: from our manifest (rig and mount per sequence), else `--rig`.
    let ours = super::dataset::manifest_setups(dir)?;
    if ours.is_none() && rig.is_none() {
        bail!(
            "`{}` has no manifest.json of `groundtruth dataset`: give --rig to order its frames (and train only on scans of ours)",
            dir.display()
        );
    }
    let layout = classifier::dataset::DatasetLayout::open(dir, None)?;
    let setups = match ours {
        Some(m) => m,
        None => {
            let Some(rig) = rig else {
                bail!(
                    "`{}` has no manifest.json of `groundtruth dataset`: give --rig to order its frames (and train only on scans of ours)",
                    dir.display()
                );
            };
            let setup = classifier::recording::sensor_setup(Some(rig), None)?;
            layout.sequences.iter().map(|s| (s.id.clone(), setup.clone())).collect()
        }
    };
    // Each frame (sequence number, place in it) read as a recording of its own, in parallel.
    let frames: Vec<(usize, usize)> =
        layout.sequences.iter().enumerate().flat_map(|(k, s)| (0..s.frames.len()).map(move |i| (k, i))).collect();
    println!("{}: {} sequences, {} frames", dir.display(), layout.sequences.len(), frames.len());
    let parts: Vec<anyhow::Result<TrainingSet>> = frames
        .par_iter()
        .enumerate()
        .map(|(ordinal, &(sequence, place))| {
            let id = layout.sequences.get(sequence).map(|s| s.id.as_str()).unwrap_or_default();
            let setup = setups.get(id).with_context(|| format!("sequence `{id}` is not in the manifest"))?;
            let setup = &in_frame_of(setup.clone(), sequence);
            let recording = Recording::from_dataset(layout.part(sequence, place..place + 1));
            let mut frames = recording.frames(Ordering::Ordered(setup))?;
            let frame = frames.next_frame().with_context(|| format!("sequence `{id}`: no frame {place}"))??;
            contribution_of(frame.cloud, (ordinal as u64, sequence), params)
                .with_context(|| format!("`{}`", frame.provenance))
        })
        .collect();
    let mut set = TrainingSet::default();
    for part in parts {
        set.append(part?);
    }
    let trained_on = serde_json::json!({ "dataset": dir.display().to_string(), "frames": frames.len() });
    Ok((set, trained_on))
}

/// Runs `train --method learned`.
pub fn run(args: &LearnedArgs<'_>) -> anyhow::Result<()> {
    // Before any scan is made for it.
    if !classifier::learned::train::BUILT {
        anyhow::bail!("train --method learned: {}", classifier::learned::train::NOT_BUILT);
    }
    let t0 = Instant::now();
    let section = match args.config {
        Some(path) => DatasetConfig::load(path, false)?.train,
        None => None,
    };
    if let Some(m) = section.as_ref().and_then(|s| s.method.as_deref())
        && m != "learned"
    {
        bail!("`train.method` = `{m}` in the file, but --method learned was asked for");
    }
    let params = params(section.as_ref(), &args.overrides, args.threads);
    params.validate()?;
    let (set, trained_on) = super::scan::with_threads(args.threads, || match (args.config, args.dataset) {
        (Some(c), None) => from_config(c, &params),
        (None, Some(d)) => from_dataset(d, args.rig, &params),
        _ => bail!("give --config D.toml or --dataset DIR"),
    })??;
    let scanned_s = t0.elapsed().as_secs_f64();
    println!(
        "training set: {} returns from {} frames ({} held out: {} returns); features in {scanned_s:.1} s",
        set.len(),
        set.frames.0,
        set.frames.1,
        set.valid_labels.len()
    );
    let (model, report) = super::scan::with_threads(args.threads, || train(&set, &params, trained_on))??;
    model.save(args.out)?;
    println!(
        "trained {} trees of depth <= {} in {:.1} s; held-out F1 {:.4} (precision {:.4}, recall {:.4}; Nitsch's {:.4}) at threshold {:.2}",
        model.trees.len(),
        params.depth,
        report.seconds,
        report.valid_f1,
        report.valid_precision,
        report.valid_recall,
        report.valid_f1_nitsch,
        report.threshold
    );
    println!(
        "model written to {} ({} bytes); {:.1} s in all",
        args.out.display(),
        std::fs::metadata(args.out)?.len(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
