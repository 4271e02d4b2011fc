//! Fuzz target: the PLY point-cloud reader must return a cloud or an error for any bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = sim::io::ply::read_bytes(std::path::Path::new("fuzz.ply"), data);
});
