//! `groundtruth eval`. TODO

/// Arguments of `groundtruth eval`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs `groundtruth eval`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`eval` is not implemented yet")
}
