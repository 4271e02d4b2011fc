//! `groundtruth dataset`: labelled scans on demand as a SemanticKITTI-layout dataset, generated in
//! shards, and `groundtruth dataset verify DIR`.
//!
//! ```text
//! DIR/manifest.json              the dataset's configuration, its id and per-sequence counts
//! DIR/groundtruth.yaml           the label config (SemanticKITTI's format: labels, color_map, ...)
//! DIR/sequences/NN/velodyne/NNNNNN.bin    float32 x y z intensity per return (KITTI scan order)
//! DIR/sequences/NN/labels/NNNNNN.label    uint32 per return: class | instance << 16
//! DIR/sequences/NN/{calib,poses,times}.txt
//! DIR/sequences/NN/{pcd,ply,las}/NNNNNN.*  optional extra files per frame
//! ```
//!
//! Frames: the points of a single-sensor rig are in its sensor frame (as KITTI's are in the
//! Velodyne's), those of a multi-sensor rig in the vehicle frame. `calib.txt`'s `Tr` is the
//! identity (P0-P3 too: there is no camera), so `poses.txt` line `k` is the pose of that frame (the
//! cloud's frame at the start of scan `k`) in the cloud frame of scan 0, 3 x 4 row-major, as
//! `Tr^-1 * pose * Tr` reduces to in SemanticKITTI's tools. `times.txt` holds each scan's start,
//! seconds. The frame rate is the rig's.
//!
//! Sharding: the frames of all sequences, numbered in the file's order, go to shard `k mod N`
//! (`--shard I/N`); every shard writes into the same `DIR` (the files are disjoint, and the
//! manifest, label config and per-sequence text files are the same bytes from every shard), so
//! shards on several machines combine by copying their folders together. Every file is written
//! atomically, a frame's `.label` last: a frame is complete when its `.label` exists, and
//! `--resume` skips complete frames. A `DIR` holding another dataset's manifest is refused.

pub(crate) mod config;
pub(crate) mod generate;
mod labels;
mod verify;
pub(crate) mod write;

use std::path::PathBuf;

use anyhow::bail;

/// Arguments of `groundtruth dataset`.
#[derive(clap::Args, Debug, Clone)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Args {
    /// `verify DIR`: check a written dataset.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The dataset file (TOML; see `examples/dataset-semantickitti.toml`).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Output directory (the dataset root).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// This process's part of the frames, `I/N` (0-based).
    #[arg(long, default_value = "0/1")]
    pub shard: String,
    /// Skip frames already complete (their `.label` written).
    #[arg(long)]
    pub resume: bool,
    /// Worker threads (default: all cores). The files are identical at any count.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Allow more than 10 million frames in all.
    #[arg(long)]
    pub allow_large: bool,
    /// Ray casting backend: `bvh` (the reproducible reference) or `gpu` (files agree with `bvh`'s
    /// within the contract of docs/scanning.md, not to the bit).
    #[arg(long, default_value = "bvh")]
    pub backend: String,
}

/// The subcommands of `groundtruth dataset`.
#[derive(clap::Subcommand, Debug, Clone)]
pub enum Command {
    /// Check a written dataset: frame counts, file sizes, label values, finite points, poses and
    /// times; print frames, points, ground share and class shares per sequence.
    Verify {
        /// The dataset root.
        dir: PathBuf,
    },
}

/// The sensor setup of every sequence of a dataset of ours (see
/// [`classifier::dataset::ours::sequence_setups`]).
pub fn manifest_setups(
    dir: &std::path::Path,
) -> anyhow::Result<Option<std::collections::BTreeMap<String, classifier::ordering::SensorSetup>>> {
    Ok(classifier::dataset::ours::sequence_setups(dir)?)
}

/// Runs `groundtruth dataset`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if let Some(Command::Verify { dir }) = &args.command {
        return verify::run(dir);
    }
    let (Some(config), Some(out)) = (&args.config, &args.out) else {
        bail!("groundtruth dataset needs --config DATASET.toml and --out DIR (or: groundtruth dataset verify DIR)");
    };
    let shard = crate::cli::shard::Shard::parse(&args.shard)?;
    let config = config::DatasetConfig::load(config, args.allow_large)?;
    let backend = super::scan::parse_backend(&args.backend)?;
    let summary =
        super::scan::with_threads(args.threads, || write::generate(&config, out, shard, args.resume, backend))??;
    println!("{}", serde_json::to_string_pretty(&summary)?);
    Ok(())
}
