//! The result files of a sweep directory and resuming them.
//!
//! `DIR/sweep.json` records the sweep (canonical, lists expanded), its id (the [`stable_key`] of
//! that text) and the shard. `DIR/results.csv` (header line first) and `DIR/results.jsonl` (one
//! JSON object per line, the same names as the CSV header) hold one row per configuration and
//! method, appended as each configuration finishes (all its rows in one write per file, then
//! synced). Columns, in order:
//!
//! | column | what |
//! |---|---|
//! | `key` | the configuration's stable key (32 hex digits, [`super::expand`]) |
//! | `scene`, `rig`, `seed`, `body` | what was scanned; `body` is `rig` or the moved sensor |
//! | the swept parameters | `x_m` .. `yaw_deg`, then `sensor.<field>`, only those the sweep lists |
//! | `method` | the classification method |
//! | `returns`, `ground_returns` | returns and true ground returns, summed over the frames |
//! | `ground_area_m2` | area of the 0.5 m x 0.5 m vehicle-frame cells holding a ground return |
//! | `farthest_ground_m` | largest range of a ground return, metres (empty if none) |
//! | `ground_rings` | rows of the merged grid with at least one ground return |
//! | `blind_zone_m` | smallest horizontal distance from the body (mean sensor position) to a ground return |
//! | `acc fpr precision recall f1 iou` | the method's scores pooled over the frames |
//! | `points_<band> acc_<band> fpr_<band> f1_<band>` | the same per range band `0_10m 10_20m 20_40m 40_80m 80m_up` |
//!
//! An undefined measure (no ground, a zero denominator) is an empty CSV field and `null` in JSON.
//! Rows are appended in completion order, which depends on the threads; sorted, the files of a
//! sweep are the same at any thread count and sharded or not.

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::path::Path;

use anyhow::{Context, bail};
use serde_json::Value;

use super::expand::Space;
use crate::cli::shard::{Shard, complete_lines, stable_key, write_lines_atomic};

/// The identity file of a sweep directory.
pub const IDENTITY_FILE: &str = "sweep.json";
/// The CSV result file.
pub const CSV_FILE: &str = "results.csv";
/// The JSON-lines result file.
pub const JSONL_FILE: &str = "results.jsonl";

/// The point-statistics columns.
pub const STAT_COLUMNS: [&str; 6] =
    ["returns", "ground_returns", "ground_area_m2", "farthest_ground_m", "ground_rings", "blind_zone_m"];
/// The score columns.
pub const METRIC_COLUMNS: [&str; 6] = ["acc", "fpr", "precision", "recall", "f1", "iou"];

/// Column-name suffix of range band `b` (`0_10m`, ..., `80m_up`).
pub fn band_slug(b: usize) -> String {
    let name = classifier::metrics::range_band_name(b);
    match name.strip_suffix('+') {
        Some(open) => format!("{open}_up"),
        None => name.replace('-', "_"),
    }
}

/// Number of range bands.
pub fn bands() -> usize {
    classifier::metrics::RANGE_BANDS_M.len() + 1
}

/// The directory's identity: the sweep's id, the sweep itself and the shard (`None` when merged).
pub fn identity(space: &Space, shard: Option<Shard>) -> Value {
    let sweep = space.sweep.canonical();
    let id = stable_key(&sweep.to_string());
    serde_json::json!({
        "kind": "groundtruth-sweep",
        "id": id,
        "configurations": space.count,
        "shard": shard.map(|s| s.to_string()),
        "sweep": sweep,
    })
}

/// The column names of a sweep's result files.
pub fn header(space: &Space) -> Vec<String> {
    let mut h: Vec<String> = ["key", "scene", "rig", "seed", "body"].iter().map(|s| s.to_string()).collect();
    h.extend(space.sweep.axes().map(|a| a.name.clone()));
    h.push("method".into());
    h.extend(STAT_COLUMNS.iter().chain(&METRIC_COLUMNS).map(|s| s.to_string()));
    for b in 0..bands() {
        let slug = band_slug(b);
        h.extend(["points", "acc", "fpr", "f1"].iter().map(|m| format!("{m}_{slug}")));
    }
    h
}

/// A number as a JSON value; NaN and infinities become `null`.
pub fn num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// One value as a CSV field: strings bare, numbers as JSON writes them, `null` empty.
fn csv_field(v: &Value) -> String {
    match v {
        Value::Null => String::new(),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// A row as a CSV line (no newline).
pub fn csv_line(row: &[Value]) -> String {
    row.iter().map(csv_field).collect::<Vec<_>>().join(",")
}

/// A row as a JSON line (no newline): an object keyed by the header's names.
pub fn json_line(header: &[String], row: &[Value]) -> String {
    let obj: serde_json::Map<String, Value> = header.iter().cloned().zip(row.iter().cloned()).collect();
    Value::Object(obj).to_string()
}

/// `(key, method)` of a CSV line, given the method's column.
fn csv_key(line: &str, method_col: usize) -> Option<(String, String)> {
    let fields: Vec<&str> = line.split(',').collect();
    Some((fields.first()?.to_string(), fields.get(method_col)?.to_string()))
}

/// `(key, method)` of a JSON line.
fn json_key(line: &str) -> Option<(String, String)> {
    let v: Value = serde_json::from_str(line).ok()?;
    Some((v.get("key")?.as_str()?.to_string(), v.get("method")?.as_str()?.to_string()))
}

/// The rows found in a directory's result files: complete lines only (a torn last line is
/// dropped), each `(key, method)` once, and only keys with a row for every method in both files.
pub struct Found {
    /// CSV lines (no header) by `(key, method)`.
    pub csv: BTreeMap<(String, String), String>,
    /// JSON lines by `(key, method)`.
    pub json: BTreeMap<(String, String), String>,
    /// Keys with every method's row in both files.
    pub done: HashSet<String>,
}

/// Reads `dir`'s result files (see [`Found`]); `header` must match the CSV's.
pub fn read_found(dir: &Path, header: &[String], methods: &[String]) -> anyhow::Result<Found> {
    let head = header.join(",");
    let method_col = header.iter().position(|h| h == "method").context("header without method")?;
    let csv_lines = complete_lines(&dir.join(CSV_FILE))?;
    if let Some(first) = csv_lines.first()
        && *first != head
    {
        bail!("{}: its header is not this sweep's; choose another --out", dir.join(CSV_FILE).display());
    }
    let csv: BTreeMap<(String, String), String> =
        csv_lines.into_iter().skip(1).filter_map(|l| Some((csv_key(&l, method_col)?, l))).collect();
    let json: BTreeMap<(String, String), String> =
        complete_lines(&dir.join(JSONL_FILE))?.into_iter().filter_map(|l| Some((json_key(&l)?, l))).collect();
    let mut per_key: HashMap<&str, BTreeSet<&str>> = HashMap::new();
    for (k, m) in csv.keys() {
        if json.contains_key(&(k.clone(), m.clone())) {
            per_key.entry(k).or_default().insert(m);
        }
    }
    let done: HashSet<String> = per_key
        .into_iter()
        .filter(|(_, ms)| methods.iter().all(|m| ms.contains(m.as_str())))
        .map(|(k, _)| k.to_string())
        .collect();
    Ok(Found { csv, json, done })
}

/// Rewrites `dir`'s result files (atomically) to hold exactly the rows of `found.done`, sorted by
/// `(key, method)`: what a resumed run starts from.
pub fn rewrite_done(dir: &Path, header: &[String], found: &Found) -> anyhow::Result<()> {
    write_rows(dir, header, found, |k| found.done.contains(k))
}

/// Writes the rows of `found` whose key passes `keep`, sorted by `(key, method)`, to `dir`'s two
/// result files (atomically, the CSV with its header).
pub fn write_rows(dir: &Path, header: &[String], found: &Found, keep: impl Fn(&str) -> bool) -> anyhow::Result<()> {
    let mut csv = vec![header.join(",")];
    csv.extend(found.csv.iter().filter(|((k, _), _)| keep(k)).map(|(_, l)| l.clone()));
    let json: Vec<String> = found.json.iter().filter(|((k, _), _)| keep(k)).map(|(_, l)| l.clone()).collect();
    write_lines_atomic(&dir.join(CSV_FILE), &csv)?;
    write_lines_atomic(&dir.join(JSONL_FILE), &json)
}

/// Reads every row of a sweep directory's `results.jsonl` as JSON objects.
pub fn read_rows(dir: &Path) -> anyhow::Result<Vec<serde_json::Map<String, Value>>> {
    let path = dir.join(JSONL_FILE);
    if !path.exists() {
        bail!("{}: no results (run `groundtruth sweep --out {}` first)", path.display(), dir.display());
    }
    complete_lines(&path)?
        .iter()
        .enumerate()
        .map(|(i, l)| match serde_json::from_str::<Value>(l) {
            Ok(Value::Object(o)) => Ok(o),
            _ => bail!("{}: line {} is not a JSON object", path.display(), i + 1),
        })
        .collect()
}

/// Reads a sweep directory's identity file.
pub fn read_identity(dir: &Path) -> anyhow::Result<Value> {
    let path = dir.join(IDENTITY_FILE);
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("{}: not a sweep directory (no {IDENTITY_FILE})", dir.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_slugs_and_null_fields() {
        let slugs: Vec<String> = (0..bands()).map(band_slug).collect();
        assert_eq!(slugs, ["0_10m", "10_20m", "20_40m", "40_80m", "80m_up"]);
        let row = vec![Value::from("k"), num(f64::NAN), num(0.5), Value::from(3)];
        assert_eq!(csv_line(&row), "k,,0.5,3");
        let h: Vec<String> = ["key", "f1", "acc", "n"].iter().map(|s| s.to_string()).collect();
        assert_eq!(json_line(&h, &row), r#"{"acc":0.5,"f1":null,"key":"k","n":3}"#);
    }
}
