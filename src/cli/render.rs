//! `groundtruth render`: a picture of a scene from above (`--scene`) or of a scan (`--input`).

use std::path::PathBuf;

/// Arguments of `groundtruth render`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene name or TOML file: draw the scene from above, coloured by class.
    #[arg(long, conflicts_with = "input")]
    pub scene: Option<String>,
    /// Scan output directory (with manifest.json): draw one frame of the scan.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Frame index within the scan.
    #[arg(long, default_value_t = 0)]
    pub frame: usize,
    /// View of a scan: `bev` (bird's-eye) or `range` (rows x columns range image).
    #[arg(long, default_value = "bev")]
    pub view: String,
    /// Colouring of a scan: `class`, `ground`, `range` or `height`.
    #[arg(long, default_value = "class")]
    pub color: String,
    /// Scene seed (with `--scene`).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output PNG file.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `groundtruth render`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.scene.is_some() {
        super::render_scene::run(&args)
    } else if args.input.is_some() {
        super::render_scan::run(&args)
    } else {
        anyhow::bail!("render needs --scene NAME|FILE.toml or --input SCAN_DIR")
    }
}
