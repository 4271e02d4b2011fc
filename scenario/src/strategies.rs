//! proptest strategies for the parameters that break ground classifiers (feature `proptest`, on by
//! default). Each strategy yields a small case struct whose `scenario()` is a ready
//! [`Scenario`] (default rig `vlp16-roof`; change it with [`Scenario::rig`]).
//!
//! ```
//! use groundtruth_scenario::{Region, strategies};
//! use proptest::prelude::*;
//!
//! proptest!(ProptestConfig::with_cases(2), |(ramp in strategies::ramps(2.0..=10.0, 10.0..=20.0))| {
//!     let scan = ramp.scenario().rig("hdl64e-roof").ideal(true).scan()?;
//!     let s = scan.score_method("nitsch", &Region::RampSurface)?;
//!     prop_assert!(s.recall() >= 0.9, "{ramp:?}: {s}");
//! });
//! ```

use std::ops::RangeInclusive;

use proptest::prelude::*;

use crate::{MountOverride, Scenario, Weather};

/// A `ramp` scene: the corridor's slope (negative descends) and the distance to its foot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RampCase {
    /// `slope_deg`, degrees.
    pub slope_deg: f32,
    /// `distance_m`, metres.
    pub distance_m: f32,
}

impl RampCase {
    /// The scenario: family `ramp` with these parameters.
    ///
    /// ```
    /// let case = groundtruth_scenario::strategies::RampCase { slope_deg: -12.0, distance_m: 15.0 };
    /// assert_eq!(case.scenario().scan()?.family(), "ramp");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn scenario(&self) -> Scenario {
        Scenario::family("ramp").param("slope_deg", self.slope_deg).param("distance_m", self.distance_m)
    }
}

/// Ramps with `slope_deg` and `distance_m` drawn from the given ranges (within the family's
/// -20 ..= 20 deg and 3 ..= 100 m).
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let case = groundtruth_scenario::strategies::ramps(-5.0..=5.0, 10.0..=12.0).new_tree(&mut runner).unwrap().current();
/// assert!(case.slope_deg.abs() <= 5.0 && (10.0..=12.0).contains(&case.distance_m));
/// ```
pub fn ramps(slope_deg: RangeInclusive<f32>, distance_m: RangeInclusive<f32>) -> impl Strategy<Value = RampCase> {
    (slope_deg, distance_m).prop_map(|(slope_deg, distance_m)| RampCase { slope_deg, distance_m })
}

/// Ramps of any slope from 20 deg down to 20 deg up, 5 to 40 m ahead.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let case = groundtruth_scenario::strategies::ramp().new_tree(&mut runner).unwrap().current();
/// assert!(case.slope_deg.abs() <= 20.0);
/// ```
pub fn ramp() -> impl Strategy<Value = RampCase> {
    ramps(-20.0..=20.0, 5.0..=40.0)
}

/// A `basin` scene: depth below the road and width of its flat bottom.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BasinCase {
    /// `depth_m`, metres.
    pub depth_m: f32,
    /// `bottom_width_m`, metres.
    pub bottom_width_m: f32,
}

impl BasinCase {
    /// The scenario: family `basin` with these parameters.
    ///
    /// ```
    /// let case = groundtruth_scenario::strategies::BasinCase { depth_m: 1.0, bottom_width_m: 6.0 };
    /// assert_eq!(case.scenario().scan()?.ground_z_m(10.0, -8.0), -1.0);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn scenario(&self) -> Scenario {
        Scenario::family("basin").param("depth_m", self.depth_m).param("bottom_width_m", self.bottom_width_m)
    }
}

/// Basins with `depth_m` and `bottom_width_m` drawn from the given ranges.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let case = groundtruth_scenario::strategies::basins(1.0..=2.0, 4.0..=5.0).new_tree(&mut runner).unwrap().current();
/// assert!((1.0..=2.0).contains(&case.depth_m));
/// ```
pub fn basins(depth_m: RangeInclusive<f32>, bottom_width_m: RangeInclusive<f32>) -> impl Strategy<Value = BasinCase> {
    (depth_m, bottom_width_m).prop_map(|(depth_m, bottom_width_m)| BasinCase { depth_m, bottom_width_m })
}

/// Basins 0.3 to 3 m deep with a flat bottom 2 to 20 m wide.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let case = groundtruth_scenario::strategies::basin().new_tree(&mut runner).unwrap().current();
/// assert!((0.3..=3.0).contains(&case.depth_m));
/// ```
pub fn basin() -> impl Strategy<Value = BasinCase> {
    basins(0.3..=3.0, 2.0..=20.0)
}

/// An `elevated` scene: raised ground plateaus (ground) beside loading docks, platforms, cars,
/// vans and trucks with flat roofs (not ground).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElevatedCase {
    /// `plateau_height_m`: height of the raised ground, metres.
    pub plateau_height_m: f32,
    /// `dock_height_m`: height of the loading dock (the platforms stand at 0.5, 0.75 and 1 times
    /// it), metres.
    pub dock_height_m: f32,
    /// The scene seed (places the parked vehicles).
    pub seed: u64,
}

impl ElevatedCase {
    /// The scenario: family `elevated` with these parameters and seed.
    ///
    /// ```
    /// let case = groundtruth_scenario::strategies::ElevatedCase { plateau_height_m: 2.0, dock_height_m: 1.0, seed: 0 };
    /// assert_eq!(case.scenario().scan()?.ground_z_m(30.0, -20.0), 2.0);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn scenario(&self) -> Scenario {
        Scenario::family("elevated")
            .param("plateau_height_m", self.plateau_height_m)
            .param("dock_height_m", self.dock_height_m)
            .seed(self.seed)
    }
}

/// Elevated scenes with plateau and dock heights drawn from the given ranges, and any seed.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let case = groundtruth_scenario::strategies::elevations(0.5..=1.0, 1.0..=1.5).new_tree(&mut runner).unwrap().current();
/// assert!((0.5..=1.0).contains(&case.plateau_height_m));
/// ```
pub fn elevations(
    plateau_height_m: RangeInclusive<f32>,
    dock_height_m: RangeInclusive<f32>,
) -> impl Strategy<Value = ElevatedCase> {
    (plateau_height_m, dock_height_m, 0u64..1000).prop_map(|(plateau_height_m, dock_height_m, seed)| ElevatedCase {
        plateau_height_m,
        dock_height_m,
        seed,
    })
}

/// Plateaus and docks 0.3 to 3 m high.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let case = groundtruth_scenario::strategies::elevated().new_tree(&mut runner).unwrap().current();
/// assert!((0.3..=3.0).contains(&case.dock_height_m));
/// ```
pub fn elevated() -> impl Strategy<Value = ElevatedCase> {
    elevations(0.3..=3.0, 0.3..=3.0)
}

/// A `hill` scene: the slope the ego vehicle stands on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HillCase {
    /// `slope_deg`, degrees (climbing ahead).
    pub slope_deg: f32,
}

impl HillCase {
    /// The scenario: family `hill` with this slope.
    ///
    /// ```
    /// let case = groundtruth_scenario::strategies::HillCase { slope_deg: 20.0 };
    /// let scan = case.scenario().scan()?;
    /// // The vehicle settles on the slope: nose up is negative pitch.
    /// assert!((scan.frames()[0].vehicle_pose.pitch_rad + 20f64.to_radians()).abs() < 0.01);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn scenario(&self) -> Scenario {
        Scenario::family("hill").param("slope_deg", self.slope_deg)
    }
}

/// Hills with the ego slope drawn from `slope_deg` (within 0 ..= 25).
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let case = groundtruth_scenario::strategies::hills(5.0..=6.0).new_tree(&mut runner).unwrap().current();
/// assert!((5.0..=6.0).contains(&case.slope_deg));
/// ```
pub fn hills(slope_deg: RangeInclusive<f32>) -> impl Strategy<Value = HillCase> {
    slope_deg.prop_map(|slope_deg| HillCase { slope_deg })
}

/// Hills with the ego vehicle on 0 to 25 deg.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let case = groundtruth_scenario::strategies::hill().new_tree(&mut runner).unwrap().current();
/// assert!((0.0..=25.0).contains(&case.slope_deg));
/// ```
pub fn hill() -> impl Strategy<Value = HillCase> {
    hills(0.0..=25.0)
}

/// A sensor mount: height, pitch and roll (x, y and yaw stay the rig's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MountCase {
    /// Height above the ground, metres.
    pub z_m: f32,
    /// Pitch, degrees, positive tilts the sensor down.
    pub pitch_deg: f32,
    /// Roll, degrees.
    pub roll_deg: f32,
}

impl MountCase {
    /// The mount overrides.
    ///
    /// ```
    /// let m = groundtruth_scenario::strategies::MountCase { z_m: 1.0, pitch_deg: 2.0, roll_deg: -1.0 };
    /// assert_eq!(m.overrides().z_m, Some(1.0));
    /// ```
    pub fn overrides(&self) -> MountOverride {
        MountOverride {
            z_m: Some(self.z_m),
            pitch_deg: Some(self.pitch_deg),
            roll_deg: Some(self.roll_deg),
            ..MountOverride::default()
        }
    }

    /// `scenario` with this mount on its (first) sensor.
    ///
    /// ```
    /// use groundtruth_scenario::{Scenario, strategies::MountCase};
    /// let m = MountCase { z_m: 0.4, pitch_deg: 0.0, roll_deg: 0.0 };
    /// assert_eq!(m.apply(Scenario::family("flat")).scan()?.rig().sensors[0].mount.z_m, 0.4);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn apply(&self, scenario: Scenario) -> Scenario {
        scenario.mount(self.overrides())
    }
}

/// Mounts with height, pitch and roll drawn from the given ranges.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let m = groundtruth_scenario::strategies::mounts(1.0..=2.0, 0.0..=0.0, 0.0..=0.0).new_tree(&mut runner).unwrap().current();
/// assert!((1.0..=2.0).contains(&m.z_m) && m.pitch_deg == 0.0);
/// ```
pub fn mounts(
    z_m: RangeInclusive<f32>,
    pitch_deg: RangeInclusive<f32>,
    roll_deg: RangeInclusive<f32>,
) -> impl Strategy<Value = MountCase> {
    (z_m, pitch_deg, roll_deg).prop_map(|(z_m, pitch_deg, roll_deg)| MountCase { z_m, pitch_deg, roll_deg })
}

/// Mounts 0.3 to 3 m high, pitched -10 to +10 deg and rolled -5 to +5 deg.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let m = groundtruth_scenario::strategies::mount().new_tree(&mut runner).unwrap().current();
/// assert!((0.3..=3.0).contains(&m.z_m) && m.roll_deg.abs() <= 5.0);
/// ```
pub fn mount() -> impl Strategy<Value = MountCase> {
    mounts(0.3..=3.0, -10.0..=10.0, -5.0..=5.0)
}

/// Measurement noise on (`true`: the sensor's noise, quantisation and dropout) or off (ideal
/// ranges); use as `scenario.ideal(!noise)`.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let _noise: bool = groundtruth_scenario::strategies::noise().new_tree(&mut runner).unwrap().current();
/// ```
pub fn noise() -> impl Strategy<Value = bool> {
    any::<bool>()
}

/// Weather drawn from the given ranges: fog of visibility `visibility_m`, rain and snow of rate
/// `rain_mm_h` / `snow_mm_h` (within 1 ..= 100000 m, 0 ..= 50 mm/h and 0 ..= 5 mm/h), each kind
/// equally likely; use as `scenario.weather(w)`.
///
/// ```
/// use groundtruth_scenario::{Weather, strategies};
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let w = strategies::weathers(30.0..=60.0, 5.0..=10.0, 1.0..=2.0).new_tree(&mut runner).unwrap().current();
/// assert!(w.validate().is_ok(), "{w:?}");
/// ```
pub fn weathers(
    visibility_m: RangeInclusive<f64>,
    rain_mm_h: RangeInclusive<f64>,
    snow_mm_h: RangeInclusive<f64>,
) -> impl Strategy<Value = Weather> {
    prop_oneof![
        visibility_m.prop_map(|visibility_m| Weather::Fog { visibility_m }),
        rain_mm_h.prop_map(|rate_mm_h| Weather::Rain { rate_mm_h }),
        snow_mm_h.prop_map(|rate_mm_h| Weather::Snow { rate_mm_h }),
    ]
}

/// Adverse weather as met on the road: fog of 30 to 200 m visibility, rain of 1 to 50 mm/h, snow
/// of 0.5 to 5 mm/h.
///
/// ```
/// use proptest::strategy::{Strategy, ValueTree};
/// let mut runner = proptest::test_runner::TestRunner::deterministic();
/// let w = groundtruth_scenario::strategies::weather().new_tree(&mut runner).unwrap().current();
/// assert!(w.extinction_per_m() > 0.0, "{w:?}");
/// ```
pub fn weather() -> impl Strategy<Value = Weather> {
    weathers(30.0..=200.0, 1.0..=50.0, 0.5..=5.0)
}

/// A deterministic proptest configuration: [`cases`]`(default)` cases, the random stream seeded
/// with `GT_PROPTEST_SEED` from the environment (default 0) so every run draws the same cases, and
/// no failure-persistence files (a failing case is printed; keep it as a named test).
///
/// ```
/// let config = groundtruth_scenario::strategies::config(3);
/// assert!(config.cases >= 1);
/// assert!(config.failure_persistence.is_none());
/// ```
pub fn config(default: u32) -> ProptestConfig {
    let seed = std::env::var("GT_PROPTEST_SEED").ok().and_then(|v| v.parse().ok()).unwrap_or(0);
    ProptestConfig {
        cases: cases(default),
        rng_seed: proptest::test_runner::RngSeed::Fixed(seed),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// The proptest case count: `GT_PROPTEST_CASES` from the environment if set (a long run), else
/// `default` (a CI-sized run).
///
/// ```
/// let n = groundtruth_scenario::strategies::cases(4);
/// assert!(n >= 1);
/// ```
pub fn cases(default: u32) -> u32 {
    std::env::var("GT_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).filter(|&n| n > 0).unwrap_or(default)
}
