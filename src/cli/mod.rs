//! Command-line interface: one module per subcommand.

mod bench;
mod bench_agreement;
mod bench_classify;
mod bench_scan;
mod classify;
mod classify_bag;
mod common;
mod dataset;
mod demo;
mod eval;
mod eval_dataset;
mod eval_paper;
mod list;
mod render;
mod render_scan;
mod render_scene;
mod scan;
mod scene;
mod shard;
mod sweep;
mod train;
mod train_learned;

use clap::{Parser, Subcommand};

/// LiDAR ground truth on demand: scan procedural scenes, classify ground, evaluate.
#[derive(Parser, Debug)]
#[command(name = "groundtruth", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once per run: the size of the largest variant (eval's three modes and the flat spellings
// it still reads) costs nothing worth boxing it for.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand, Debug)]
enum Command {
    /// The main job on a built-in default: scan, classify, score and draw (city, hdl64e-roof, nitsch).
    Demo(demo::Args),
    /// List the scenes, rigs and classification methods this build knows.
    List(list::Args),
    /// Scan a scene with a rig and write ordered labelled clouds and a manifest.
    Scan(scan::Args),
    /// Scene tools (export a scene mesh).
    #[command(subcommand)]
    Scene(scene::Command),
    /// Draw a scene from above, or a scan as a bird's-eye view or range image (PNG).
    Render(render::Args),
    /// Classify ground points in scanned clouds.
    Classify(classify::Args),
    /// Score methods: `eval scene` (a scanned scene, Table I style), `eval dataset` (a labelled recording) or `eval paper mcdaniel`.
    Eval(eval::Args),
    /// Train a learning method (McDaniel et al.'s SVM, or the learned method's trees) on our scans and write the model (JSON).
    Train(train::Args),
    /// Sensor-mount sensitivity sweeps: run (sharded, resumable), merge, plot, report.
    Sweep(sweep::Args),
    /// Labelled scans as a SemanticKITTI-layout dataset (sharded, resumable), or `verify DIR`.
    Dataset(dataset::Args),
    /// Benchmarks that print one JSON object.
    #[command(subcommand)]
    Bench(bench::Command),
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Demo(a) => demo::run(a),
        Command::List(a) => list::run(a),
        Command::Scan(a) => scan::run(a),
        Command::Scene(c) => scene::run(c),
        Command::Render(a) => render::run(a),
        Command::Classify(a) => classify::run(a),
        Command::Eval(a) => eval::run(a),
        Command::Train(a) => train::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Dataset(a) => dataset::run(a),
        Command::Bench(c) => bench::run(c),
    }
}
