//! `groundtruth scan`. TODO

/// Arguments of `groundtruth scan`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs `groundtruth scan`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`scan` is not implemented yet")
}
