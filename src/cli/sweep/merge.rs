//! `groundtruth sweep merge DIR... --out DIR`: joins the directories of a sweep's shards (or of
//! interrupted runs) into one. Every input must hold the same sweep (`sweep.json` ids equal);
//! rows are united by `(key, method)` (a row found twice must be the same line), only complete
//! configurations (every method, in both files) are kept, and the output files are sorted by key
//! and method, so merging is deterministic whatever the order of the inputs. Configurations of
//! the sweep still missing are counted in the printed summary (and warned about on stderr).

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{Context, bail};
use serde_json::Value;

use super::results::{self, CSV_FILE, Found, IDENTITY_FILE, JSONL_FILE};
use crate::cli::shard::{claim_dir, complete_lines};

/// Arguments of `groundtruth sweep merge`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Sweep directories to join (shards of one sweep).
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Output directory (created; rewritten if it holds an earlier merge of the same sweep).
    #[arg(long)]
    out: PathBuf,
}

/// Runs `groundtruth sweep merge`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut identity: Option<Value> = None;
    let mut header: Option<String> = None;
    for d in &args.dirs {
        if d.canonicalize().ok().is_some_and(|c| args.out.canonicalize().ok() == Some(c)) {
            bail!("--out {}: is also an input; merge into a new directory", args.out.display());
        }
        let id = results::read_identity(d)?;
        match &identity {
            None => identity = Some(id),
            Some(first) if first.get("id") != id.get("id") || first.get("sweep") != id.get("sweep") => bail!(
                "{}: holds another sweep (id {}) than {} (id {}); merge only shards of one sweep",
                d.display(),
                id.get("id").unwrap_or(&Value::Null),
                args.dirs[0].display(),
                first.get("id").unwrap_or(&Value::Null)
            ),
            Some(_) => {}
        }
        if let Some(h) = complete_lines(&d.join(CSV_FILE))?.into_iter().next() {
            match &header {
                None => header = Some(h),
                Some(first) if *first != h => bail!("{}: its CSV header differs from the other inputs'", d.display()),
                Some(_) => {}
            }
        }
    }
    let mut identity = identity.context("no input directories")?;
    let header: Vec<String> = header.context("no input holds results.csv")?.split(',').map(str::to_string).collect();
    let methods: Vec<String> = identity["sweep"]["methods"]
        .as_array()
        .context("sweep.json without sweep.methods")?
        .iter()
        .filter_map(|m| m.as_str().map(str::to_string))
        .collect();
    let mut all = Found { csv: BTreeMap::new(), json: BTreeMap::new(), done: Default::default() };
    for d in &args.dirs {
        let found = results::read_found(d, &header, &methods)?;
        for (k, line) in found.csv.into_iter().filter(|((key, _), _)| found.done.contains(key)) {
            if let Some(old) = all.csv.get(&k)
                && *old != line
            {
                bail!("{}: row {} / {} differs from another input's", d.display(), k.0, k.1);
            }
            all.csv.insert(k, line);
        }
        all.json.extend(found.json.into_iter().filter(|((key, _), _)| found.done.contains(key)));
        all.done.extend(found.done);
    }
    identity["shard"] = Value::Null;
    claim_dir(&args.out, IDENTITY_FILE, &identity, &[CSV_FILE, JSONL_FILE], true)?;
    results::write_rows(&args.out, &header, &all, |_| true)?;
    let total = identity["configurations"].as_u64().unwrap_or(0);
    let merged = all.done.len() as u64;
    if merged < total {
        eprintln!(
            "warning: {} of {total} configurations are missing (a shard not run or not finished?)",
            total - merged
        );
    }
    let summary = serde_json::json!({
        "inputs": args.dirs.len(),
        "configurations": total,
        "merged": merged,
        "missing": total.saturating_sub(merged),
        "rows": all.csv.len(),
    });
    println!("{summary}");
    Ok(())
}
