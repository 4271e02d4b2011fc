//! Shared helpers of the subcommands: resolving scene and rig names or files.

use sim::{Rig, SceneMesh};

/// Loads a scene by built-in name, bundled scene name, or TOML file path, with `seed`.
pub fn load_scene(name_or_file: &str, seed: u64) -> anyhow::Result<SceneMesh> {
    let _ = seed;
    Ok(sim::scene::builtin::builtin(name_or_file)?)
}

/// Loads a rig by preset name or TOML file path.
pub fn load_rig(name_or_file: &str) -> anyhow::Result<Rig> {
    let _ = name_or_file;
    anyhow::bail!("rigs not implemented yet")
}
