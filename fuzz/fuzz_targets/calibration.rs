//! Fuzz target: the calibration readers (our TOML and text, the velodyne driver's YAML, Ouster's
//! JSON, Hesai's CSV); the first byte picks the format.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&k, rest)) = data.split_first() else { return };
    let Ok(text) = std::str::from_utf8(rest) else { return };
    let ext = ["toml", "txt", "yaml", "json", "csv"][usize::from(k) % 5];
    let path = std::path::PathBuf::from(format!("fuzz.{ext}"));
    let expected = (k >= 128).then_some(usize::from(k % 128));
    if let Ok(cal) = classifier::ordering::Calibration::parse(&path, text, expected) {
        let _ = cal.to_table(2048);
    }
});
