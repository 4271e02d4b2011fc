//! Generation time of every bundled scene (target: under 1 s each in release), with its triangle
//! count printed once. Run: `cargo bench -p groundtruth-scenes --bench generate`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};

fn generate(c: &mut Criterion) {
    let mut group = c.benchmark_group("generate");
    group.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    for name in scenes::bundled_names() {
        let scene = scenes::load_bundled(name, 0).expect("bundled scene loads");
        eprintln!("{name}: {} triangles, {} vertices", scene.mesh.len(), scene.mesh.vertices.len());
        group.bench_function(name, |b| b.iter(|| scenes::load_bundled(black_box(name), black_box(0)).unwrap()));
    }
    group.finish();
}

criterion_group!(benches, generate);
criterion_main!(benches);
