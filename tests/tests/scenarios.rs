//! Scenario tests on the hard cases of seed 000 and 002: ramps, basins (the elevated target beyond
//! a lowered surface), elevated non-ground surfaces, forests, and the sensor at other mounts.

use gt_tests::run;

#[test]
fn ramp_up_and_down_stay_ground() {
    for scene in ["ramp-up", "ramp-down"] {
        let s = run(scene, "hdl64e-roof", "nitsch", 1, 0.0);
        let sc = s.eval.pooled.scores();
        eprintln!("{scene}: {sc:?}");
        assert!(sc.f1 >= 0.97, "{scene}: F1 {}", sc.f1);
        assert!(sc.fpr <= 0.05, "{scene}: FPR {}", sc.fpr);
    }
}

#[test]
fn ground_beyond_a_basin_is_ground() {
    let s = run("basin", "os1-128-roof", "nitsch", 1, 0.0);
    let c = &s.frames[0].cloud;
    let d = &s.decisions[0];
    // Ground far from the vehicle (beyond the basin) must still be found: recall over ground
    // returns farther than 25 m.
    let far: Vec<usize> = (0..c.len()).filter(|&i| c.has_return(i) && c.ground[i] && c.range_m[i] > 25.0).collect();
    assert!(far.len() > 1000, "far ground seen ({})", far.len());
    let found = far.iter().filter(|&&i| d[i]).count();
    let recall = found as f64 / far.len() as f64;
    eprintln!("basin far-ground recall {recall}");
    assert!(recall >= 0.9, "far ground recall {recall}");
    assert!(s.eval.pooled.scores().f1 >= 0.97);
}

#[test]
fn flat_roofs_docks_and_tables_are_not_ground() {
    let s = run("elevated", "hdl64e-roof", "nitsch", 1, 0.0);
    let c = &s.frames[0].cloud;
    let d = &s.decisions[0];
    // Flat, horizontal, non-ground returns (roofs, docks, tables): normal within 10 deg of +z.
    let flat_non_ground: Vec<usize> =
        (0..c.len()).filter(|&i| c.has_return(i) && !c.ground[i] && c.normal[i].z > 0.985).collect();
    assert!(flat_non_ground.len() > 200, "elevated flat surfaces seen ({})", flat_non_ground.len());
    let called = flat_non_ground.iter().filter(|&&i| d[i]).count();
    let rate = called as f64 / flat_non_ground.len() as f64;
    eprintln!("elevated flat non-ground called ground: {rate}");
    assert!(rate <= 0.2, "{rate} of flat non-ground surfaces called ground");
}

#[test]
fn forest_ground_is_found_under_the_trees_by_the_nodding_laser() {
    // Seed 002's sparse-scene rig: the nodding UTM-30LX with 180 deg of its field of view, ideal
    // ranges. (With 1 cm range noise the method loses ground near the sensor, where neighbouring
    // beams are only millimetres apart; with the full 270 deg the beams behind the tilt axis run
    // down as the nod goes up, so their rows are in reverse elevation order. Both are documented
    // limits of an automotive method on this rig.)
    let rig_file = concat!(env!("CARGO_MANIFEST_DIR"), "/../sim/rigs/nodding-180.toml");
    let rig = sim::Rig::load(rig_file).unwrap();
    for name in ["forest-sparse", "forest-moderate"] {
        let spec = gt_tests::ScanSpec { scene: name.to_string(), ideal: true, ..Default::default() };
        let frames = gt_tests::scan_on(&spec.load_scene().unwrap(), &rig, &spec);
        assert_eq!((frames[0].cloud.rows, frames[0].cloud.cols), (200, 721));
        let sc = gt_tests::classify(frames, "nitsch").eval.pooled.scores();
        eprintln!("{name} nodding-180 ideal: {sc:?}");
        assert!(sc.f1 >= 0.98, "{name}: F1 {}", sc.f1);
    }
}

#[test]
fn plane_fitting_is_clearly_worse_than_the_method_on_rural_roads() {
    let nitsch = run("rural", "lux-roof-4", "nitsch", 1, 0.0).eval.pooled.scores();
    let ransac = run("rural", "lux-roof-4", "ransac", 1, 0.0).eval.pooled.scores();
    eprintln!("rural: nitsch {nitsch:?} ransac {ransac:?}");
    assert!(nitsch.acc > ransac.acc + 0.1, "nitsch accuracy {} vs ransac {}", nitsch.acc, ransac.acc);
}

#[test]
fn nitsch_on_the_270_deg_nodding_rig_finds_the_ground_as_at_180() {
    // The rear flanks of the 270 deg fan run down in elevation as the nod goes up; the method flips
    // those columns' rows (classifier::nitsch::row_order) and must then do as well as at 180 deg.
    let rig_180 = sim::Rig::load(concat!(env!("CARGO_MANIFEST_DIR"), "/../sim/rigs/nodding-180.toml")).unwrap();
    let rig_270 = sim::Rig::preset("utm30lx-nodding").unwrap();
    for name in ["forest-sparse", "forest-moderate", "forest-dense"] {
        let spec = gt_tests::ScanSpec { scene: name.to_string(), ideal: true, ..Default::default() };
        let scene = spec.load_scene().unwrap();
        let f1 = |rig: &sim::Rig| {
            let frames = gt_tests::scan_on(&scene, rig, &spec);
            gt_tests::classify(frames, "nitsch").eval.pooled.scores()
        };
        let (s180, s270) = (f1(&rig_180), f1(&rig_270));
        eprintln!("{name} ideal nitsch: 180 deg {s180:?}\n  270 deg {s270:?}");
        assert!(s270.recall >= s180.recall - 0.02, "{name}: recall 270 deg {} vs 180 deg {}", s270.recall, s180.recall);
        assert!(s270.f1 >= s180.f1 - 0.02, "{name}: F1 270 deg {} vs 180 deg {}", s270.f1, s180.f1);
    }
}

/// Nitsch's misses beside the car (issue 36, item 4). On real street frames (SemanticKITTI sequence
/// 00, frames 0-2) nearly all of `nitsch`'s missed ground within 10 m of the sensor is not a ground
/// candidate at all (947 of 958 in frame 0): its normal leans more than 25 deg (`g_rho` under the
/// threshold), on curb faces and the kerb edges of sidewalks, which SemanticKITTI labels sidewalk
/// (ground). Ordering, neighbours and clustering are not the cause (11 of 958 sit in rejected
/// clusters of 1-3 points). It is the paper's method: ground is where the surface normal is
/// near-vertical, and a curb's face is vertical. Our city's curbs are labelled the same way
/// (sidewalk), and the test keeps the limit measured: `nitsch` finds few curb-face returns near
/// the sensor (measured: 0.105 of 1,358 within 15 m), the learned method, which has seen curbs
/// labelled ground, most of them (0.946).
#[test]
fn curb_faces_are_sidewalk_that_normals_cannot_call_ground() {
    let faces = |s: &gt_tests::Scenario| -> (usize, usize) {
        let (c, d) = (&s.frames[0].cloud, &s.decisions[0]);
        // Curb faces near the sensor: sidewalk returns whose true normal is horizontal.
        let face: Vec<usize> = (0..c.len())
            .filter(|&i| {
                c.has_return(i)
                    && c.label[i] == sim::SemanticClass::SIDEWALK
                    && c.normal[i].z.abs() < 0.3
                    && c.range_m[i] < 15.0
            })
            .collect();
        (face.len(), face.iter().filter(|&&i| d[i]).count())
    };
    let (n, nitsch) = faces(&run("city", "hdl64e-roof", "nitsch", 1, 0.0));
    let (_, learned) = faces(&run("city", "hdl64e-roof", "learned", 1, 0.0));
    let (rn, rl) = (nitsch as f64 / n as f64, learned as f64 / n as f64);
    eprintln!("curb faces within 15 m: {n}; nitsch finds {rn:.3}, learned {rl:.3}");
    assert!(n >= 100, "curb faces seen: {n}");
    assert!(rn <= 0.5, "nitsch finds {rn} of the curb faces: the documented limit changed");
    assert!(rl >= 0.7, "learned finds {rl} of the curb faces");
}
