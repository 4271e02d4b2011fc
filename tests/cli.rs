//! The integration tests of the `groundtruth` program (each runs the test build's binary), one test binary: each file beside this one is a module
//! of it (one link instead of one per file, and the tests of every file run side by side).
//! Run one file's tests with `cargo test -p groundtruth-cli --test cli FILE::`.

#[path = "cli_bench_raycast.rs"]
mod cli_bench_raycast;
#[path = "cli_dataset.rs"]
mod cli_dataset;
#[path = "cli_gpu.rs"]
mod cli_gpu;
#[path = "cli_layouts.rs"]
mod cli_layouts;
#[path = "cli_learned.rs"]
mod cli_learned;
#[path = "cli_pipe.rs"]
mod cli_pipe;
#[path = "cli_ros2.rs"]
mod cli_ros2;
#[path = "cli_spec.rs"]
mod cli_spec;
#[path = "cli_sweep.rs"]
mod cli_sweep;
#[path = "cli_weather.rs"]
mod cli_weather;
#[path = "common/mod.rs"]
mod common;
