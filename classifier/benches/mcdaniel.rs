//! Criterion benchmark of McDaniel et al. on one 200 x 1081 sweep (`utm30lx-nodding` on
//! `forest-dense`, scene and scan seed 0): the whole frame (origins, stage 1, f1-f8, SVM,
//! propagation) with the bundled model, and the ray-tracing feature f8 alone.
//! `cargo bench -p groundtruth-classifier --bench mcdaniel`.

use classifier::mcdaniel::{self, Columns, FeatureParams, McDaniel, McDanielParams};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let scene = scenes::load("forest-dense", 0).unwrap();
    let rig = sim::Rig::preset("utm30lx-nodding").unwrap();
    let config = sim::scan::ScanConfig { ego_z_m: scene.ego_ground_z_m, ..Default::default() };
    let cloud = sim::scan::scan(&scene.mesh, &rig, &config).unwrap().remove(0).cloud;
    let mut m = McDaniel::new(mcdaniel::default_model().unwrap(), McDanielParams::default()).unwrap();
    c.bench_function("mcdaniel_200x1081_forest_dense", |b| {
        b.iter(|| m.classify(std::hint::black_box(&cloud)).unwrap())
    });
    let origins = classifier::sensor_origin::origins_for_cloud(&cloud, None).unwrap();
    let columns = Columns::build(&cloud, &FeatureParams::default());
    c.bench_function("mcdaniel_f8_200x1081_forest_dense", |b| {
        b.iter(|| mcdaniel::ray_trace::ray_trace_counts(std::hint::black_box(&cloud), &columns, &origins))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
