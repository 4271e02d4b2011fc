//! `groundtruth list`. TODO

/// Arguments of `groundtruth list`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs `groundtruth list`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`list` is not implemented yet")
}
