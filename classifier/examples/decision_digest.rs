//! Prints a digest (FNV-1a over the exact bits) of the features, cluster roots and decisions of the
//! Nitsch method on synthetic frames with dropouts and noise, under several parameter sets. Run it
//! before and after a performance change: identical lines mean identical outputs.
//! `cargo run --release -p groundtruth-classifier --example decision_digest`

use classifier::nitsch::neighbours::Wrap;
use classifier::synthetic::{SyntheticSensor, benchmark_frame, car, flat_ground};
use classifier::{Nitsch, NitschParams};
use glam::Vec3;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

struct Fnv(u64);

impl Fnv {
    fn add(&mut self, x: u32) {
        for b in x.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
        }
    }
}

/// Drops a fraction of the returns and adds z noise (seeded).
fn damage(cloud: &mut sim::OrderedCloud, drop: f32, noise_m: f32, seed: u64) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    for i in 0..cloud.point_in_vehicle.len() {
        if !cloud.point_in_vehicle[i].is_finite() {
            continue;
        }
        if rng.random::<f32>() < drop {
            cloud.point_in_vehicle[i] = Vec3::NAN;
            cloud.range_m[i] = f32::NAN;
        } else {
            cloud.point_in_vehicle[i].z += (rng.random::<f32>() - 0.5) * 2.0 * noise_m;
        }
    }
}

fn digest(cloud: &sim::OrderedCloud, params: NitschParams) -> (u64, u64, usize, usize) {
    let mut nitsch = Nitsch::new(params).unwrap();
    let out = nitsch.classify(cloud).unwrap();
    let (mut f, mut d) = (Fnv(0xcbf2_9ce4_8422_2325), Fnv(0xcbf2_9ce4_8422_2325));
    let feats = &nitsch.features;
    for i in 0..feats.g_rho.len() {
        for v in [feats.normal[i].x, feats.normal[i].y, feats.normal[i].z, feats.n_rho[i], feats.g_rho[i]] {
            f.add(v.to_bits());
        }
    }
    if params.cluster {
        for i in 0..feats.g_rho.len() {
            d.add(nitsch.workspace.cluster_of(i).map_or(u32::MAX, |r| r as u32));
        }
    }
    for &g in &out {
        d.add(u32::from(g));
    }
    let clusters = if params.cluster { nitsch.workspace.cluster_count() } else { 0 };
    (f.0, d.0, out.iter().filter(|&&g| g).count(), clusters)
}

fn main() {
    let bench = benchmark_frame();
    let mut damaged = bench.clone();
    damage(&mut damaged, 0.1, 0.03, 7);
    let mut holey = bench.clone();
    damage(&mut holey, 0.4, 0.05, 11);
    let shapes = [flat_ground(), car(8.0, 1.0, 0.0), car(15.0, -4.0, 0.0)];
    let mut forward = SyntheticSensor::forward(64, 700, -20.0, 5.0, 120.0, 1.6).scan(&shapes);
    damage(&mut forward, 0.2, 0.02, 3);
    let base = NitschParams::default();
    let mut variants = vec![("default", base)];
    let mut p = base;
    p.features.occlusion_ratio = 0.1;
    p.features.max_neighbour_distance_m = 3.0;
    p.features.min_valid_pairs = 3;
    variants.push(("occl+maxdist", p));
    let mut p = base;
    p.neighbours.max_col_gap = 4;
    p.neighbours.wrap = Wrap::Never;
    p.clustering.link_tolerance_rel = 0.02;
    p.clustering.near_search_m = 6.0;
    variants.push(("gap4+nowrap+rel", p));
    let mut p = base;
    p.clustering.max_plane_offset_m = 0.0;
    p.neighbours.max_col_gap = 1;
    p.neighbours.wrap = Wrap::Always;
    variants.push(("gap1+wrap+noplane", p));
    variants.push(("no-cluster", NitschParams { cluster: false, ..base }));
    for (cname, cloud) in [("bench", &bench), ("damaged", &damaged), ("holey", &holey), ("forward", &forward)] {
        for (pname, params) in &variants {
            let (f, d, ground, clusters) = digest(cloud, *params);
            println!("{cname:8} {pname:18} features {f:016x} decisions {d:016x} ground {ground:6} clusters {clusters}");
        }
    }
}
