//! EXIF through `read_exif` (JPEG, TIFF, PNG containers), then the initial focal length the
//! camera solve starts from.
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::photo::{initial_focal_px, read_exif};
use photomontage_fuzz::write_scratch;

fuzz_target!(|data: &[u8]| {
    let path = write_scratch("photo.jpg", data);
    if let Ok(info) = read_exif(&path) {
        let _ = initial_focal_px(&info, [4000, 3000]);
    }
});
