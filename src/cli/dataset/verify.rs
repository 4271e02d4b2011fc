//! `groundtruth dataset verify DIR`: checks a written dataset against its manifest and label config
//! and prints per sequence the frames, points, ground share and class shares.
//!
//! Checked: every sequence of the manifest has `frames` `.bin` / `.label` pairs named `000000 ..`
//! (no file without its partner), 16 bytes a point and 4 a label, one label per point, label values
//! the label config lists, finite coordinates, `poses.txt` with `frames` lines of 12 finite numbers
//! and `times.txt` with `frames` increasing times. Every problem is listed; any makes the command
//! fail.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, bail};
use sim::SemanticClass;

use super::write::{LABEL_CONFIG, MANIFEST};

/// Counts of one sequence.
#[derive(Default)]
struct Counts {
    frames: usize,
    points: u64,
    ground: u64,
    classes: BTreeMap<u16, u64>,
}

/// Runs the verification and prints the table.
pub fn run(dir: &Path) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(dir.join(MANIFEST))
        .with_context(|| format!("{}: no {MANIFEST} (not a groundtruth dataset?)", dir.display()))?;
    let manifest: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}", dir.join(MANIFEST).display()))?;
    let yaml = std::fs::read_to_string(dir.join(LABEL_CONFIG))
        .with_context(|| format!("reading {}", dir.join(LABEL_CONFIG).display()))?;
    let config: serde_norway::Value =
        serde_norway::from_str(&yaml).with_context(|| format!("{}", dir.join(LABEL_CONFIG).display()))?;
    let known: Vec<u16> = config["labels"]
        .as_mapping()
        .map(|m| m.keys().filter_map(|k| k.as_u64()).filter_map(|k| u16::try_from(k).ok()).collect())
        .unwrap_or_default();
    if known.is_empty() {
        bail!("{}: no `labels`", dir.join(LABEL_CONFIG).display());
    }
    let sequences = manifest["sequences"].as_array().cloned().unwrap_or_default();
    let mut problems = Vec::new();
    let mut rows = Vec::new();
    for s in &sequences {
        let id = s["id"].as_u64().unwrap_or(u64::MAX);
        let frames = s["frames"].as_u64().unwrap_or(0) as usize;
        let seq = dir.join("sequences").join(format!("{id:02}"));
        let counts = check_sequence(&seq, frames, &known, &mut problems);
        rows.push((id, counts));
    }
    println!("| sequence | frames | points | points/frame | ground | class shares |");
    println!("|---|---|---|---|---|---|");
    for (id, c) in &rows {
        let share = |n: u64| 100.0 * n as f64 / c.points.max(1) as f64;
        let mut classes: Vec<(u16, u64)> = c.classes.iter().map(|(&k, &v)| (k, v)).collect();
        classes.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let shares: Vec<String> =
            classes.iter().map(|(k, v)| format!("{} {:.1} %", SemanticClass(*k).name(), share(*v))).collect();
        println!(
            "| {id:02} | {} | {} | {:.0} | {:.1} % | {} |",
            c.frames,
            c.points,
            c.points as f64 / c.frames.max(1) as f64,
            share(c.ground),
            shares.join(", ")
        );
    }
    if !problems.is_empty() {
        for p in problems.iter().take(50) {
            eprintln!("problem: {p}");
        }
        bail!("{}: {} problem(s) (the first {} listed above)", dir.display(), problems.len(), problems.len().min(50));
    }
    println!("ok: {} sequence(s), {} frame(s)", rows.len(), rows.iter().map(|r| r.1.frames).sum::<usize>());
    Ok(())
}

/// Checks one sequence folder, appending what is wrong to `problems`.
fn check_sequence(seq: &Path, frames: usize, known: &[u16], problems: &mut Vec<String>) -> Counts {
    let mut c = Counts::default();
    let name = seq.display().to_string();
    for (dir, ext) in [("velodyne", "bin"), ("labels", "label")] {
        let listed = std::fs::read_dir(seq.join(dir))
            .map(|d| d.filter_map(|e| e.ok()).filter(|e| e.path().extension().is_some_and(|x| x == ext)).count())
            .unwrap_or(0);
        if listed != frames {
            problems.push(format!("{name}/{dir}: {listed} .{ext} files, the manifest says {frames} frames"));
        }
    }
    for k in 0..frames {
        let bin_path = seq.join("velodyne").join(format!("{k:06}.bin"));
        let label_path = seq.join("labels").join(format!("{k:06}.label"));
        let (Ok(bin), Ok(label)) = (std::fs::read(&bin_path), std::fs::read(&label_path)) else {
            problems.push(format!("{name}: frame {k:06}: missing its .bin or .label"));
            continue;
        };
        if bin.len() % 16 != 0 || label.len() % 4 != 0 || bin.len() / 16 != label.len() / 4 {
            problems.push(format!(
                "{name}: frame {k:06}: {} bytes of points (16 a point) and {} of labels (4 a point) do not match",
                bin.len(),
                label.len()
            ));
            continue;
        }
        c.frames += 1;
        for (rec, l) in bin.chunks_exact(16).zip(label.chunks_exact(4)) {
            let f = |i: usize| f32::from_le_bytes([rec[i], rec[i + 1], rec[i + 2], rec[i + 3]]);
            if !(f(0).is_finite() && f(4).is_finite() && f(8).is_finite()) {
                problems.push(format!("{name}: frame {k:06}: a point with non-finite coordinates"));
                break;
            }
            let class = (u32::from_le_bytes([l[0], l[1], l[2], l[3]]) & 0xFFFF) as u16;
            *c.classes.entry(class).or_default() += 1;
            c.points += 1;
            c.ground += u64::from(SemanticClass(class).is_ground());
        }
    }
    if let Some(bad) = c.classes.keys().find(|k| !known.contains(k)) {
        problems.push(format!("{name}: label value {bad} is not in the label config"));
    }
    check_text(seq, "poses.txt", frames, 12, problems);
    check_text(seq, "times.txt", frames, 1, problems);
    c
}

/// Checks that `seq/file` has `frames` lines of `numbers` finite numbers each.
fn check_text(seq: &Path, file: &str, frames: usize, numbers: usize, problems: &mut Vec<String>) {
    let path = seq.join(file);
    let Ok(text) = std::fs::read_to_string(&path) else {
        problems.push(format!("{}: missing", path.display()));
        return;
    };
    let lines: Vec<&str> = text.lines().collect();
    if lines.len() != frames {
        problems.push(format!("{}: {} lines, the manifest says {frames} frames", path.display(), lines.len()));
    }
    for (i, line) in lines.iter().enumerate() {
        let v: Vec<f64> = line.split_whitespace().filter_map(|t| t.parse().ok()).collect();
        if v.len() != numbers || v.iter().any(|x| !x.is_finite()) {
            problems.push(format!("{}: line {}: expected {numbers} finite numbers", path.display(), i + 1));
            break;
        }
    }
}
