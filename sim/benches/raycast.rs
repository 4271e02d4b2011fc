//! Ray casting speed on the 1.3 M-triangle fixture terrain with one 128 x 2048 spinning-LiDAR frame
//! (262,144 rays): the BVH backend (the 4-wide tree with fan traversal, one ray at a time with and
//! without the previous-hit seed, obvhs's own BVH2 and CWBVH traversals; 1 and 2 threads) and the
//! parry reference. `cargo bench -p groundtruth-sim --bench raycast`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sim::cast::{BvhCaster, BvhLayout, BvhOptions, Caster, ParryCaster, fixture};

fn raycast(c: &mut Criterion) {
    let mesh = fixture::terrain_scene();
    let rays = fixture::lidar_rays(1);
    let mut g = c.benchmark_group("raycast_fixture_frame");
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.sample_size(10);
    let single = BvhOptions { packet_rays: 0, coherent: false, ..BvhOptions::default() };
    let variants = [
        ("bvh4-fan16", BvhOptions::default()),
        ("bvh4-fan8", BvhOptions { packet_rays: 8, ..BvhOptions::default() }),
        ("bvh4-single", single),
        ("bvh4-single-seeded", BvhOptions { coherent: true, ..single }),
        ("obvhs-bvh2", BvhOptions { layout: BvhLayout::Binary, ..single }),
        ("obvhs-cwbvh", BvhOptions { layout: BvhLayout::Wide, max_prims_per_leaf: 3, ..single }),
    ];
    for (name, options) in variants {
        let caster = BvhCaster::with_options(&mesh, options);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
            g.bench_function(format!("{name}/{threads}t"), |b| b.iter(|| pool.install(|| caster.cast_all(&rays))));
        }
    }
    let parry = ParryCaster::new(&mesh);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("thread pool");
    g.bench_function("parry/2t", |b| b.iter(|| pool.install(|| parry.cast_all(&rays))));
    g.finish();
    c.bench_function("bvh_build_fixture", |b| b.iter(|| BvhCaster::new(&mesh)));
}

criterion_group!(benches, raycast);
criterion_main!(benches);
