//! `groundtruth-scenario`: scenario tests for ground segmenters. Build a scene (a generator family
//! and named parameters, a bundled scene, or TOML), scan it with a LiDAR rig into labelled ordered
//! clouds, select **regions** to assert on (the ramp surface, the ground beyond a basin, car roofs,
//! ...) and score any ground decisions on them: a user's, or one of ours by method name.
//!
//! ```
//! use groundtruth_scenario::{Region, Scenario};
//!
//! // "On a 12 deg down ramp seen by an HDL-64E at 1.9 m, my ground segmenter keeps 95 % of the
//! // ramp surface."
//! let scan = Scenario::family("ramp")
//!     .param("slope_deg", -12.0)
//!     .param("distance_m", 5.0) // from 1.9 m up, a 12 deg drop is hidden beyond about 9 m

//!     .rig("hdl64e-roof")
//!     .mount_z_m(1.9)
//!     .scan()?;
//! // A toy segmenter on the points (vehicle frame, metres): a flat world, ground within 0.3 m of z = 0.
//! let mine = scan.decide_points(|points| points.iter().map(|p| p[2].abs() < 0.3).collect())?;
//! let ramp = scan.score(&Region::RampSurface, &mine)?;
//! // The toy loses the ramp below z = -0.3 m; a real method keeps it.
//! assert!(ramp.recall() < 0.95, "{ramp}");
//! assert!(scan.score_method("nitsch", &Region::RampSurface)?.recall() >= 0.95);
//! # Ok::<(), groundtruth_scenario::ScenarioError>(())
//! ```
//!
//! Every front end (this builder, the command line, dataset and sweep files, Python) describes a
//! scan with one [`ScanSpec`], turned into the scanner's input by [`ScanSpec::setup`].
//!
//! Everything that takes user input returns [`ScenarioError`]; nothing panics on it. With the
//! default feature `proptest`, [`strategies`] has proptest strategies for the hard cases (ramps,
//! basins, raised plateaus vs flat roofs, hills, mounts, noise).

mod builder;
pub mod error;
mod geometry;
mod mount_override;
mod param_value;
pub mod region;
mod scan;
pub mod score;
pub mod spec;
#[cfg(feature = "proptest")]
pub mod strategies;

pub use builder::Scenario;
pub use error::{Result, ScenarioError};
pub use mount_override::{MOUNT_LIMITS, MountMode, MountOverride, MountTarget};
pub use param_value::ParamValue;
pub use region::Region;
pub use scan::{Decisions, Scan};
pub use score::RegionScore;
/// The simulator crate, re-exported (clouds, rigs, classes).
pub use sim;
pub use sim::effects::weather::Weather;
pub use spec::{LoadedScene, ScanBackend, ScanSetup, ScanSpec};
