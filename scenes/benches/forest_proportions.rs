//! Not a timing benchmark: scans the three forest scenes with a nodding UTM-30LX-like pattern (seed
//! 002: axis 0.55 m above ground, 270 deg at 0.25 deg, 200 scans from -75 to +55 deg pitch, 30 m
//! range) using the simulator's default caster, and prints the share of returns per seed-002
//! category (ground, bushes/shrubs, trunks, branches/leaves) next to the paper's Tables I-III.
//! Run: `cargo bench -p scenes --bench forest_proportions`.

use std::collections::{BTreeMap, BTreeSet};

use glam::Vec3;
use sim::SemanticClass;
use sim::cast::{Backend, Ray};

/// Paper's shares (ground, bushes, trunks, canopy) from Tables I-III.
const PAPER: [(&str, [f64; 4]); 3] = [
    ("forest-sparse", [53488.0, 0.0, 8324.0, 7786.0]),
    ("forest-moderate", [74161.0, 30987.0, 4483.0, 32154.0]),
    ("forest-dense", [65192.0, 67403.0, 11494.0, 10314.0]),
];

fn main() {
    let mut rays = Vec::new();
    let origin = Vec3::new(0.0, 0.0, 0.55);
    for s in 0..200 {
        let pitch = (-75.0f32 + 130.0 * s as f32 / 199.0).to_radians();
        for k in 0..1081 {
            let yaw = (-135.0f32 + 0.25 * k as f32).to_radians();
            let dir = Vec3::new(pitch.cos() * yaw.cos(), pitch.cos() * yaw.sin(), pitch.sin());
            rays.push(Ray { origin, dir, t_max: 30.0 });
        }
    }
    for (name, paper) in PAPER {
        let scene = scenes::load_bundled(name, 0).expect("bundled forest loads");
        let m = &scene.mesh;
        let trees: BTreeSet<u32> =
            m.surfaces.iter().filter(|s| s.class == SemanticClass::TRUNK).map(|s| s.instance).collect();
        let caster = Backend::default().build(m);
        let mut counts: BTreeMap<usize, u64> = BTreeMap::new();
        for hit in caster.cast_all(&rays).into_iter().flatten() {
            let s = m.surfaces[hit.triangle as usize];
            let cat = if s.class.is_ground() {
                0
            } else if s.class == SemanticClass::TRUNK {
                2
            } else if trees.contains(&s.instance) {
                3
            } else {
                1
            };
            *counts.entry(cat).or_default() += 1;
        }
        let total: u64 = counts.values().sum();
        let ptotal: f64 = paper.iter().sum();
        let share = |c: usize| 100.0 * *counts.get(&c).unwrap_or(&0) as f64 / total.max(1) as f64;
        println!(
            "{name}: {total} returns; ground {:.0}% (paper {:.0}%), bushes {:.0}% ({:.0}%), trunks {:.0}% ({:.0}%), canopy {:.0}% ({:.0}%)",
            share(0),
            100.0 * paper[0] / ptotal,
            share(1),
            100.0 * paper[1] / ptotal,
            share(2),
            100.0 * paper[2] / ptotal,
            share(3),
            100.0 * paper[3] / ptotal,
        );
    }
}
