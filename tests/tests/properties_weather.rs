//! Weather properties: what fog, rain and snow do to a scan, and what they do to our ground
//! classifiers, drawn with `groundtruth_scenario::strategies::weather()` on the road scenes.
//!
//! - The scan: the same seed gives the same bytes at 1 and 2 threads; every return that is not
//!   the medium's keeps its clear-weather range, label and ground truth, its intensity only lower;
//!   the medium's returns are labelled fog / rain / snow and never ground; thinner fog never
//!   turns more beams into fog.
//! - The classifiers: per method and weather kind, the ground recall on the road scenes and the
//!   false-ground rate of the medium's returns (particles near the ground called ground). Each
//!   case prints `PROP <property> <method> <value>`; the bound tables carry the worst values seen.
//!
//! Case counts are CI-sized (4 per property), seeded with `GT_PROPTEST_SEED` (default 0);
//! `GT_PROPTEST_CASES=N` runs N.

use groundtruth_scenario::strategies::{self, config};
use groundtruth_scenario::{Region, RegionScore, Scan, Scenario, Weather};
use gt_tests::{ScanSpec, cloud_bits, scan_with_threads};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use sim::rig::Rig;
use sim::scene::SemanticClass;

const METHODS: [&str; 5] = ["nitsch", "ransac", "grid", "mcdaniel", "learned"];

fn road_scene() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec!["city", "highway", "rural"])
}

fn scan_of(s: Scenario) -> Result<Scan, TestCaseError> {
    s.scan().map_err(|e| TestCaseError::fail(e.to_string()))
}

fn kind(w: &Weather) -> &'static str {
    match w {
        Weather::Clear => "clear",
        Weather::Fog { .. } => "fog",
        Weather::Rain { .. } => "rain",
        Weather::Snow { .. } => "snow",
    }
}

/// A bound per method (nitsch, ransac, grid, mcdaniel, learned): `Some(b)` asserted, `None`
/// printed only (a documented known limit with a named test below).
type Bounds = [Option<f64>; 5];

/// Ground recall lost to the weather on the road scenes (city, highway, rural; HDL-64E on the
/// roof), per kind: clear-air recall minus weather recall, at most. Worst values seen: see the
/// comments and docs/weather.md.
// Worst of 40 cases (GT_PROPTEST_CASES=40, seed 0; fog 12, rain 17, snow 11 cases), in method
// order: fog 0.444, 0.0015, 0.557, 0.029, 0.018; rain 0.458, 0.014, 0.496, 0.026, 0.057; snow
// 0.566, 0.037, 0.965, 0.053, 0.085 (snow and rain measured before their calibration, ten times
// too thick). nitsch and grid (the same cluster rules) are a known failure in fog:
// `nitsch_and_grid_lose_the_road_when_fog_cuts_the_far_ground`.
const FOG_RECALL_DROP: Bounds = [None, Some(0.01), None, Some(0.05), Some(0.03)];
const RAIN_RECALL_DROP: Bounds = [None, Some(0.05), None, Some(0.05), Some(0.08)];
const SNOW_RECALL_DROP: Bounds = [None, Some(0.06), None, Some(0.08), Some(0.12)];
/// Share of the medium's returns called ground, per kind. Fog returns hang 1-8 m in front of the
/// sensor, above the road; snow and rain returns are anywhere in the beam, some just above the
/// road. Worst of the 40 cases: fog 0.0009 (nitsch), rain 0.0032 (nitsch), snow 0.0163 (ransac),
/// 0.0148 (mcdaniel), 0.0064 (learned).
const FOG_FALSE_GROUND: Bounds = [Some(0.005); 5];
const RAIN_FALSE_GROUND: Bounds = [Some(0.01); 5];
const SNOW_FALSE_GROUND: Bounds = [Some(0.03); 5];

fn bounds(w: &Weather) -> (&'static Bounds, &'static Bounds) {
    match w {
        Weather::Fog { .. } | Weather::Clear => (&FOG_RECALL_DROP, &FOG_FALSE_GROUND),
        Weather::Rain { .. } => (&RAIN_RECALL_DROP, &RAIN_FALSE_GROUND),
        Weather::Snow { .. } => (&SNOW_RECALL_DROP, &SNOW_FALSE_GROUND),
    }
}

/// Prints the value and checks it is at most `bound`.
fn check(
    property: &str,
    case: &str,
    v: f64,
    s: &RegionScore,
    method: &str,
    bound: Option<f64>,
) -> Result<(), TestCaseError> {
    eprintln!("PROP {property} {method} {v:.4} ({case}; {s})");
    if let Some(b) = bound {
        prop_assert!(v <= b, "{property}: {method} {v:.4} against bound {b} on {case}: {s}");
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(4))]

    /// The same seed gives the same bytes at 1 and 2 threads in every weather.
    #[test]
    fn weather_scans_are_the_same_at_one_and_two_threads(
        scene in road_scene(),
        seed in 0u64..1_000_000,
        weather in strategies::weather(),
    ) {
        let spec = ScanSpec { scene: scene.to_string(), seed, frames: 2, speed_m_per_s: 8.0, weather: Some(weather), ..ScanSpec::default() };
        let scene = spec.load_scene().unwrap();
        let rig = Rig::preset("vlp16-roof").unwrap();
        let one = scan_with_threads(1, &scene, &rig, &spec);
        let two = scan_with_threads(2, &scene, &rig, &spec);
        for (a, b) in one.iter().zip(&two) {
            prop_assert!(cloud_bits(&a.cloud) == cloud_bits(&b.cloud), "frame {} differs ({weather:?})", a.index);
        }
    }

    /// Against `clear` (the same detection threshold, no medium): every return of the weather scan
    /// that is not the medium's is the same surface point with the same label and ground truth, at
    /// most as bright; the medium's returns are labelled as the weather's kind, never ground, and
    /// lie nearer than the beam's clear-weather return.
    #[test]
    fn weather_keeps_ground_truth_and_labels_its_own_returns(
        scene in road_scene(),
        seed in 0u64..1_000_000,
        weather in strategies::weather(),
    ) {
        let clear = scan_of(Scenario::bundled(scene).rig("hdl64e-roof").seed(seed).weather(Weather::Clear))?;
        let wet = scan_of(Scenario::bundled(scene).rig("hdl64e-roof").seed(seed).weather(weather))?;
        let (a, b) = (&clear.frames()[0].cloud, &wet.frames()[0].cloud);
        let class = match weather {
            Weather::Fog { .. } => SemanticClass::FOG,
            Weather::Rain { .. } => SemanticClass::RAIN,
            _ => SemanticClass::SNOW,
        };
        let (mut medium, mut kept) = (0, 0);
        for i in (0..b.len()).filter(|&i| b.has_return(i)) {
            if b.label[i].is_weather() {
                medium += 1;
                prop_assert_eq!(b.label[i], class);
                prop_assert!(!b.ground[i]);
                prop_assert!(!a.has_return(i) || b.range_m[i] < a.range_m[i], "cell {}: {} vs {}", i, b.range_m[i], a.range_m[i]);
            } else {
                kept += 1;
                prop_assert!(a.has_return(i), "cell {} returns only in weather", i);
                prop_assert_eq!(a.range_m[i].to_bits(), b.range_m[i].to_bits());
                prop_assert_eq!(a.label[i], b.label[i]);
                prop_assert_eq!(a.ground[i], b.ground[i]);
                prop_assert!(b.intensity[i] <= a.intensity[i], "cell {}", i);
            }
        }
        eprintln!("{scene} seed {seed} {weather:?}: {medium} medium returns, {kept} kept of {}", a.returns());
        prop_assert!(kept > 0);
    }

    /// Thinner fog never turns more beams into fog returns (visibility v < 2v: a superset of beams).
    #[test]
    fn thinner_fog_fogs_fewer_beams(scene in road_scene(), seed in 0u64..1_000, v in 20.0f64..100.0) {
        let fogged = |visibility_m: f64| -> Result<usize, TestCaseError> {
            let s = scan_of(Scenario::bundled(scene).rig("vlp16-roof").seed(seed).weather(Weather::Fog { visibility_m }))?;
            let c = &s.frames()[0].cloud;
            Ok((0..c.len()).filter(|&i| c.has_return(i) && c.label[i] == SemanticClass::FOG).count())
        };
        let (thick, thin) = (fogged(v)?, fogged(2.0 * v)?);
        prop_assert!(thin <= thick, "V {v}: {thick} fog returns, at 2V {thin}");
    }

    /// Per method: the ground recall lost to the weather (recall in clear air minus recall in the
    /// weather, same scene, seed and rig) on the road scenes, and the share of the medium's
    /// returns it calls ground (bounds per kind above).
    #[test]
    fn ground_segmentation_in_weather(scene in road_scene(), seed in 0u64..1_000_000, weather in strategies::weather()) {
        let s = Scenario::bundled(scene).rig("hdl64e-roof").seed(seed);
        let clear = scan_of(s.clone().weather(Weather::Clear))?;
        let wet = scan_of(s.weather(weather))?;
        let case = format!("{scene} seed {seed} {}", weather.spec());
        let (drop_bounds, false_bounds) = bounds(&weather);
        for (k, method) in METHODS.iter().enumerate() {
            let fail = |e: groundtruth_scenario::ScenarioError| TestCaseError::fail(format!("{method}: {e}"));
            let before = clear.score(&Region::Ground, &clear.classify(method).map_err(fail)?).map_err(fail)?;
            let d = wet.classify(method).map_err(fail)?;
            let after = wet.score(&Region::Ground, &d).map_err(fail)?;
            let drop = before.recall() - after.recall();
            let name = format!("{}_ground_recall_drop", kind(&weather));
            check(&name, &format!("{case}; clear {:.4}", before.recall()), drop, &after, method, drop_bounds[k])?;
            // Thin fog (visibility above about 90 m) returns nothing of its own: no region to score.
            if let Ok(w) = wet.score(&Region::Weather, &d) {
                check(&format!("{}_false_ground", kind(&weather)), &case, w.false_ground_rate(), &w, method, false_bounds[k])?;
            }
        }
    }
}

/// Ground recall of `method` on `scene` (HDL-64E on the roof) in clear air and in `weather`.
fn recalls(scene: &str, seed: u64, weather: Weather, method: &str) -> (f64, f64) {
    recalls_with("hdl64e-roof", scene, seed, weather, method)
}

/// Known failure: fog of 166 m visibility returns nothing of its own but attenuates the far ground
/// below the detection threshold (no ground beyond about 40 m). On `rural` (seed 248540) the
/// road near the car is then no longer the largest cluster of Nitsch et al.'s rule 2 (the grid map
/// uses the same rules), and most of it is rejected: nitsch 0.933 -> 0.489, grid 0.951 -> 0.39 on
/// `highway` (seed 652352, visibility 77 m).
#[test]
fn nitsch_and_grid_lose_the_road_when_fog_cuts_the_far_ground() {
    let (clear, fog) = recalls("rural", 248_540, Weather::Fog { visibility_m: 166.0 }, "nitsch");
    assert!(clear > 0.9 && fog < 0.6, "{clear} -> {fog}");
    let (clear, fog) = recalls("highway", 652_352, Weather::Fog { visibility_m: 77.0 }, "grid");
    assert!(clear > 0.9 && fog < 0.6, "{clear} -> {fog}");
    // The learned segmenter keeps it.
    let (clear, fog) = recalls("rural", 248_540, Weather::Fog { visibility_m: 166.0 }, "learned");
    assert!(clear - fog < 0.03, "{clear} -> {fog}");
}

/// Snow calibrated on measured snowfall (docs/weather.md) is a few per cent of the returns, not
/// the 30-70 % of before, and no longer breaks the cluster rules: the cases that used to be the
/// named failure `snow_clutter_breaks_nitsch_and_grid` (nitsch 0.947 -> 0.379 on `city`, seed
/// 15402, 4.7 mm/h; grid 0.965 -> 0.0 on `highway`, seed 109, 5 mm/h, the largest calibrated rate)
/// now lose at most a few thousandths of the ground recall.
#[test]
fn calibrated_snow_leaves_nitsch_and_grid_their_ground() {
    let (clear, snow) = recalls("city", 15_402, Weather::Snow { rate_mm_h: 4.7 }, "nitsch");
    assert!(clear > 0.9 && clear - snow < 0.02, "{clear} -> {snow}");
    let (clear, snow) = recalls("highway", 109, Weather::Snow { rate_mm_h: 5.0 }, "grid");
    assert!(clear > 0.9 && clear - snow < 0.02, "{clear} -> {snow}");
}

/// Ground recall of `method` on `scene` with `rig`, clear against `weather`.
fn recalls_with(rig: &str, scene: &str, seed: u64, weather: Weather, method: &str) -> (f64, f64) {
    let s = Scenario::bundled(scene).rig(rig).seed(seed);
    let r = |w: Weather| s.clone().weather(w).scan().unwrap().score_method(method, &Region::Ground).unwrap().recall();
    let (clear, wet) = (r(Weather::Clear), r(weather));
    eprintln!("{method} {scene} {rig} seed {seed} {}: ground recall {clear:.4} clear, {wet:.4}", weather.spec());
    (clear, wet)
}

/// Known failure of `grid`, and its particle filter stage: on the OS1-128 (narrow beams, many
/// upward lasers) calibrated snow of 5 mm/h puts flakes over the road near the car, their `g_rho`
/// of about 0 pulls the squares' mean below the threshold and the ground under them is lost.
/// `grid-dror` leaves isolated returns out of the map (`classifier::baselines::isolated`) and keeps
/// it.
#[test]
fn snow_breaks_grid_on_the_os1_128_and_grid_dror_keeps_the_ground() {
    let weather = Weather::Snow { rate_mm_h: 5.0 };
    let (clear, snow) = recalls_with("os1-128-roof", "rural", 300_001, weather, "grid");
    assert!(clear > 0.9 && clear - snow > 0.1, "grid: {clear} -> {snow}");
    let (clear, snow) = recalls_with("os1-128-roof", "rural", 300_001, weather, "grid-dror");
    assert!(clear > 0.9 && clear - snow < 0.02, "grid-dror: {clear} -> {snow}");
}
