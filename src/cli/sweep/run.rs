//! Running a sweep: claim the output directory, resume what is there, then go through the
//! (scene, seed) groups in order. Each group's scene is generated and its BVH built once
//! ([`PreparedScene`]), then the group's configurations of this shard that are not yet done run in
//! parallel (rayon), each appending its rows to both result files as it finishes. Nothing
//! proportional to the number of configurations is held, except the keys already done on resume.

use std::path::Path;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::Context;
use rayon::prelude::*;
use sim::scan::PreparedScene;

use super::expand::Space;
use super::progress::Progress;
use super::results::{self, CSV_FILE, IDENTITY_FILE, JSONL_FILE};
use crate::cli::shard::{AppendLog, Claim, Shard, claim_dir};

/// What a run did, printed as one JSON object.
#[derive(serde::Serialize, Debug)]
pub struct Summary {
    /// Configurations in the sweep.
    pub configurations: u64,
    /// The shard run.
    pub shard: String,
    /// Configurations of this shard.
    pub in_shard: u64,
    /// Of these, found done on resume.
    pub already_done: u64,
    /// Configurations run now.
    pub ran: u64,
    /// Rows appended now (configurations x methods).
    pub rows: u64,
    /// Scenes generated and prepared (BVH built), one per (scene, seed) with work.
    pub scenes_prepared: u64,
    /// Seconds spent generating and preparing scenes.
    pub prepare_s: f64,
    /// Wall-clock seconds of the whole run.
    pub seconds: f64,
    /// Configurations per second run now.
    pub configurations_per_s: f64,
    /// Worker threads.
    pub threads: usize,
}

/// Runs `space`'s configurations of `shard` into `out`.
pub fn run(space: &Space, out: &Path, shard: Shard, resume: bool, threads: usize) -> anyhow::Result<Summary> {
    let start = Instant::now();
    let identity = results::identity(space, Some(shard));
    let header = results::header(space);
    let claim = claim_dir(out, IDENTITY_FILE, &identity, &[CSV_FILE, JSONL_FILE], resume)?;
    let done = match claim {
        Claim::Fresh => Default::default(),
        Claim::Resume => {
            let found = results::read_found(out, &header, &space.sweep.methods)?;
            results::rewrite_done(out, &header, &found)?;
            found.done
        }
    };
    let csv = AppendLog::open(&out.join(CSV_FILE), Some(&header.join(",")))?;
    let jsonl = AppendLog::open(&out.join(JSONL_FILE), None)?;
    let logs = Mutex::new((csv, jsonl));
    let in_shard = shard.len_of(space.count);
    let already_done = done.len() as u64;
    let todo = in_shard.saturating_sub(already_done);
    let progress = Progress::new(todo, &format!("sweep {shard}"));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().context("starting the worker threads")?;
    // The groups (scene, seed) with work for this shard, in order; each one's configurations run
    // in parallel, and the next group's scene is prepared (built, its BVH made) while they run, so
    // no core waits on a preparation.
    let mut groups = Vec::new();
    for group in 0..space.groups() {
        let lo = group * space.group_size;
        let hi = lo + space.group_size;
        // This shard's indices in [lo, hi): first, first + N, ...
        let first = lo + (shard.index + shard.count - lo % shard.count) % shard.count;
        if first >= hi {
            continue;
        }
        let n = (hi - first).div_ceil(shard.count);
        let has_pending = (0..n).any(|j| !done.contains(&space.key(&space.decode(first + j * shard.count))));
        if has_pending {
            groups.push((lo, first, n));
        }
    }
    let prepare = |lo: u64| -> anyhow::Result<(crate::cli::common::LoadedScene, PreparedScene, f64)> {
        let t = Instant::now();
        let c0 = space.decode(lo);
        let (scene_name, seed) = (&space.sweep.scenes[c0.scene], space.sweep.seeds[c0.seed]);
        let scene = crate::cli::common::load_scene_full(scene_name, seed)
            .with_context(|| format!("scene `{scene_name}` seed {seed}"))?;
        let prepared = PreparedScene::new(&scene.mesh, sim::cast::Backend::Bvh)?;
        Ok((scene, prepared, t.elapsed().as_secs_f64()))
    };
    // Groups go in batches of (at least) as many as there are threads: a batch's configurations
    // form one parallel loop (no core idles at the end of each group), and the next batch is
    // prepared while it runs.
    let batch = threads.max(2);
    let batches: Vec<&[(u64, u64, u64)]> = groups.chunks(batch).collect();
    let prepare_batch =
        |b: &[(u64, u64, u64)]| -> anyhow::Result<Vec<_>> { b.par_iter().map(|&(lo, _, _)| prepare(lo)).collect() };
    let mut prepare_s = 0.0;
    let mut ran = 0u64;
    let mut next = match batches.first() {
        Some(b) => Some(pool.install(|| prepare_batch(b))?),
        None => None,
    };
    for (k, b) in batches.iter().enumerate() {
        let scenes = next.take().expect("prepared ahead");
        prepare_s += scenes.iter().map(|s| s.2).sum::<f64>();
        // Every pending configuration of the batch: (its group's place in the batch, j).
        let work: Vec<(usize, u64)> =
            b.iter().enumerate().flat_map(|(g, &(_, _, n))| (0..n).map(move |j| (g, j))).collect();
        let pending = |&(g, j): &(usize, u64)| {
            let (_, first, _) = b[g];
            let index = first + j * shard.count;
            debug_assert!(shard.contains(index));
            let c = space.decode(index);
            let key = space.key(&c);
            (!done.contains(&key)).then_some((g, c, key))
        };
        let evaluate_batch = || {
            work.par_iter()
                .filter_map(pending)
                .try_fold(
                    || (sim::OrderedCloud::default(), 0u64),
                    |(mut cloud, count), (g, c, key)| -> anyhow::Result<_> {
                        let (scene, prepared, _) = &scenes[g];
                        let rows = super::evaluate::evaluate(space, &c, &key, scene, prepared, &mut cloud)
                            .with_context(|| format!("configuration {} (key {key})", c.index))?;
                        let mut csv_text = String::new();
                        let mut json_text = String::new();
                        for r in &rows {
                            csv_text.push_str(&results::csv_line(r));
                            csv_text.push('\n');
                            json_text.push_str(&results::json_line(&header, r));
                            json_text.push('\n');
                        }
                        {
                            let mut logs = logs.lock().unwrap_or_else(|e| e.into_inner());
                            logs.0.append(&csv_text)?;
                            logs.1.append(&json_text)?;
                        }
                        progress.inc();
                        Ok((cloud, count + 1))
                    },
                )
                .map(|r| r.map(|(_, count)| count))
                .try_reduce(|| 0, |a, b| Ok(a + b))
        };
        let following = batches.get(k + 1).copied();
        let (ran_here, prepared_next) =
            pool.install(|| rayon::join(evaluate_batch, || following.map(prepare_batch).transpose()));
        ran += ran_here?;
        next = prepared_next?;
    }
    let prepared_count = groups.len() as u64;
    progress.finish();
    let (mut csv, mut jsonl) = logs.into_inner().unwrap_or_else(|e| e.into_inner());
    csv.sync()?;
    jsonl.sync()?;
    let seconds = start.elapsed().as_secs_f64();
    Ok(Summary {
        configurations: space.count,
        shard: shard.to_string(),
        in_shard,
        already_done,
        ran,
        rows: ran * space.sweep.methods.len() as u64,
        scenes_prepared: prepared_count,
        prepare_s,
        seconds,
        configurations_per_s: ran as f64 / seconds.max(1e-9),
        threads,
    })
}
