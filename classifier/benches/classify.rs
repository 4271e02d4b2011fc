//! Criterion benchmark: features plus clustering of one synthetic 128 x 2048 frame on one core
//! (target: at most 5 ms in release), and the stages separately. Pin it to one core:
//! `taskset -c 0 cargo bench -p groundtruth-classifier`.

use classifier::nitsch::cluster::{ClusterWorkspace, cluster_candidates};
use classifier::nitsch::features::{Features, compute_features};
use classifier::synthetic::benchmark_frame;
use classifier::{Nitsch, NitschParams};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let cloud = benchmark_frame();
    let mut nitsch = Nitsch::new(NitschParams::default()).unwrap();
    let mut out = vec![false; cloud.len()];
    c.bench_function("nitsch_128x2048_features_and_clustering", |b| {
        b.iter(|| nitsch.classify_into(std::hint::black_box(&cloud), &mut out).unwrap())
    });
    let view = nitsch.view(&cloud);
    let params = nitsch.params.features;
    let mut f = Features::default();
    c.bench_function("features_128x2048", |b| {
        b.iter(|| compute_features(std::hint::black_box(&view), &params, &mut f))
    });
    // Clustering and cluster rules alone, on the features of the frame.
    nitsch.classify_into(&cloud, &mut out).unwrap();
    let threshold = nitsch.params.threshold;
    let candidate: Vec<bool> = nitsch.features.g_rho.iter().map(|&g| g >= threshold && g > 0.0).collect();
    let cluster_params = nitsch.params.clustering;
    let mut ws = ClusterWorkspace::default();
    let mut ground = vec![false; candidate.len()];
    c.bench_function("clustering_128x2048", |b| {
        b.iter(|| {
            cluster_candidates(
                std::hint::black_box(&view),
                &candidate,
                &nitsch.features.normal,
                &cluster_params,
                &mut ws,
            );
            ws.decide(view.points, ws.returns(), &cluster_params, &mut ground);
        })
    });
    let mut no_cluster = Nitsch::new(NitschParams { cluster: false, ..Default::default() }).unwrap();
    c.bench_function("nitsch_no_cluster_128x2048", |b| {
        b.iter(|| no_cluster.classify_into(std::hint::black_box(&cloud), &mut out).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
