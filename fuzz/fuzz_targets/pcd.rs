//! Fuzz target: the PCD reader must return a cloud or an error for any bytes, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = sim::io::pcd::read_bytes(std::path::Path::new("fuzz.pcd"), data);
});
