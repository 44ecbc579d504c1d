//! Photo decoding through `load_with_limits` (JPEG, PNG, TIFF, EXR by content; EXIF
//! orientation applied). The limits are small (16 MP, 512 MiB) so that a header that lies about
//! its size is refused before allocation, as the library promises, and the fuzzer's own 2 GB
//! memory cap is not the thing that stops it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::photo::{DecodeLimits, load_with_limits};
use photomontage_fuzz::write_scratch;

const LIMITS: DecodeLimits = DecodeLimits {
    max_pixels: 16_000_000,
    max_bytes: 512 << 20,
};

fuzz_target!(|data: &[u8]| {
    // No extension: the format comes from the content, as for a misnamed upload.
    let path = write_scratch("photo", data);
    if let Ok(photo) = load_with_limits(&path, &LIMITS) {
        let [w, h] = photo.size_px();
        assert!(
            u64::from(w) * u64::from(h) <= LIMITS.max_pixels,
            "decoded {w}×{h} px past the limit"
        );
    }
});
