//! The integration tests of the cross-crate scenario and property suites, one test binary: each file beside this one is a module
//! of it (one link instead of one per file, and the tests of every file run side by side).
//! Run one file's tests with `cargo test -p gt-tests --test integration FILE::`.

#[path = "docs.rs"]
mod docs;
#[path = "forests.rs"]
mod forests;
#[path = "layout.rs"]
mod layout;
#[path = "mounts.rs"]
mod mounts;
#[path = "properties_classifiers.rs"]
mod properties_classifiers;
#[path = "properties_sim.rs"]
mod properties_sim;
#[path = "properties_weather.rs"]
mod properties_weather;
#[path = "real_files.rs"]
mod real_files;
#[path = "rings_recovered.rs"]
mod rings_recovered;
#[path = "scenarios.rs"]
mod scenarios;
#[path = "weather_calibration.rs"]
mod weather_calibration;
#[path = "weather_return_modes.rs"]
mod weather_return_modes;
