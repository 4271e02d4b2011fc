//! `groundtruth render` (render_scene). TODO

/// Draws the picture.
pub fn run(_args: &super::render::Args) -> anyhow::Result<()> {
    anyhow::bail!("not implemented yet")
}
