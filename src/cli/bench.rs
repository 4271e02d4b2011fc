//! `groundtruth bench`: benchmarks that print one JSON object each.

/// Subcommands of `groundtruth bench`.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Ground classification speed (ms per frame).
    Classify(super::bench_classify::Args),
}

/// Runs `groundtruth bench`.
pub fn run(c: Command) -> anyhow::Result<()> {
    match c {
        Command::Classify(a) => super::bench_classify::run(a),
    }
}
