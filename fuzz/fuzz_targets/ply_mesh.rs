//! Fuzz target: the PLY scene-mesh reader must return a mesh or an error for any bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = sim::scene::ply::read_mesh_bytes(std::path::Path::new("fuzz.ply"), data);
});
