//! `groundtruth bench`: benchmarks that print one JSON object each.

// Declared here (not in `cli/mod.rs`) so the raycast benchmark stays in files of its own.
#[path = "bench_raycast.rs"]
mod bench_raycast;

/// Subcommands of `groundtruth bench`.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Two backends' scans compared cell by cell, and the GPU agreement contract checked.
    Agreement(super::bench_agreement::Args),
    /// Ground classification speed (ms per frame).
    Classify(super::bench_classify::Args),
    /// Ray casting speed (rays per second) of a caster backend on a scene or mesh.
    Raycast(bench_raycast::Args),
    /// Cost of a full frame (casting, effects, labels, ordered cloud) against bare ray casting.
    Scan(super::bench_scan::Args),
}

/// Runs `groundtruth bench`.
pub fn run(c: Command) -> anyhow::Result<()> {
    match c {
        Command::Agreement(a) => super::bench_agreement::run(a),
        Command::Classify(a) => super::bench_classify::run(a),
        Command::Raycast(a) => bench_raycast::run(a),
        Command::Scan(a) => super::bench_scan::run(a),
    }
}
