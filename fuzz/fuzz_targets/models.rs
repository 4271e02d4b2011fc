//! Fuzz target: the model files of `learned` and `mcdaniel` (JSON), checked as they load.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = classifier::learned::LearnedModel::from_json_str(text, "fuzz.json");
    let _ = classifier::mcdaniel::McDanielModel::from_json_str(text, "fuzz.json");
});
