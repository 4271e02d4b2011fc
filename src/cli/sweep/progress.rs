//! Progress of a long run: an `indicatif` bar with rate and time left when stderr is a terminal,
//! otherwise a plain line on stderr at most every 5 s (and at the end), for logs and batch jobs.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Counts finished items of a known total.
pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
    plain: Mutex<Plain>,
    total: u64,
    label: String,
}

struct Plain {
    done: u64,
    start: Instant,
    last: Instant,
}

/// Interval between plain progress lines.
const PLAIN_EVERY: Duration = Duration::from_secs(5);

impl Progress {
    /// Progress over `total` items, labelled `label` (e.g. `sweep 0/4`).
    pub fn new(total: u64, label: &str) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = indicatif::ProgressBar::new(total);
            let style = indicatif::ProgressStyle::with_template(
                "{prefix} [{bar:40}] {pos}/{len} configurations  {per_sec}  {elapsed_precise} elapsed, {eta} left",
            )
            .map(|s| s.progress_chars("=> "))
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            bar.set_style(style);
            bar.set_prefix(label.to_string());
            bar
        });
        let now = Instant::now();
        Progress { bar, plain: Mutex::new(Plain { done: 0, start: now, last: now }), total, label: label.to_string() }
    }

    /// One more item finished.
    pub fn inc(&self) {
        let mut p = self.plain.lock().unwrap_or_else(|e| e.into_inner());
        p.done += 1;
        if let Some(bar) = &self.bar {
            bar.inc(1);
            return;
        }
        let now = Instant::now();
        if now - p.last >= PLAIN_EVERY || p.done == self.total {
            p.last = now;
            let secs = (now - p.start).as_secs_f64().max(1e-9);
            let rate = p.done as f64 / secs;
            let left = (self.total - p.done) as f64 / rate.max(1e-9);
            eprintln!(
                "{}: {}/{} configurations ({:.1} %), {:.1}/s, {:.0} s elapsed, ~{:.0} s left",
                self.label,
                p.done,
                self.total,
                100.0 * p.done as f64 / self.total.max(1) as f64,
                rate,
                secs,
                left
            );
        }
    }

    /// Ends the bar (leaves it on screen).
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish();
        }
    }
}
