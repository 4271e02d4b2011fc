//! Fuzz target: the LAS reader (it reads from a path: the input is written to a file of this
//! process first).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("groundtruth-fuzz-{}.las", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = sim::io::las::read(&path);
    }
});
