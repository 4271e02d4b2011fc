//! Fuzz target: the LAS reader, on the input's bytes (`sim::io::las::read_bytes`, which `read`
//! shares everything with but the opening of the file).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = sim::io::las::read_bytes(std::path::Path::new("fuzz.las"), data);
});
