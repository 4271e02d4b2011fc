//! Property tests of our ground classifiers (`nitsch`, `ransac`, `grid`, `mcdaniel`, `learned`) on the hard
//! cases, drawn with the strategies of `groundtruth_scenario::strategies`: ramps up and down,
//! basins, raised plateaus beside flat non-ground tops, hills, sensor mounts, noise on and off.
//!
//! Every property states, per method, a bound on a region score (the region definitions are
//! documented on `groundtruth_scenario::Region`). A method whose known limit keeps it from a
//! meaningful bound has `None` in the table and a named regression test below documenting the
//! limit with its numbers. Each case prints `PROP <property> <method> <value>` lines; the worst
//! values of the CI-sized and the long run are in the closing comment of each bound table.
//!
//! Case counts are CI-sized (4 cases per property) and the cases drawn are fixed (seed 0);
//! `GT_PROPTEST_CASES=N` raises every property to N cases (the long run used N = 64),
//! `GT_PROPTEST_SEED=S` draws other ones.

use groundtruth_scenario::strategies::{self, config};
use groundtruth_scenario::{Decisions, Region, RegionScore, Scan, Scenario};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const METHODS: [&str; 5] = ["nitsch", "ransac", "grid", "mcdaniel", "learned"];

/// A bound per method: `Some(b)` asserted, `None` a documented known limit (value printed only).
type Bounds = [Option<f64>; 5];

/// Which way a bound goes.
#[derive(Clone, Copy)]
enum Bound {
    /// The value must be at least the bound (recall).
    AtLeast,
    /// The value must be at most the bound (false-ground rate).
    AtMost,
}

/// Decisions of every method on `scan`.
fn decide_all(scan: &Scan) -> Result<Vec<Decisions>, TestCaseError> {
    METHODS.iter().map(|m| scan.classify(m).map_err(|e| TestCaseError::fail(format!("{m}: {e}")))).collect()
}

/// Scores `region` for every method and checks `metric` against `bounds`.
#[allow(clippy::too_many_arguments)]
fn check(
    property: &str,
    case: &str,
    scan: &Scan,
    decisions: &[Decisions],
    region: &Region,
    metric: fn(&RegionScore) -> f64,
    way: Bound,
    bounds: &Bounds,
) -> Result<(), TestCaseError> {
    for ((method, d), bound) in METHODS.iter().zip(decisions).zip(bounds) {
        let s = scan.score(region, d).map_err(|e| TestCaseError::fail(format!("{case}: {e}")))?;
        let v = metric(&s);
        eprintln!("PROP {property} {method} {v:.4} ({case}; {s})");
        if let Some(b) = *bound {
            let ok = match way {
                Bound::AtLeast => v >= b,
                Bound::AtMost => v <= b,
            };
            prop_assert!(ok, "{property}: {method} {v:.4} against bound {b} on {case}: {s}");
        }
    }
    Ok(())
}

fn recall(s: &RegionScore) -> f64 {
    s.recall()
}

fn false_ground(s: &RegionScore) -> f64 {
    s.false_ground_rate()
}

fn scan(s: Scenario) -> Result<Scan, TestCaseError> {
    s.scan().map_err(|e| TestCaseError::fail(e.to_string()))
}

// Bounds, in method order nitsch, ransac, grid, mcdaniel, learned. Comments: worst value seen per
// method in the long run (GT_PROPTEST_CASES=64), "-" where the bound is a documented known limit.
// learned (the bundled model), worst of 64 cases each: up-ramp recall 0.985, down-ramp recall
// 0.974, beyond-basin recall 0.9997, basin-floor recall 1.0, roof false ground 0.012, flat-top
// false ground 0.057, plateau recall 0.869, hill recall 1.0, hill false ground 0.018, mount recall
// 0.991, mount false ground 0.0056.

/// Ramp-surface recall on up ramps 0-20 deg, 8-20 m ahead, HDL-64E, noise on or off (steep ramps
/// closer than that: `steep_ramps_close_up_with_noise`; 25 m ahead: `nitsch_drops_steep_ramps_25_m_ahead`).
/// ransac: one plane for the whole cloud (known limit, `ransac_fits_one_plane`); mcdaniel: the
/// bundled model, trained on forests, rejects most ramp surfaces (`mcdaniel_forest_model_on_ramps`).
const UP_RAMP_RECALL: Bounds = [Some(0.95), None, Some(0.80), None, Some(0.97)];
/// Ramp-surface recall on down ramps 2-20 deg, 3-5 m ahead (beyond about 9 m a 12 deg drop is hidden
/// from a roof-mounted sensor, so the region would be empty).
/// (mcdaniel: 0.63-1.0, `mcdaniel_forest_model_on_ramps`.)
const DOWN_RAMP_RECALL: Bounds = [Some(0.95), None, Some(0.70), None, Some(0.95)];
/// Recall of the ground beyond a basin 0.3-3 m deep with a 2-20 m bottom.
const BEYOND_BASIN_RECALL: Bounds = [Some(0.97), Some(0.97), Some(0.94), Some(0.88), Some(0.99)];
/// Recall of the basin floor (ransac: one plane, `ransac_fits_one_plane`).
const BASIN_FLOOR_RECALL: Bounds = [Some(0.97), None, Some(0.97), Some(0.97), Some(0.99)];
/// False-ground rate of vehicle roofs (car, van, truck; elevated scenes, any seed, noise on or off).
/// nitsch: up to 0.41 when cars stand a few metres beside the sensor
/// (`nitsch_close_car_roofs`); grid: up to 0.122 (scene seed 972; its 2D cells merge car bonnets
/// with the yard around them).
const ROOF_FALSE_GROUND: Bounds = [Some(0.45), Some(0.05), Some(0.15), Some(0.05), Some(0.03)];
/// False-ground rate of every flat raised non-ground top (loading dock 1.2-3 m, platforms 0.6-3 m,
/// tables, roofs); lower platforms are a known limit (`low_platforms_look_like_ground`). nitsch and
/// grid as for the roofs (grid up to 0.103 at scene seed 156).
const FLAT_TOP_FALSE_GROUND: Bounds = [Some(0.45), Some(0.05), Some(0.15), Some(0.15), Some(0.08)];
/// Recall of the plateau tops (raised ground 0.3-1 m, below the sensor; ransac: one plane).
/// (mcdaniel: 0.0-0.91, the forest model; `mcdaniel_forest_model_on_ramps`.)
/// (nitsch and grid: 0.53 at scene seed 979, `plateau_seed_979`; >= 0.84 elsewhere.)
const PLATEAU_RECALL: Bounds = [Some(0.50), None, Some(0.50), None, Some(0.80)];
/// Recall of the slope the ego stands on, 0-25 deg.
const HILL_RECALL: Bounds = [Some(0.97), Some(0.97), Some(0.97), Some(0.97), Some(0.99)];
/// False-ground rate of the hill's non-ground.
const HILL_FALSE_GROUND: Bounds = [Some(0.03), Some(0.05), Some(0.03), Some(0.05), Some(0.03)];
/// Ground recall in the city at mounts 1.2-3 m, pitch -10..10 deg, roll -5..5 deg (lower mounts:
/// `low_mounts_lose_ground`).
const MOUNT_RECALL: Bounds = [Some(0.80), Some(0.75), Some(0.60), Some(0.92), Some(0.97)];
/// Ground recall in the three forests with a roof rig (hdl64e-roof on the track, 2 frames at 5 m/s;
/// any scene seed). nitsch and ransac as in docs/mcdaniel.md (F1 0.87-0.99); mcdaniel: the paper's
/// nodding-laser model; their values are printed, not bounded. Worst of 24 cases: learned 0.994
/// (nitsch 0.928).
const FOREST_RECALL: Bounds = [None, None, None, None, Some(0.97)];
/// Non-ground false-ground rate in the forests (bushes, trunks, canopy). Worst of 24 cases:
/// learned 0.060 (nitsch 0.198).
const FOREST_FALSE_GROUND: Bounds = [None, None, None, None, Some(0.10)];
/// Non-ground false-ground rate in the city at those mounts.
const MOUNT_FALSE_GROUND: Bounds = [Some(0.05), Some(0.05), Some(0.05), Some(0.06), Some(0.02)];

proptest! {
    #![proptest_config(config(4))]

    #[test]
    fn up_ramps_keep_their_surface(ramp in strategies::ramps(0.0..=20.0, 8.0..=20.0), noise in strategies::noise()) {
        let case = format!("{ramp:?} noise {noise}");
        let s = scan(ramp.scenario().rig("hdl64e-roof").ideal(!noise))?;
        let d = decide_all(&s)?;
        check("up-ramp-recall", &case, &s, &d, &Region::RampSurface, recall, Bound::AtLeast, &UP_RAMP_RECALL)?;
    }

    #[test]
    fn down_ramps_keep_their_visible_surface(ramp in strategies::ramps(-20.0..=-2.0, 3.0..=5.0), noise in strategies::noise()) {
        let case = format!("{ramp:?} noise {noise}");
        let s = scan(ramp.scenario().rig("hdl64e-roof").ideal(!noise))?;
        let d = decide_all(&s)?;
        check("down-ramp-recall", &case, &s, &d, &Region::RampSurface, recall, Bound::AtLeast, &DOWN_RAMP_RECALL)?;
    }

    #[test]
    fn ground_beyond_and_in_a_basin_is_ground(basin in strategies::basin(), noise in strategies::noise()) {
        let case = format!("{basin:?} noise {noise}");
        let s = scan(basin.scenario().rig("hdl64e-roof").ideal(!noise))?;
        let d = decide_all(&s)?;
        check("beyond-basin-recall", &case, &s, &d, &Region::BeyondBasin, recall, Bound::AtLeast, &BEYOND_BASIN_RECALL)?;
        // A deep narrow basin hides its floor behind the near bank: score it where it is seen.
        let floor_seen = s.region_mask(0, &Region::BasinFloor).map_or(0, |m| m.iter().filter(|&&b| b).count());
        if floor_seen >= 50 {
            check("basin-floor-recall", &case, &s, &d, &Region::BasinFloor, recall, Bound::AtLeast, &BASIN_FLOOR_RECALL)?;
        }
    }

    #[test]
    fn flat_tops_are_not_ground_plateaus_are(
        e in strategies::elevations(0.3..=1.0, 1.2..=3.0),
        noise in strategies::noise(),
    ) {
        let case = format!("{e:?} noise {noise}");
        let s = scan(e.scenario().rig("hdl64e-roof").ideal(!noise))?;
        let d = decide_all(&s)?;
        check("roof-false-ground", &case, &s, &d, &Region::VehicleRoofs, false_ground, Bound::AtMost, &ROOF_FALSE_GROUND)?;
        check("flat-top-false-ground", &case, &s, &d, &Region::FlatRaisedTops, false_ground, Bound::AtMost, &FLAT_TOP_FALSE_GROUND)?;
        check("plateau-recall", &case, &s, &d, &Region::Plateau, recall, Bound::AtLeast, &PLATEAU_RECALL)?;
    }

    #[test]
    fn the_slope_under_the_ego_is_ground(hill in strategies::hill(), noise in strategies::noise()) {
        let case = format!("{hill:?} noise {noise}");
        let s = scan(hill.scenario().rig("hdl64e-roof").ideal(!noise))?;
        let d = decide_all(&s)?;
        check("hill-recall", &case, &s, &d, &Region::HillSlope, recall, Bound::AtLeast, &HILL_RECALL)?;
        check("hill-false-ground", &case, &s, &d, &Region::NonGround, false_ground, Bound::AtMost, &HILL_FALSE_GROUND)?;
    }

    #[test]
    fn forest_floors_are_ground_bushes_are_not(
        family in proptest::sample::select(vec!["forest-sparse", "forest-moderate", "forest-dense"]),
        seed in 0u64..100_000,
        noise in strategies::noise(),
    ) {
        let case = format!("{family} seed {seed} noise {noise}");
        let s = scan(Scenario::family(family).seed(seed).rig("hdl64e-roof").frames(2).speed_m_per_s(5.0).ideal(!noise))?;
        let d = decide_all(&s)?;
        check("forest-recall", &case, &s, &d, &Region::Ground, recall, Bound::AtLeast, &FOREST_RECALL)?;
        check("forest-false-ground", &case, &s, &d, &Region::NonGround, false_ground, Bound::AtMost, &FOREST_FALSE_GROUND)?;
    }

    #[test]
    fn ground_is_found_at_any_mount(mount in strategies::mounts(1.2..=3.0, -10.0..=10.0, -5.0..=5.0), noise in strategies::noise()) {
        let case = format!("{mount:?} noise {noise}");
        let s = scan(mount.apply(Scenario::family("city").rig("hdl64e-roof").ideal(!noise)))?;
        let d = decide_all(&s)?;
        check("mount-recall", &case, &s, &d, &Region::Ground, recall, Bound::AtLeast, &MOUNT_RECALL)?;
        check("mount-false-ground", &case, &s, &d, &Region::NonGround, false_ground, Bound::AtMost, &MOUNT_FALSE_GROUND)?;
    }
}

// Regression tests: the known limits, with the numbers measured when they were written (ideal
// HDL-64E on the roof unless stated). Each asserts the limit still holds as documented, so a change
// of method shows up here and the documentation is updated with it.

fn score(s: &Scenario, method: &str, region: &Region) -> RegionScore {
    let scan = s.scan().unwrap();
    let r = scan.score_method(method, region).unwrap();
    eprintln!("{method}: {r}");
    r
}

/// RANSAC fits one plane to the whole cloud (the ground plane at the vehicle): the 12 deg up ramp's
/// surface (recall 0.11), a 1.5 m deep basin's floor (0.0) and 0.5 m plateaus (0.0) are off it.
#[test]
fn ransac_fits_one_plane() {
    let hdl = |s: Scenario| s.rig("hdl64e-roof").ideal(true);
    let ramp = score(&hdl(Scenario::family("ramp").param("slope_deg", 12.0)), "ransac", &Region::RampSurface);
    assert!(ramp.recall() < 0.3, "{ramp}");
    let floor = score(&hdl(Scenario::family("basin").param("depth_m", 1.5)), "ransac", &Region::BasinFloor);
    assert!(floor.recall() < 0.05, "{floor}");
    let plateau = score(&hdl(Scenario::family("elevated").param("plateau_height_m", 0.5)), "ransac", &Region::Plateau);
    assert!(plateau.recall() < 0.05, "{plateau}");
}

/// The bundled McDaniel model was trained on the three forests; on ramps its SVM rejects most of the
/// surface: recall 0.05-1.0 over 0-20 deg up ramps (0.12 at 15 deg), 0.59-1.0 on down ramps 3-5 m
/// ahead; on raised plateaus 0.3-1 m high it keeps 0.0-0.91 of the top.
#[test]
fn mcdaniel_forest_model_on_ramps() {
    let s = Scenario::family("ramp").param("slope_deg", 15.0).rig("hdl64e-roof").ideal(true);
    let r = score(&s, "mcdaniel", &Region::RampSurface);
    assert!(r.recall() < 0.5, "{r}");
}

/// A 8 x 6 m platform 0.48 m high, 13 m from the ego (instance 5 of `elevated` with
/// `dock_height_m = 0.96`): its top is flat and only a curb-like step above the yard, so the local
/// methods call it ground: nitsch 0.99 of it, grid 0.79, mcdaniel 0.18 with the bundled model of
/// 3a95b28 (0.52 with the model before it; ransac 0: above its plane).
#[test]
fn low_platforms_look_like_ground() {
    let s = Scenario::family("elevated")
        .param("dock_height_m", 0.96)
        .param("plateau_height_m", 0.3)
        .rig("hdl64e-roof")
        .ideal(true);
    let scan = s.scan().unwrap();
    let platform = scan.region_mask(0, &Region::Instance(5)).unwrap();
    let tops = scan.region_mask(0, &Region::FlatRaisedTops).unwrap();
    let c = &scan.frames()[0].cloud;
    let top: Vec<usize> = (0..c.len()).filter(|&i| platform[i] && tops[i]).collect();
    assert!(top.len() > 500, "platform top returns {}", top.len());
    assert!(top.iter().all(|&i| c.label[i] == sim::SemanticClass::OTHER_STRUCTURE));
    let fgr = |m: &str| {
        let d = scan.classify(m).unwrap();
        let r = top.iter().filter(|&&i| d[0][i]).count() as f64 / top.len() as f64;
        eprintln!("{m}: platform top called ground {r:.4} of {}", top.len());
        r
    };
    assert!(fgr("nitsch") > 0.9);
    assert!(fgr("grid") > 0.6);
    assert!(fgr("mcdaniel") > 0.1);
    assert!(fgr("ransac") < 0.05);
}

/// At 0.3 m above the road (city), the ground ahead is seen at grazing angles and the neighbourhood
/// methods lose half of it: ground recall nitsch 0.49, grid 0.36 (mcdaniel 0.99, ransac 1.0).
#[test]
fn low_mounts_lose_ground() {
    let s = Scenario::family("city").rig("hdl64e-roof").mount_z_m(0.3).mount_pitch_deg(0.0);
    let scan = s.scan().unwrap();
    let recall = |m: &str| scan.score_method(m, &Region::Ground).unwrap().recall();
    let (nitsch, grid, mcdaniel) = (recall("nitsch"), recall("grid"), recall("mcdaniel"));
    eprintln!("0.3 m mount: nitsch {nitsch:.4} grid {grid:.4} mcdaniel {mcdaniel:.4}");
    assert!(nitsch < 0.7 && grid < 0.6, "nitsch {nitsch} grid {grid}");
    assert!(mcdaniel > 0.95, "mcdaniel {mcdaniel}");
}

/// Found by `up_ramps_keep_their_surface`: up ramps of 15-20 deg starting 5 m ahead, range noise on.
/// Close up, the HDL-64E's neighbouring rows on the steep surface are centimetres apart, so the range
/// noise tilts the local normals past the methods' thresholds: nitsch keeps 0.74-0.83 of the surface
/// (0.995 ideal), grid none (0.86 ideal; grid-no-cluster 0.46-0.57). From 8 m on both meet the
/// property's bounds (at 6 m: nitsch 0.92, grid 0.73).
#[test]
fn steep_ramps_close_up_with_noise() {
    for slope in [15.0f32, 16.710821, 20.0] {
        let s = Scenario::family("ramp").param("slope_deg", slope).param("distance_m", 5.0).rig("hdl64e-roof");
        let noisy = s.clone().scan().unwrap();
        let ideal = s.ideal(true).scan().unwrap();
        let recall = |scan: &Scan, m: &str| scan.score_method(m, &Region::RampSurface).unwrap().recall();
        let (nitsch, grid) = (recall(&noisy, "nitsch"), recall(&noisy, "grid"));
        let (nitsch_ideal, grid_ideal) = (recall(&ideal, "nitsch"), recall(&ideal, "grid"));
        eprintln!(
            "{slope} deg at 5 m: nitsch {nitsch:.4} (ideal {nitsch_ideal:.4}), grid {grid:.4} (ideal {grid_ideal:.4})"
        );
        assert!((0.7..0.9).contains(&nitsch) && nitsch_ideal >= 0.99, "nitsch {nitsch} ideal {nitsch_ideal}");
        assert!(grid < 0.1 && grid_ideal >= 0.85, "grid {grid} ideal {grid_ideal}");
    }
}

/// Found by `flat_tops_are_not_ground_plateaus_are`: cars parked 1-8 m beside the ego, roofs at
/// 1.5 m, half a metre below the sensor. Scene seed 157 with range noise: nitsch calls 0.375 of the
/// roofs ground (instances 21, 22, 37, 38: 60-90 % each), 0.016 without noise; scene seed 220 with
/// ideal ranges: 0.205. Most seeds stay at 0 (156, 158). The worst seen in the long run is 0.41,
/// hence the property's bound of 0.45 for nitsch against 0.05 for the others.
#[test]
fn nitsch_close_car_roofs() {
    let s = |seed: u64| {
        let s = Scenario::family("elevated").param("dock_height_m", 1.2).param("plateau_height_m", 0.3);
        s.seed(seed).rig("hdl64e-roof")
    };
    let noisy_157 = score(&s(157), "nitsch", &Region::VehicleRoofs).false_ground_rate();
    let ideal_157 = score(&s(157).ideal(true), "nitsch", &Region::VehicleRoofs).false_ground_rate();
    let ideal_220 = score(&s(220).ideal(true), "nitsch", &Region::VehicleRoofs).false_ground_rate();
    assert!((0.25..0.45).contains(&noisy_157), "seed 157 noisy {noisy_157}");
    assert!(ideal_157 < 0.05, "seed 157 ideal {ideal_157}");
    assert!((0.1..0.3).contains(&ideal_220), "seed 220 ideal {ideal_220}");
}

/// Found by `up_ramps_keep_their_surface` (17.7 deg, 28.5 m in the long run): an up ramp of 14-20 deg
/// starting 25 m ahead loses its whole surface to nitsch's cluster stage (recall 0.0, ideal ranges),
/// while the features alone keep it (nitsch-no-cluster 0.98) and the same ramps 20 or 30 m ahead are
/// kept (>= 0.97); 10 deg ramps are kept at 25 m too. The ramp's cluster is dropped whole, so this
/// looks like a cluster-rule defect rather than a feature limit (reported; the method is not this
/// test's to change). When it is fixed this test fails: widen the property's distances to 30 m.
#[test]
fn nitsch_drops_steep_ramps_25_m_ahead() {
    for slope in [14.0f32, 18.0] {
        let s = Scenario::family("ramp").param("slope_deg", slope).param("distance_m", 25.0);
        let scan = s.rig("hdl64e-roof").ideal(true).scan().unwrap();
        let recall = |m: &str| scan.score_method(m, &Region::RampSurface).unwrap().recall();
        let (clustered, features) = (recall("nitsch"), recall("nitsch-no-cluster"));
        eprintln!("{slope} deg at 25 m: nitsch {clustered:.4}, nitsch-no-cluster {features:.4}");
        assert!(clustered < 0.1, "nitsch {clustered}");
        assert!(features > 0.95, "nitsch-no-cluster {features}");
    }
}

/// Found by `flat_tops_are_not_ground_plateaus_are` in the long run: 0.76 m plateaus, scene seed 979
/// (dock 1.2-1.7 m), ideal ranges: nitsch and grid (which shares nitsch's features) both keep only
/// 0.53 of the plateau tops (the same 357 of 672 returns), where other seeds give >= 0.84.
#[test]
fn plateau_seed_979() {
    let s = Scenario::family("elevated").param("plateau_height_m", 0.7633249).param("dock_height_m", 1.2);
    let scan = s.seed(979).rig("hdl64e-roof").ideal(true).scan().unwrap();
    let recall = |m: &str| scan.score_method(m, &Region::Plateau).unwrap().recall();
    let (nitsch, grid) = (recall("nitsch"), recall("grid"));
    eprintln!("seed 979 plateau: nitsch {nitsch:.4} grid {grid:.4}");
    assert!((0.45..0.65).contains(&nitsch), "nitsch {nitsch}");
    assert!((0.45..0.65).contains(&grid), "grid {grid}");
}
