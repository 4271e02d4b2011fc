//! `groundtruth sweep plot DIR --x PARAM [--y PARAM] --metric NAME [--by method|scene|rig]
//! [--where COLUMN=VALUE]... --out FILE.png|.svg`.
//!
//! - One parameter: a line per group (`--by`, default `method`) of the metric against the
//!   parameter. Each point is the mean over the seeds of the per-seed value, and a light band
//!   spans the lowest to the highest seed; where other parameters vary too, each seed's value is
//!   their mean (the title says which were averaged).
//! - Two parameters (`--y`): a heat map of the metric's mean over everything else (seeds, other
//!   parameters, scenes unless filtered); a method's score needs one method (`--where method=...`).
//!
//! `--where` keeps only rows whose column has that value (repeatable), e.g. `--where scene=city`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde_json::{Map, Value};

use super::results::{self, STAT_COLUMNS};
use crate::plot::{Band, HeatMap, LinePlot, Series};

/// Arguments of `groundtruth sweep plot`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Sweep directory (results.jsonl, sweep.json).
    dir: PathBuf,
    /// Parameter on the x axis (a swept parameter, e.g. pitch_deg).
    #[arg(long)]
    x: String,
    /// Second parameter: draw a heat map over x and y.
    #[arg(long)]
    y: Option<String>,
    /// Metric (a numeric column, e.g. f1, fpr, blind_zone_m, f1_20_40m).
    #[arg(long)]
    metric: String,
    /// One line per method, scene or rig.
    #[arg(long, value_enum, default_value_t = By::Method)]
    by: By,
    /// Keep only rows with COLUMN=VALUE (repeatable).
    #[arg(long = "where", value_name = "COLUMN=VALUE")]
    filters: Vec<String>,
    /// Output file, .png or .svg.
    #[arg(long)]
    out: PathBuf,
}

/// What one line of a line plot stands for.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum By {
    /// One line per method.
    Method,
    /// One line per scene.
    Scene,
    /// One line per rig.
    Rig,
}

impl By {
    fn column(self) -> &'static str {
        match self {
            By::Method => "method",
            By::Scene => "scene",
            By::Rig => "rig",
        }
    }
}

/// Runs `groundtruth sweep plot`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let ext = args.out.extension().and_then(|e| e.to_str());
    if !matches!(ext, Some("png" | "svg")) {
        bail!("--out {}: a plot is written as .png or .svg", args.out.display());
    }
    let data = Data::load(&args.dir)?;
    let rows = data.filtered(&args.filters)?;
    match &args.y {
        None => {
            let (plot, bands) = line_plot(&data, &rows, &args.x, &args.metric, args.by)?;
            crate::plot::save_line_plot_with_bands(&plot, &bands, &args.out)?;
        }
        Some(y) => {
            let map = heat_map(&data, &rows, &args.x, y, &args.metric)?;
            crate::plot::save_heat_map(&map, &args.out)?;
        }
    }
    println!("{}", args.out.display());
    Ok(())
}

/// A sweep directory's rows and parameter names.
pub struct Data {
    /// Every row.
    pub rows: Vec<Map<String, Value>>,
    /// The swept parameters (column names), in column order.
    pub params: Vec<String>,
    /// The parameters' values, in the sweep's order.
    pub values: BTreeMap<String, Vec<Value>>,
}

impl Data {
    /// Reads `dir`'s identity and rows.
    pub fn load(dir: &Path) -> anyhow::Result<Data> {
        let identity = results::read_identity(dir)?;
        let axes = identity["sweep"]["axes"].as_array().context("sweep.json without sweep.axes")?;
        let params = axes.iter().filter_map(|a| a["name"].as_str().map(str::to_string)).collect();
        let values = axes
            .iter()
            .filter_map(|a| Some((a["name"].as_str()?.to_string(), a["values"].as_array()?.clone())))
            .collect();
        Ok(Data { rows: results::read_rows(dir)?, params, values })
    }

    /// The rows passing every `COLUMN=VALUE` filter.
    pub fn filtered(&self, filters: &[String]) -> anyhow::Result<Vec<&Map<String, Value>>> {
        let mut keep: Vec<&Map<String, Value>> = self.rows.iter().collect();
        for f in filters {
            let (col, want) =
                f.split_once('=').with_context(|| format!("--where `{f}`: expected COLUMN=VALUE, e.g. scene=city"))?;
            if self.rows.first().is_some_and(|r| !r.contains_key(col)) {
                bail!("--where `{f}`: no column `{col}`");
            }
            keep.retain(|r| r.get(col).is_some_and(|v| field(v) == want));
            if keep.is_empty() {
                bail!("--where `{f}`: no row has {col} = {want}");
            }
        }
        Ok(keep)
    }

    fn check_param(&self, flag: &str, p: &str) -> anyhow::Result<()> {
        if !self.params.iter().any(|q| q == p) {
            bail!("{flag} `{p}`: not a swept parameter of this sweep; swept: {}", self.params.join(", "));
        }
        if self.values[p].iter().any(|v| !v.is_number()) {
            bail!("{flag} `{p}`: its values are not numbers");
        }
        Ok(())
    }
}

/// A value as the CSV writes it.
fn field(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Null => String::new(),
        other => other.to_string(),
    }
}

fn check_metric(rows: &[&Map<String, Value>], metric: &str) -> anyhow::Result<()> {
    let Some(first) = rows.first() else { bail!("no rows to plot") };
    if !first.get(metric).is_some_and(|v| v.is_number() || v.is_null()) || metric == "seed" {
        let numeric: Vec<&str> =
            first.iter().filter(|(k, v)| v.is_number() && *k != "seed").map(|(k, _)| k.as_str()).collect();
        bail!("--metric `{metric}`: not a metric of these rows; known: {}", numeric.join(", "));
    }
    Ok(())
}

/// The axis label of a column, with its unit.
pub fn label(name: &str) -> String {
    let known = match name {
        "x_m" => "mount x, forward (m)",
        "y_m" => "mount y, left (m)",
        "z_m" => "mount height z (m)",
        "roll_deg" => "mount roll (deg)",
        "pitch_deg" => "mount pitch (deg, + = down)",
        "yaw_deg" => "mount yaw (deg, + = left)",
        "acc" => "accuracy",
        "fpr" => "false-positive rate",
        "precision" => "precision",
        "recall" => "recall",
        "f1" => "F1",
        "iou" => "ground IoU",
        "returns" => "returns (points)",
        "ground_returns" => "ground returns (points)",
        "ground_area_m2" => "ground area covered (m²)",
        "farthest_ground_m" => "farthest ground return (m)",
        "ground_rings" => "rings that see ground",
        "blind_zone_m" => "blind-zone radius (m)",
        "sensor.frequency_hz" => "sensor frequency (Hz)",
        "sensor.columns" => "sensor columns",
        _ => "",
    };
    if !known.is_empty() {
        return known.to_string();
    }
    for (prefix, what) in [("f1_", "F1"), ("acc_", "accuracy"), ("fpr_", "FPR"), ("points_", "points")] {
        if let Some(band) = name.strip_prefix(prefix) {
            return format!("{what}, range {}", band.replace("_up", "+").replace('_', "-"));
        }
    }
    name.to_string()
}

fn num(v: Option<&Value>) -> Option<f64> {
    v.and_then(Value::as_f64).filter(|x| x.is_finite())
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// A total order for f64 keys (values are finite).
fn key(x: f64) -> i64 {
    (x * 1e9).round() as i64
}

/// The line plot of `metric` against `x`, one line per `by` group, a band over seeds.
pub fn line_plot(
    data: &Data,
    rows: &[&Map<String, Value>],
    x: &str,
    metric: &str,
    by: By,
) -> anyhow::Result<(LinePlot, Vec<Band>)> {
    data.check_param("--x", x)?;
    check_metric(rows, metric)?;
    // group -> x -> seed -> values
    type Cells = BTreeMap<String, BTreeMap<i64, (f64, BTreeMap<u64, Vec<f64>>)>>;
    let mut cells: Cells = BTreeMap::new();
    let mut seeds = BTreeSet::new();
    for r in rows {
        let (Some(xv), Some(m)) = (num(r.get(x)), num(r.get(metric))) else { continue };
        let seed = r.get("seed").and_then(Value::as_u64).unwrap_or(0);
        seeds.insert(seed);
        let group = field(r.get(by.column()).unwrap_or(&Value::Null));
        let e = cells.entry(group).or_default().entry(key(xv)).or_insert((xv, BTreeMap::new()));
        e.1.entry(seed).or_default().push(m);
    }
    if cells.is_empty() {
        bail!("--metric `{metric}`: no defined value to plot");
    }
    let mut series = Vec::new();
    let mut bands = Vec::new();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (group, xs) in &cells {
        let mut points = Vec::new();
        let mut band = Vec::new();
        for (xv, per_seed) in xs.values() {
            let seed_means: Vec<f64> = per_seed.values().map(|v| mean(v)).collect();
            let y = mean(&seed_means);
            let (a, b) = seed_means.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
            points.push((*xv, y));
            band.push((*xv, a, b));
            (lo, hi) = (lo.min(a), hi.max(b));
        }
        series.push(Series { name: group.clone(), points, dashed: false });
        bands.push(band);
    }
    let xs: Vec<f64> = data.values[x].iter().filter_map(Value::as_f64).collect();
    let (x0, x1) = xs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let (x0, x1) = if x1 > x0 { (x0, x1) } else { (x0 - 0.5, x0 + 0.5) };
    let pad = if hi > lo { 0.06 * (hi - lo) } else { 0.05 * hi.abs().max(1e-3) };
    let averaged: Vec<&str> =
        data.params.iter().filter(|p| *p != x && data.values[p.as_str()].len() > 1).map(String::as_str).collect();
    let mut title = format!("{} vs {}", label(metric), x);
    let mut notes = Vec::new();
    if seeds.len() > 1 {
        notes.push(format!("band: min-max over {} seeds", seeds.len()));
    }
    if !averaged.is_empty() {
        notes.push(format!("mean over {}", averaged.join(", ")));
    }
    if !notes.is_empty() {
        title = format!("{title} ({})", notes.join("; "));
    }
    let plot = LinePlot {
        title,
        x_label: label(x),
        y_label: label(metric),
        x_range: (x0, x1),
        y_range: (lo - pad, hi + pad),
        series,
        diagonal: false,
    };
    Ok((plot, if seeds.len() > 1 { bands } else { Vec::new() }))
}

/// The heat map of `metric`'s mean over `x` and `y`.
pub fn heat_map(data: &Data, rows: &[&Map<String, Value>], x: &str, y: &str, metric: &str) -> anyhow::Result<HeatMap> {
    data.check_param("--x", x)?;
    data.check_param("--y", y)?;
    if x == y {
        bail!("--x and --y are both `{x}`");
    }
    check_metric(rows, metric)?;
    let methods: BTreeSet<String> = rows.iter().map(|r| field(r.get("method").unwrap_or(&Value::Null))).collect();
    if methods.len() > 1 && !STAT_COLUMNS.contains(&metric) {
        bail!(
            "--metric `{metric}` of {} methods in one heat map: choose one with --where method=NAME ({})",
            methods.len(),
            methods.into_iter().collect::<Vec<_>>().join(", ")
        );
    }
    let mut xs: Vec<f64> = data.values[x].iter().filter_map(Value::as_f64).collect();
    let mut ys: Vec<f64> = data.values[y].iter().filter_map(Value::as_f64).collect();
    xs.sort_by(f64::total_cmp);
    ys.sort_by(f64::total_cmp);
    let mut sums = vec![vec![(0.0, 0u32); xs.len()]; ys.len()];
    for r in rows {
        let (Some(xv), Some(yv), Some(m)) = (num(r.get(x)), num(r.get(y)), num(r.get(metric))) else { continue };
        let (Some(c), Some(rr)) =
            (xs.iter().position(|&v| key(v) == key(xv)), ys.iter().position(|&v| key(v) == key(yv)))
        else {
            continue;
        };
        sums[rr][c].0 += m;
        sums[rr][c].1 += 1;
    }
    let values = sums.iter().map(|row| row.iter().map(|&(s, n)| (n > 0).then(|| s / n as f64)).collect()).collect();
    let scenes: BTreeSet<String> = rows.iter().map(|r| field(r.get("scene").unwrap_or(&Value::Null))).collect();
    let over = if scenes.len() > 1 { "seeds, scenes" } else { "seeds" };
    let what = if methods.len() == 1 {
        format!("{}, ", methods.into_iter().next().unwrap_or_default())
    } else {
        String::new()
    };
    Ok(HeatMap {
        title: format!("{} ({what}mean over {over} and other parameters)", label(metric)),
        x_label: label(x),
        y_label: label(y),
        value_label: label(metric),
        xs,
        ys,
        values,
    })
}
