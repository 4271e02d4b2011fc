//! `groundtruth list`: the scenes, rigs, classification methods and casting backends this build
//! knows, with the GPU adapter the `gpu` backend would use.

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
    println!("casting backends:");
    println!("  bvh (production)");
    if sim::cast::REFERENCE_BUILT {
        println!("  parry (reference)");
    } else {
        println!("  parry (reference): {}", sim::cast::REFERENCE_NOT_BUILT);
    }
    match sim::cast::gpu_adapter() {
        Ok(adapter) => println!("  gpu: {adapter}"),
        Err(e) => println!("  gpu: unavailable: {e}"),
    }
    Ok(())
}
