//! `groundtruth sweep plot`: not implemented yet.

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Refuses: not implemented yet.
pub fn run(_a: Args) -> anyhow::Result<()> {
    anyhow::bail!("sweep plot: not implemented yet")
}
