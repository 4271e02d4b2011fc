//! `groundtruth classify`. TODO

/// Arguments of `groundtruth classify`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs `groundtruth classify`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`classify` is not implemented yet")
}
