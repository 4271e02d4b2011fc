//! Times features and clustering on the synthetic 128 x 2048 frame by the thread's own CPU time
//! (`/proc/thread-self/schedstat`, Linux), which stays meaningful on a loaded machine where wall
//! time does not. Run with `cargo run --release -p classifier --example bench_cpu`.

use classifier::synthetic::benchmark_frame;
use classifier::{Nitsch, NitschParams};

fn cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(0)
}

fn main() {
    let cloud = benchmark_frame();
    let mut nitsch = Nitsch::new(NitschParams::default()).unwrap();
    let mut out = vec![false; cloud.len()];
    let reps = 30;
    let (mut best, mut feat, mut clus) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    for _ in 0..reps {
        let t = cpu_ns();
        nitsch.classify_into(&cloud, &mut out).unwrap();
        let ms = (cpu_ns() - t) as f64 / 1e6;
        best = best.min(ms);
        feat = feat.min(nitsch.times.features_s * 1e3);
        clus = clus.min(nitsch.times.clustering_s * 1e3);
    }
    println!(
        "{{\"rows\": {}, \"cols\": {}, \"cpu_ms_total_min\": {best:.3}, \"wall_ms_features_min\": {feat:.3}, \"wall_ms_clustering_min\": {clus:.3}}}",
        cloud.rows, cloud.cols
    );
}
