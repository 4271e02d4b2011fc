//! `groundtruth scene`: scene tools.

use std::path::PathBuf;

/// Subcommands of `groundtruth scene`.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Write a scene's mesh as binary PLY with per-face class, instance and reflectivity.
    Export {
        /// Scene name or TOML file.
        #[arg(long)]
        scene: String,
        /// Scene seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Output PLY file.
        #[arg(long)]
        out: PathBuf,
    },
}

/// Runs `groundtruth scene`.
pub fn run(c: Command) -> anyhow::Result<()> {
    match c {
        Command::Export { scene, seed, out } => {
            let mesh = super::common::load_scene(&scene, seed)?;
            sim::scene::ply::write_mesh(&out, &mesh)?;
            println!("wrote {} ({} triangles, {} vertices)", out.display(), mesh.len(), mesh.vertices.len());
            Ok(())
        }
    }
}
