//! Seed 002's forests look like the paper's: one nod of the UTM-30LX at the paper's mount gives,
//! per scene, the paper's shares of ground, bushes/shrubs, trunks and branches/leaves (each within
//! 20 % of the paper's share, relative) and its fraction of beams with a return (within 15
//! percentage points); and a vehicle standing on the forest track sees ground with every roof rig.
//! `cargo run --release -p gt-tests --example forest_shares -- --seeds 0,1,2,3,4 --roof` prints the
//! same figures for more seeds.

use gt_tests::forests::{self, NEAR_M, PAPER, ROOF_RIGS};
use sim::SemanticClass;

/// Seeds asserted here (the example checks more).
const SEEDS: [u64; 3] = [0, 1, 2];

#[test]
fn nodding_scans_of_the_forests_give_the_papers_shares() {
    for paper in &PAPER {
        let rig = paper.load_rig();
        let expect = paper.shares();
        for seed in SEEDS {
            let c = forests::measure(paper.scene, &rig, seed);
            let (rel, points) = forests::deviation(paper, &c);
            let got = c.shares();
            eprintln!(
                "{} seed {seed}: returns {:.3} (paper {:.3}), shares {got:.3?} (paper {expect:.3?})",
                paper.scene,
                c.returns_fraction(),
                paper.returns_fraction()
            );
            assert_eq!(c.other, 0, "{} seed {seed}: returns of other classes", paper.scene);
            for (k, name) in forests::CATEGORIES.iter().enumerate() {
                if expect[k] == 0.0 {
                    assert_eq!(c.per_category[k], 0, "{} seed {seed}: {name} the paper has none of", paper.scene);
                } else {
                    assert!(
                        rel[k] <= 0.2,
                        "{} seed {seed}: {name} share {:.3}, paper {:.3} ({:.0} % off)",
                        paper.scene,
                        got[k],
                        expect[k],
                        100.0 * rel[k]
                    );
                }
            }
            assert!(points.abs() <= 15.0, "{} seed {seed}: returns {points:+.1} points from the paper's", paper.scene);
        }
    }
}

#[test]
fn every_roof_rig_sees_ground_around_the_vehicle_in_every_forest() {
    let rigs: Vec<sim::Rig> = ROOF_RIGS.iter().map(|name| sim::Rig::preset(name).unwrap()).collect();
    for paper in &PAPER {
        for seed in SEEDS {
            for (name, c) in ROOF_RIGS.iter().zip(forests::measure_rigs(paper.scene, &rigs, seed)) {
                let near = c.near_ground as f64 / c.returns as f64;
                eprintln!(
                    "{name} {} seed {seed}: {} returns, ground {:.3}, within {NEAR_M} m {near:.3}",
                    paper.scene,
                    c.returns,
                    c.ground_share()
                );
                // Measured minimum over seeds 0..4: 13.6 % ground, 12.3 % ground within 20 m
                // (vlp16-roof on forest-dense, where the vehicle stands on the track among
                // bushes; hdl64e-roof sees 30 % there). See the forest module docs.
                assert!(c.ground_share() >= 0.12, "{name} {} seed {seed}: ground {:.3}", paper.scene, c.ground_share());
                assert!(near >= 0.10, "{name} {} seed {seed}: ground within {NEAR_M} m {near:.3}", paper.scene);
            }
        }
    }
}

#[test]
fn bushes_are_their_own_class_and_map_to_vegetation_in_kitti_and_medium_vegetation_in_las() {
    let spec =
        gt_tests::ScanSpec { scene: "forest-moderate".into(), rig: "utm30lx-nodding".into(), ..Default::default() };
    let cloud = &gt_tests::scan_spec(&spec).0[0].cloud;
    let count =
        |class: SemanticClass| (0..cloud.len()).filter(|&i| cloud.has_return(i) && cloud.label[i] == class).count();
    let (bush, canopy, trunk) =
        (count(SemanticClass::BUSH), count(SemanticClass::VEGETATION), count(SemanticClass::TRUNK));
    assert!(bush > 1000 && canopy > 1000 && trunk > 100, "bush {bush}, canopy {canopy}, trunk {trunk}");
    // SemanticKITTI `.label`: bushes are written as 70 vegetation, so the standard label configs read them.
    let (_, labels, n) = sim::io::kitti::encode(cloud, None).unwrap();
    assert_eq!(n, cloud.returns());
    let kitti: Vec<u32> =
        labels.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) & 0xFFFF).collect();
    assert_eq!(kitti.iter().filter(|&&l| l == 73).count(), 0);
    assert_eq!(kitti.iter().filter(|&&l| l == 70).count(), bush + canopy);
    assert_eq!(kitti.iter().filter(|&&l| l == 71).count(), trunk);
    // LAS: ASPRS 4 (medium vegetation) for bushes, 5 (high vegetation) for canopy and trunks.
    let (bytes, n) = sim::io::las::encode(std::path::Path::new("forest.las"), cloud).unwrap();
    let offset = u32::from_le_bytes(bytes[96..100].try_into().unwrap()) as usize;
    let record = usize::from(u16::from_le_bytes(bytes[105..107].try_into().unwrap()));
    let classes: Vec<u8> = (0..n).map(|k| bytes[offset + k * record + 16]).collect();
    assert_eq!(classes.iter().filter(|&&c| c == 4).count(), bush);
    assert_eq!(classes.iter().filter(|&&c| c == 5).count(), canopy + trunk);
}
