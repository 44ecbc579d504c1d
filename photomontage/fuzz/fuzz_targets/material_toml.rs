//! Material library TOML: `MaterialLibrary::from_toml_str` (parse, validate, duplicate names).
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::scene::MaterialLibrary;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = MaterialLibrary::from_toml_str(text);
    }
});
