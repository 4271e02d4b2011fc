//! The integration tests of `sim`, one test binary: each file beside this one is a module
//! of it (one link instead of one per file, and the tests of every file run side by side).
//! Run one file's tests with `cargo test -p groundtruth-sim --test integration FILE::`.

#[path = "bags_never_panic.rs"]
mod bags_never_panic;
#[cfg(feature = "reference")]
#[path = "caster.rs"]
mod caster;
#[path = "catalogue.rs"]
mod catalogue;
#[path = "common/mod.rs"]
mod common;
#[path = "formats.rs"]
mod formats;
#[path = "gpu_cwbvh.rs"]
mod gpu_cwbvh;
#[path = "gpu_scan.rs"]
mod gpu_scan;
#[path = "pcd_layouts.rs"]
mod pcd_layouts;
#[path = "readers_never_panic.rs"]
mod readers_never_panic;
#[path = "rigs.rs"]
mod rigs;
#[path = "scan.rs"]
mod scan;
#[path = "sensors.rs"]
mod sensors;
