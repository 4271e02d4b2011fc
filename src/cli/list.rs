//! `groundtruth list`: the scenes, rigs and classification methods this build knows.

/// Arguments of `groundtruth list`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Prints the known scenes, rigs and methods, one section each.
pub fn run(_args: Args) -> anyhow::Result<()> {
    println!("scenes:");
    for name in super::common::scene_names() {
        println!("  {name}");
    }
    println!("rigs:");
    for name in sim::rig::PRESETS {
        println!("  {name}");
    }
    println!("methods:");
    for name in classifier::METHODS {
        println!("  {name}");
    }
    Ok(())
}
