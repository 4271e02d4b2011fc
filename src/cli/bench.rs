//! `groundtruth bench`. TODO

/// Subcommands of `groundtruth bench`.
#[derive(clap::Subcommand, Debug)]
pub enum Command {}

/// Runs `groundtruth bench`.
pub fn run(c: Command) -> anyhow::Result<()> {
    match c {}
}
