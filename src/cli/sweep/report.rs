//! `groundtruth sweep report DIR [--out FILE.md]`: a Markdown summary of a sweep for a design
//! review: what was swept, the best and the worst configuration of each method (by F1, mean over
//! seeds), mean scores per method and scene, and plots (F1 per method and blind-zone radius per
//! scene against each numeric parameter, with a band over seeds; an F1 heat map per method over
//! the first two numeric parameters), written as PNG under `DIR/plots/`.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Context;
use serde_json::{Map, Value};

use super::plot::{By, Data, heat_map, label, line_plot};

/// Arguments of `groundtruth sweep report`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Sweep directory.
    dir: PathBuf,
    /// Markdown file to write (default DIR/report.md; plots go to DIR/plots/ either way).
    #[arg(long)]
    out: Option<PathBuf>,
}

fn field(v: Option<&Value>) -> String {
    match v {
        Some(Value::String(s)) => s.clone(),
        Some(Value::Null) | None => String::new(),
        Some(other) => other.to_string(),
    }
}

fn num(r: &Map<String, Value>, c: &str) -> Option<f64> {
    r.get(c).and_then(Value::as_f64).filter(|x| x.is_finite())
}

fn fmt(x: Option<f64>) -> String {
    x.map_or("-".to_string(), |v| format!("{v:.4}"))
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Runs `groundtruth sweep report`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let data = Data::load(&args.dir)?;
    let identity = super::results::read_identity(&args.dir)?;
    let sweep = &identity["sweep"];
    let out = args.out.clone().unwrap_or_else(|| args.dir.join("report.md"));
    let plot_dir = args.dir.join("plots");
    std::fs::create_dir_all(&plot_dir).with_context(|| format!("creating {}", plot_dir.display()))?;
    let rel = |p: &std::path::Path| -> String {
        let base = out.parent().unwrap_or(std::path::Path::new("."));
        p.strip_prefix(base).unwrap_or(p).display().to_string()
    };
    let list = |k: &str| -> String {
        sweep[k].as_array().map(|a| a.iter().map(|v| field(Some(v))).collect::<Vec<_>>().join(", ")).unwrap_or_default()
    };
    let total = identity["configurations"].as_u64().unwrap_or(0);
    let methods: Vec<String> =
        sweep["methods"].as_array().into_iter().flatten().filter_map(|m| m.as_str().map(str::to_string)).collect();
    let configs: std::collections::HashSet<&str> =
        data.rows.iter().filter_map(|r| r.get("key").and_then(Value::as_str)).collect();
    let mut md = String::new();
    writeln!(md, "# Sweep report: {}\n", args.dir.display())?;
    writeln!(
        md,
        "{} of {total} configurations present ({} rows). Scenes: {}. Rigs: {}. Seeds: {}. Methods: {}. \
         Moved: `{}` ({} frame(s) per configuration{}).\n",
        configs.len(),
        data.rows.len(),
        list("scenes"),
        list("rigs"),
        list("seeds"),
        list("methods"),
        field(sweep.get("body")),
        sweep["frames"],
        if sweep["ideal"].as_bool() == Some(true) { ", ideal measurements" } else { "" }
    )?;
    writeln!(md, "| parameter | values |\n|---|---|")?;
    for p in &data.params {
        let v: Vec<String> = data.values[p].iter().map(|v| field(Some(v))).collect();
        let shown =
            if v.len() > 8 { format!("{} .. {} ({} values)", v[0], v[v.len() - 1], v.len()) } else { v.join(", ") };
        writeln!(md, "| `{p}` ({}) | {shown} |", label(p))?;
    }
    // Per method and configuration (scene, rig, parameters): mean over seeds.
    let config_cols: Vec<String> =
        ["scene", "rig"].iter().map(|s| s.to_string()).chain(data.params.iter().cloned()).collect();
    let shown_cols = ["f1", "fpr", "recall", "precision", "blind_zone_m", "farthest_ground_m"];
    writeln!(md, "\n## Best and worst configuration per method\n")?;
    writeln!(md, "By F1, mean over the seeds of each configuration.\n")?;
    let head: Vec<String> = config_cols.iter().map(|c| format!("`{c}`")).collect();
    let metric_head: Vec<String> = shown_cols.iter().map(|c| label(c)).collect();
    writeln!(md, "| method | | {} | {} |", head.join(" | "), metric_head.join(" | "))?;
    writeln!(md, "|---|---|{}", "---|".repeat(head.len() + metric_head.len()))?;
    for m in &methods {
        let mut groups: BTreeMap<Vec<String>, Vec<&Map<String, Value>>> = BTreeMap::new();
        for r in data.rows.iter().filter(|r| field(r.get("method")) == *m) {
            groups.entry(config_cols.iter().map(|c| field(r.get(c))).collect()).or_default().push(r);
        }
        let scored: Vec<(&Vec<String>, Vec<Option<f64>>)> = groups
            .iter()
            .map(|(k, rs)| {
                let means =
                    shown_cols.iter().map(|c| mean(&rs.iter().filter_map(|r| num(r, c)).collect::<Vec<_>>())).collect();
                (k, means)
            })
            .filter(|(_, v): &(_, Vec<Option<f64>>)| v[0].is_some())
            .collect();
        let by_f1 = |a: &&(&Vec<String>, Vec<Option<f64>>), b: &&(&Vec<String>, Vec<Option<f64>>)| {
            a.1[0].unwrap_or(f64::NAN).total_cmp(&b.1[0].unwrap_or(f64::NAN))
        };
        let best = scored.iter().max_by(by_f1);
        let worst = scored.iter().min_by(by_f1);
        for (tag, row) in [("best", best), ("worst", worst)] {
            if let Some((k, v)) = row {
                let vals: Vec<String> = v.iter().map(|x| fmt(*x)).collect();
                writeln!(md, "| {m} | {tag} | {} | {} |", k.join(" | "), vals.join(" | "))?;
            }
        }
    }
    writeln!(md, "\n## Mean scores per method and scene\n")?;
    writeln!(md, "Pooled scores of each configuration, averaged over all configurations and seeds.\n")?;
    writeln!(
        md,
        "| method | scene | accuracy | FPR | precision | recall | F1 | IoU |\n|---|---|---|---|---|---|---|---|"
    )?;
    let mut per: BTreeMap<(String, String), Vec<&Map<String, Value>>> = BTreeMap::new();
    for r in &data.rows {
        per.entry((field(r.get("method")), field(r.get("scene")))).or_default().push(r);
    }
    for ((m, s), rs) in &per {
        let cells: Vec<String> = ["acc", "fpr", "precision", "recall", "f1", "iou"]
            .iter()
            .map(|c| fmt(mean(&rs.iter().filter_map(|r| num(r, c)).collect::<Vec<_>>())))
            .collect();
        writeln!(md, "| {m} | {s} | {} |", cells.join(" | "))?;
    }
    writeln!(md, "\n## Plots\n")?;
    let all: Vec<&Map<String, Value>> = data.rows.iter().collect();
    let numeric: Vec<&String> =
        data.params.iter().filter(|p| data.values[p.as_str()].iter().all(Value::is_number)).collect();
    for p in &numeric {
        let slug = p.replace('.', "_");
        for (metric, by, name) in [("f1", By::Method, "f1"), ("blind_zone_m", By::Scene, "blind_zone")] {
            let path = plot_dir.join(format!("{name}_vs_{slug}.png"));
            let (plot, bands) = line_plot(&data, &all, p, metric, by)?;
            crate::plot::save_line_plot_with_bands(&plot, &bands, &path)?;
            writeln!(md, "![{} vs {p}]({})\n", label(metric), rel(&path))?;
        }
    }
    if numeric.len() >= 2 {
        for m in &methods {
            let rows: Vec<&Map<String, Value>> = data.rows.iter().filter(|r| field(r.get("method")) == *m).collect();
            let path = plot_dir
                .join(format!("f1_{m}_{}_x_{}.png", numeric[0], numeric[1]).replace('.', "_").replace("_png", ".png"));
            let map = heat_map(&data, &rows, numeric[0], numeric[1], "f1")?;
            crate::plot::save_heat_map(&map, &path)?;
            writeln!(md, "![F1 of {m} over {} and {}]({})\n", numeric[0], numeric[1], rel(&path))?;
        }
    }
    sim::io::atomic::write_bytes_atomic(&out, md.as_bytes())?;
    println!("{}", out.display());
    Ok(())
}
