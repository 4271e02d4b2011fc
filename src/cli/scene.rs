//! `groundtruth scene`. TODO

/// Subcommands of `groundtruth scene`.
#[derive(clap::Subcommand, Debug)]
pub enum Command {}

/// Runs `groundtruth scene`.
pub fn run(c: Command) -> anyhow::Result<()> {
    match c {}
}
