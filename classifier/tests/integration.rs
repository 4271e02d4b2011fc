//! The integration tests of `classifier`, one test binary: each file beside this one is a module
//! of it (one link instead of one per file, and the tests of every file run side by side).
//! Run one file's tests with `cargo test -p groundtruth-classifier --test integration FILE::`.

#[path = "baselines_metrics_ordering.rs"]
mod baselines_metrics_ordering;
#[path = "classify.rs"]
mod classify;
#[path = "features.rs"]
mod features;
#[path = "hesai_calibration.rs"]
mod hesai_calibration;
#[path = "mcdaniel.rs"]
mod mcdaniel;
#[path = "mcdaniel_svm.rs"]
mod mcdaniel_svm;
#[path = "ordering_calibration.rs"]
mod ordering_calibration;
#[path = "ordering_inputs.rs"]
mod ordering_inputs;
#[path = "ordering_recovered.rs"]
mod ordering_recovered;
#[path = "organized_reading.rs"]
mod organized_reading;
#[path = "recording_inputs.rs"]
mod recording_inputs;
