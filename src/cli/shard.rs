//! Machinery shared by the commands that split a large job over processes or machines and pick up
//! where a killed run stopped (`groundtruth sweep`, later `groundtruth dataset`):
//!
//! - [`Shard`]: `--shard I/N` (0-based, `0 <= I < N`, as Slurm's `SLURM_ARRAY_TASK_ID` with
//!   `--array=0-(N-1)` and Kubernetes' `JOB_COMPLETION_INDEX` count); item `k` of a job belongs to
//!   shard `k mod N`, so shards are disjoint, cover every item and interleave (each shard gets its
//!   share of every scene, not one scene each).
//! - [`stable_key`]: a 128-bit FNV-1a hash of a canonical description, as 32 hex digits; the same
//!   on every machine, build and Rust version (unlike `DefaultHasher`), so it keys rows and files
//!   across runs.
//! - [`claim_dir`]: an output directory records the identity of the job it holds
//!   (`DIR/<identity file>`); a directory holding another job's output is refused, and one holding
//!   this job's output is only continued with `--resume`.
//! - [`AppendLog`] and [`complete_lines`]: line-oriented result files appended one `write` of
//!   whole lines at a time and synced, so a killed run loses at most the lines being written; on
//!   resume, a torn last line (no newline) is dropped.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

/// One of `count` disjoint parts of a job (`--shard index/count`, 0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This part, `0 ..= count - 1`.
    pub index: u64,
    /// Number of parts, at least 1.
    pub count: u64,
}

impl Default for Shard {
    fn default() -> Self {
        Shard::ALL
    }
}

impl Shard {
    /// The whole job as one part.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Parses `I/N` with `0 <= I < N`, e.g. `0/4` .. `3/4`.
    pub fn parse(s: &str) -> anyhow::Result<Shard> {
        let bad = || {
            anyhow::anyhow!("--shard `{s}`: expected I/N with integers 0 <= I < N (e.g. 0/4 .. 3/4; I counts from 0)")
        };
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let index: u64 = i.trim().parse().map_err(|_| bad())?;
        let count: u64 = n.trim().parse().map_err(|_| bad())?;
        if count == 0 {
            bail!("--shard `{s}`: the shard count N must be at least 1");
        }
        if index >= count {
            bail!("--shard `{s}`: the shard index I must be in 0 ..= {} (I counts from 0)", count - 1);
        }
        Ok(Shard { index, count })
    }

    /// Whether item `k` of the job belongs to this shard.
    pub fn contains(&self, k: u64) -> bool {
        k % self.count == self.index
    }

    /// How many of the items `0 .. total` belong to this shard.
    pub fn len_of(&self, total: u64) -> u64 {
        total / self.count + u64::from(total % self.count > self.index)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// 128-bit FNV-1a of `bytes`.
pub fn fnv1a_128(bytes: &[u8]) -> u128 {
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    bytes.iter().fold(OFFSET, |h, &b| (h ^ u128::from(b)).wrapping_mul(PRIME))
}

/// The stable key of a canonical description: [`fnv1a_128`] as 32 lower-case hex digits.
pub fn stable_key(canonical: &str) -> String {
    format!("{:032x}", fnv1a_128(canonical.as_bytes()))
}

/// How an output directory was found by [`claim_dir`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Claim {
    /// New or empty of this job's files: start afresh.
    Fresh,
    /// Holds this job's earlier output and `--resume` was given: continue it.
    Resume,
}

/// Claims `dir` for the job whose identity is `identity` (a JSON value; its `"id"` field, a
/// string, is what must match). `identity_file` is the file in `dir` recording it and
/// `data_files` the job's output files there.
///
/// Refused: a directory whose identity file names another job; output files without an identity
/// file; this job's output files without `resume` (the message says to pass `--resume`).
/// Otherwise the identity file is written (atomically) and the directory created.
pub fn claim_dir(
    dir: &Path,
    identity_file: &str,
    identity: &serde_json::Value,
    data_files: &[&str],
    resume: bool,
) -> anyhow::Result<Claim> {
    let id = identity.get("id").and_then(|v| v.as_str()).context("identity without an \"id\"")?;
    let id_path = dir.join(identity_file);
    let present: Vec<&str> = data_files.iter().copied().filter(|f| dir.join(f).exists()).collect();
    if id_path.exists() {
        let text = std::fs::read_to_string(&id_path).with_context(|| format!("reading {}", id_path.display()))?;
        let old: serde_json::Value = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a JSON identity file; choose another --out", id_path.display()))?;
        let old_id = old.get("id").and_then(|v| v.as_str()).unwrap_or("");
        if old_id != id {
            bail!(
                "--out {}: holds the results of another job ({} id {old_id}, this one is {id}); choose another --out",
                dir.display(),
                identity_file
            );
        }
        if old != *identity {
            bail!(
                "--out {}: holds this job run with other settings ({}: {}); choose another --out",
                dir.display(),
                identity_file,
                text.trim()
            );
        }
    } else if !present.is_empty() {
        bail!(
            "--out {}: holds {} but no {identity_file}: not this job's output; choose another --out",
            dir.display(),
            present.join(", ")
        );
    }
    let claim = if present.is_empty() {
        Claim::Fresh
    } else if resume {
        Claim::Resume
    } else {
        bail!(
            "--out {}: already holds results of this job ({}); pass --resume to continue it, or choose another --out",
            dir.display(),
            present.join(", ")
        );
    };
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let text = serde_json::to_string_pretty(identity)? + "\n";
    sim::io::atomic::write_bytes_atomic(&id_path, text.as_bytes())?;
    Ok(claim)
}

/// The complete lines of a text file (each ended by `\n`, which is removed); a torn last line
/// without its newline (a run killed mid-write) is left out. A missing file has no lines.
pub fn complete_lines(path: &Path) -> anyhow::Result<Vec<String>> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e).with_context(|| format!("reading {}", path.display())),
    };
    let end = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
    let text = std::str::from_utf8(&bytes[..end]).with_context(|| format!("{}: not UTF-8", path.display()))?;
    Ok(text.lines().map(str::to_string).collect())
}

/// Writes `lines` (each followed by `\n`) to `path` atomically (temporary file and rename).
pub fn write_lines_atomic(path: &Path, lines: &[String]) -> anyhow::Result<()> {
    let mut text = String::with_capacity(lines.iter().map(|l| l.len() + 1).sum());
    for l in lines {
        text.push_str(l);
        text.push('\n');
    }
    sim::io::atomic::write_bytes_atomic(path, text.as_bytes())?;
    Ok(())
}

/// A result file appended in whole lines: each [`AppendLog::append`] is one `write` of complete
/// lines, so a killed process (even by SIGKILL: written data is in the kernel's page cache) leaves
/// every earlier line intact and at most the lines being written torn (which [`complete_lines`]
/// drops). The data is synced to disk (`fdatasync`) when [`SYNC_EVERY`] has passed since the last
/// sync and when the log is dropped, so a power cut loses at most that much of the latest rows
/// (and `--resume` recomputes them); syncing after every row would cost ~8 ms per row here.
pub struct AppendLog {
    file: File,
    path: PathBuf,
    last_sync: std::time::Instant,
}

/// Longest time appended lines stay unsynced.
pub const SYNC_EVERY: std::time::Duration = std::time::Duration::from_millis(250);

impl Drop for AppendLog {
    fn drop(&mut self) {
        // Best effort: an error here has no one to go to; the lines are written already.
        let _ = self.file.sync_data();
    }
}

impl AppendLog {
    /// Opens `path` for appending, creating it with `header` (one line) when it is missing or empty.
    pub fn open(path: &Path, header: Option<&str>) -> anyhow::Result<AppendLog> {
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .with_context(|| format!("opening {} for appending", path.display()))?;
        let mut log = AppendLog { file, path: path.to_path_buf(), last_sync: std::time::Instant::now() };
        let empty = log.file.metadata().map(|m| m.len() == 0).unwrap_or(true);
        if let (true, Some(h)) = (empty, header) {
            log.append(&format!("{h}\n"))?;
        }
        Ok(log)
    }

    /// Appends `text` (whole lines, each ending in `\n`) with one write; syncs the data when
    /// [`SYNC_EVERY`] has passed since the last sync.
    pub fn append(&mut self, text: &str) -> anyhow::Result<()> {
        debug_assert!(text.is_empty() || text.ends_with('\n'));
        self.file.write_all(text.as_bytes()).with_context(|| format!("appending to {}", self.path.display()))?;
        if self.last_sync.elapsed() >= SYNC_EVERY {
            self.sync()?;
        }
        Ok(())
    }

    /// Syncs the appended data to disk now.
    pub fn sync(&mut self) -> anyhow::Result<()> {
        self.file.sync_data().with_context(|| format!("syncing {}", self.path.display()))?;
        self.last_sync = std::time::Instant::now();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_partition() {
        assert_eq!(Shard::parse("0/4").unwrap(), Shard { index: 0, count: 4 });
        assert_eq!(Shard::parse("3/4").unwrap(), Shard { index: 3, count: 4 });
        for bad in ["5/4", "4/4", "0/0", "1", "a/b", "-1/4", "1/-4", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        let total = 10;
        let shards: Vec<Shard> = (0..3).map(|i| Shard { index: i, count: 3 }).collect();
        for k in 0..total {
            assert_eq!(shards.iter().filter(|s| s.contains(k)).count(), 1);
        }
        assert_eq!(shards.iter().map(|s| s.len_of(total)).collect::<Vec<_>>(), vec![4, 3, 3]);
        assert_eq!(Shard::ALL.len_of(7), 7);
    }

    #[test]
    fn stable_key_is_fnv1a_128() {
        // Published FNV-1a 128 test vectors.
        assert_eq!(stable_key(""), "6c62272e07bb014262b821756295c58d");
        assert_eq!(stable_key("a"), "d228cb696f1a8caf78912b704e4a8964");
    }

    #[test]
    fn torn_last_line_is_dropped_and_dir_claims_checked() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        let mut log = AppendLog::open(&p, Some("a,b")).unwrap();
        log.append("1,2\n3,4\n").unwrap();
        drop(log);
        std::fs::OpenOptions::new().append(true).open(&p).unwrap().write_all(b"5,").unwrap();
        assert_eq!(complete_lines(&p).unwrap(), vec!["a,b", "1,2", "3,4"]);
        // Reopening does not repeat the header.
        AppendLog::open(&p, Some("a,b")).unwrap();
        assert_eq!(complete_lines(&p).unwrap().len(), 3);

        let out = dir.path().join("out");
        let id = serde_json::json!({"id": "x1"});
        assert_eq!(claim_dir(&out, "job.json", &id, &["r.csv"], false).unwrap(), Claim::Fresh);
        std::fs::write(out.join("r.csv"), "a\n").unwrap();
        let e = claim_dir(&out, "job.json", &id, &["r.csv"], false).unwrap_err().to_string();
        assert!(e.contains("--resume"), "{e}");
        assert_eq!(claim_dir(&out, "job.json", &id, &["r.csv"], true).unwrap(), Claim::Resume);
        let other = serde_json::json!({"id": "x2"});
        let e = claim_dir(&out, "job.json", &other, &["r.csv"], true).unwrap_err().to_string();
        assert!(e.contains("another job"), "{e}");
    }
}
