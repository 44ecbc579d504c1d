//! OpenDroneMap `gcp_list.txt`: `parse_odm_gcp_list` (CRS header, rows, limits).
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::photogrammetry::control_io::parse_odm_gcp_list;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse_odm_gcp_list(text);
    }
});
