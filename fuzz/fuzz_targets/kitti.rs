//! Fuzz target: the KITTI `.bin` + `.label` reader; the first byte picks where the input splits
//! into the `.bin` and `.label` parts.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&k, rest)) = data.split_first() else { return };
    let split = (rest.len() * usize::from(k) / 255).min(rest.len());
    let (bin, label) = rest.split_at(split);
    let _ = sim::io::kitti::read_bytes(
        std::path::Path::new("fuzz.bin"),
        bin,
        Some((std::path::Path::new("fuzz.label"), label)),
    );
    let _ = sim::io::kitti::read_bytes(std::path::Path::new("fuzz.bin"), rest, None);
});
