//! `groundtruth bench classify`. TODO(classifier helper)

/// Arguments of `groundtruth bench classify`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the classification benchmark and prints one JSON object.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("not implemented yet")
}
