//! The integration tests of `scenes`, one test binary: each file beside this one is a module
//! of it (one link instead of one per file, and the tests of every file run side by side).
//! Run one file's tests with `cargo test -p groundtruth-scenes --test integration FILE::`.

#[path = "bundled.rs"]
mod bundled;
#[path = "common/mod.rs"]
mod common;
#[path = "errors.rs"]
mod errors;
#[path = "params.rs"]
mod params;
#[path = "proptest_ramp.rs"]
mod proptest_ramp;
#[path = "watertight.rs"]
mod watertight;
