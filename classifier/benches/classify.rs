//! Criterion benchmark: features plus clustering of one synthetic 128 x 2048 frame on one core
//! (target: at most 5 ms in release), and the stages separately.

use classifier::features::{Features, compute_features};
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
