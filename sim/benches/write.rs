//! Writing one 128 x 2048 frame (OS1-128 size, ~90 % returns) in all four formats (PCD binary,
//! PLY, KITTI, LAS) with `write_frame`, and each format alone. Target: all four under 50 ms.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use sim::io::formats::{Formats, FrameContext, write_frame};
use sim::{OrderedCloud, SemanticClass};

/// A 128 x 2048 frame: a ground disc below the sensor and a ring of walls; 1 cell in 10 empty.
fn frame() -> OrderedCloud {
    let (rows, cols) = (128, 2048);
    let mut c = OrderedCloud::empty(rows, cols, 1);
    for row in 0..rows {
        for col in 0..cols {
            let i = c.index(0, row, col);
            c.ring[i] = row as u16;
            c.column[i] = col as u32;
            c.sensor[i] = 0;
            c.time_s[i] = col as f64 * 0.1 / cols as f64;
            if (row * 31 + col * 17) % 10 == 0 {
                continue;
            }
            let az = col as f32 / cols as f32 * std::f32::consts::TAU;
            let ground = row < 64;
            let r = if ground { 3.0 + row as f32 * 0.5 } else { 40.0 };
            let p = Vec3::new(r * az.cos(), r * az.sin(), if ground { -1.9 } else { (row - 64) as f32 * 0.2 });
            c.point_in_vehicle[i] = p;
            c.range_m[i] = p.length();
            c.intensity[i] = 0.3;
            c.label[i] = if ground { SemanticClass::ROAD } else { SemanticClass::BUILDING };
            c.ground[i] = ground;
            c.normal[i] = Vec3::Z;
        }
    }
    c
}

fn bench_write(c: &mut Criterion) {
    let cloud = frame();
    // `GT_BENCH_DIR` picks where the files go (e.g. /dev/shm to leave out the disk's fsync cost).
    let dir = match std::env::var_os("GT_BENCH_DIR") {
        Some(base) => tempfile::tempdir_in(base),
        None => tempfile::tempdir(),
    }
    .expect("temp dir");
    let ctx = FrameContext { index: 0, sensor_from_vehicle: None };
    let mut group = c.benchmark_group("write_128x2048");
    group.sample_size(20);
    for (name, list) in
        [("all4", "pcd,ply,kitti,las"), ("pcd", "pcd"), ("ply", "ply"), ("kitti", "kitti"), ("las", "las")]
    {
        let formats = Formats::parse(list).expect("formats");
        group.bench_function(name, |b| {
            b.iter(|| black_box(write_frame(dir.path(), &cloud, &ctx, &formats).expect("write")))
        });
    }
    group.finish();
    let mut group = c.benchmark_group("encode_128x2048");
    group.sample_size(10);
    let path = dir.path().join("x");
    group.bench_function("pcd", |b| b.iter(|| black_box(sim::io::pcd::encode(&cloud, false).expect("pcd"))));
    group.bench_function("ply", |b| b.iter(|| black_box(sim::io::ply::encode(&cloud).expect("ply"))));
    group.bench_function("kitti", |b| b.iter(|| black_box(sim::io::kitti::encode(&cloud, None).expect("kitti"))));
    group.bench_function("las", |b| b.iter(|| black_box(sim::io::las::encode(&path, &cloud).expect("las"))));
    group.finish();
}

criterion_group!(benches, bench_write);
criterion_main!(benches);
