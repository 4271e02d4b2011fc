//! Times the Nitsch method (features, clustering, cluster rules, echo planes) on the synthetic
//! 128 x 2048 frame: the thread's own CPU time per frame (`/proc/thread-self/schedstat`, Linux,
//! averaged over all repetitions), which stays meaningful on a loaded machine, and the wall time
//! per stage (min and median). Pin it to one core: `taskset -c 0`. Run with `cargo run --release -p groundtruth-classifier --example bench_cpu`.

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
    let reps = 100;
    nitsch.classify_into(&cloud, &mut out).unwrap();
    let (mut wall, mut feat, mut clus) = (Vec::new(), Vec::new(), Vec::new());
    // The scheduler updates the thread's CPU time only now and then (a tick), so it is read once
    // around all repetitions; wall times are per repetition (min and median).
    let cpu0 = cpu_ns();
    for _ in 0..reps {
        let t = std::time::Instant::now();
        nitsch.classify_into(&cloud, &mut out).unwrap();
        wall.push(t.elapsed().as_secs_f64() * 1e3);
        feat.push(nitsch.times.features_s * 1e3);
        clus.push(nitsch.times.clustering_s * 1e3);
    }
    let cpu_ms = (cpu_ns() - cpu0) as f64 / 1e6 / f64::from(reps);
    let stats = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        (v[0], v[v.len() / 2])
    };
    let ((w_min, w_med), (f_min, f_med), (c_min, c_med)) = (stats(&mut wall), stats(&mut feat), stats(&mut clus));
    println!(
        "{{\"rows\": {}, \"cols\": {}, \"cpu_ms_per_frame_mean\": {cpu_ms:.3}, \"wall_ms_total_min\": {w_min:.3}, \"wall_ms_total_median\": {w_med:.3}, \"wall_ms_features_min\": {f_min:.3}, \"wall_ms_features_median\": {f_med:.3}, \"wall_ms_clustering_min\": {c_min:.3}, \"wall_ms_clustering_median\": {c_med:.3}}}",
        cloud.rows, cloud.cols
    );
}
