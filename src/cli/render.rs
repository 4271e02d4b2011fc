//! `groundtruth render`. TODO

/// Arguments of `groundtruth render`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs `groundtruth render`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`render` is not implemented yet")
}
