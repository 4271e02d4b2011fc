//! `groundtruth render --input DIR|FILE.pcd`: a bird's-eye view or range image of one frame of a
//! scan, coloured by class, ground truth, range or height, written as PNG.
//!
//! The frame's PCD is found through `DIR/manifest.json` (`frames[N].file`); without a manifest,
//! `DIR/frame_NNNNNN.pcd` is used. `--input FILE` draws that file: `.pcd`, `.ply` (a point
//! cloud) or a KITTI `.bin` (with the `.label` beside it when there is one).

use std::path::{Path, PathBuf};

use anyhow::Context;
use sim::picture::{self, BevOptions, Coloring, RangeOptions, View};

/// Finds the PCD file of frame `frame` in `input` (a scan directory or a PCD file).
fn frame_file(input: &Path, frame: usize) -> anyhow::Result<PathBuf> {
    if input.is_file() {
        return Ok(input.to_path_buf());
    }
    if !input.is_dir() {
        anyhow::bail!("{}: no such file or directory", input.display());
    }
    let manifest = input.join("manifest.json");
    if manifest.is_file() {
        let text = std::fs::read_to_string(&manifest).with_context(|| format!("{}", manifest.display()))?;
        let json: serde_json::Value =
            serde_json::from_str(&text).with_context(|| format!("{}: not valid JSON", manifest.display()))?;
        let frames = json
            .get("frames")
            .and_then(|f| f.as_array())
            .with_context(|| format!("{}: no `frames` list", manifest.display()))?;
        let entry = frames.get(frame).with_context(|| {
            format!(
                "--frame {frame}: the scan has {} frames (allowed: 0 ..= {})",
                frames.len(),
                frames.len().saturating_sub(1)
            )
        })?;
        let file = entry
            .get("file")
            .and_then(|f| f.as_str())
            .with_context(|| format!("{}: frames[{frame}] has no `file`", manifest.display()))?;
        if !file.ends_with(".pcd") {
            // The frame's own file may be another format; look for the PCD among its files.
            if let Some(pcd) = entry
                .get("files")
                .and_then(|f| f.as_array())
                .and_then(|files| files.iter().filter_map(|f| f.get("file")?.as_str()).find(|f| f.ends_with(".pcd")))
            {
                return Ok(input.join(pcd));
            }
            anyhow::bail!("{}: frame {frame} has no PCD file (render reads PCD)", manifest.display());
        }
        return Ok(input.join(file));
    }
    let pcd = input.join(format!("frame_{frame:06}.pcd"));
    if pcd.is_file() {
        Ok(pcd)
    } else {
        anyhow::bail!("{}: no manifest.json and no {}", input.display(), pcd.display())
    }
}

/// Reads a PCD, PLY or KITTI `.bin` (with the `.label` beside it, if any) by file extension.
fn read_cloud(file: &Path) -> anyhow::Result<sim::OrderedCloud> {
    let ext = file.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    Ok(match ext.as_deref() {
        Some("ply") => sim::io::ply::read(file)?,
        Some("bin") => {
            let label = file.with_extension("label");
            sim::io::kitti::read(file, label.is_file().then_some(label.as_path()))?
        }
        _ => sim::io::pcd::read(file)?,
    })
}

/// Draws the picture.
pub fn run(args: &super::render::Args) -> anyhow::Result<()> {
    let input = args.input.as_deref().context("render of a scan needs --input DIR|FILE.pcd")?;
    let view = View::parse(&args.view)?;
    let coloring = Coloring::parse(&args.color)?;
    if args.out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() != Some("png") {
        anyhow::bail!("--out {}: the picture is PNG, give a .png file name", args.out.display());
    }
    let file = frame_file(input, args.frame)?;
    let cloud = read_cloud(&file)?;
    let img = match view {
        View::Bev => picture::render_bev(&cloud, &coloring, &BevOptions::default())?,
        View::Range => picture::render_range(&cloud, &coloring, &RangeOptions::default())?,
    };
    picture::save_png(&args.out, &img)?;
    println!(
        "{}: {} view of {} ({} x {}, {} returns), {} x {} px",
        args.out.display(),
        args.view,
        file.display(),
        cloud.rows * cloud.planes,
        cloud.cols,
        cloud.returns(),
        img.width(),
        img.height()
    );
    Ok(())
}
