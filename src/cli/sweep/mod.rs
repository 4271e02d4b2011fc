//! `groundtruth sweep`: sensor-mount sensitivity studies. A sweep file ([`config`]) names scenes,
//! rigs, seeds, methods and lists or ranges of mount and sensor parameters; the run covers their
//! product ([`expand`]), scanning, classifying and scoring every configuration ([`evaluate`]) in
//! parallel ([`run`]) and appending one row per configuration and method to `DIR/results.csv` and
//! `DIR/results.jsonl` ([`results`]). `--shard I/N` runs a deterministic 1/N of the
//! configurations and `--resume` continues a killed run ([`crate::cli::shard`]);
//! `sweep merge` joins shard directories ([`merge`]), `sweep plot` draws a metric against one or
//! two parameters ([`plot`]) and `sweep report` writes a Markdown summary ([`report`]).

mod config;
mod evaluate;
mod expand;
mod merge;
mod plot;
mod progress;
mod report;
mod results;
mod run;

use std::path::PathBuf;

use anyhow::Context;

use crate::cli::shard::Shard;

/// Arguments of `groundtruth sweep`.
#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    command: Option<Command>,
    /// The sweep file (TOML; see examples/sweep-mount.toml).
    #[arg(long, required = true)]
    config: Option<PathBuf>,
    /// Output directory: sweep.json, results.csv, results.jsonl.
    #[arg(long, required = true)]
    out: Option<PathBuf>,
    /// Run only shard I of N (0 <= I < N): configurations whose index is I modulo N.
    #[arg(long, value_parser = Shard::parse)]
    shard: Option<Shard>,
    /// Continue an interrupted run in --out (rows already complete are kept, not repeated).
    #[arg(long)]
    resume: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Allow a product of more than 10 million configurations.
    #[arg(long)]
    allow_large: bool,
}

#[derive(clap::Subcommand, Debug)]
enum Command {
    /// Join shard directories of one sweep into one directory (rows sorted by key and method).
    Merge(merge::Args),
    /// Plot a metric against one parameter (lines, a band over seeds) or two (heat map).
    Plot(plot::Args),
    /// Write a Markdown summary: best and worst configuration per method, and plots.
    Report(report::Args),
}

/// Runs `groundtruth sweep`.
pub fn run(args: Args) -> anyhow::Result<()> {
    match args.command {
        Some(Command::Merge(a)) => return merge::run(a),
        Some(Command::Plot(a)) => return plot::run(a),
        Some(Command::Report(a)) => return report::run(a),
        None => {}
    }
    let (Some(config), Some(out)) = (&args.config, &args.out) else {
        anyhow::bail!("--config and --out are required");
    };
    let threads = match args.threads {
        Some(0) => anyhow::bail!("--threads 0: allowed 1 ..= 1024"),
        Some(n) if n > 1024 => anyhow::bail!("--threads {n}: allowed 1 ..= 1024"),
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let text = std::fs::read_to_string(config).with_context(|| format!("reading {}", config.display()))?;
    let sweep = config::Sweep::parse(&text, &config.display().to_string())?;
    let space = expand::Space::new(sweep, args.allow_large).with_context(|| config.display().to_string())?;
    let summary = run::run(&space, out, args.shard.unwrap_or_default(), args.resume, threads)?;
    println!("{}", serde_json::to_string(&summary)?);
    Ok(())
}
