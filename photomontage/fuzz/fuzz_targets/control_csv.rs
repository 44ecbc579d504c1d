//! Control-point CSVs: `parse_control_points_csv` (id,X,Y,Z[,sigma_m]) and `parse_points_csv`
//! (id,X,Y,Z,x,y[,sigma_px]) on the same text.
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::photogrammetry::control_io::{parse_control_points_csv, parse_points_csv};

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse_control_points_csv(text, [0.05; 3]);
        let _ = parse_points_csv(text);
    }
});
