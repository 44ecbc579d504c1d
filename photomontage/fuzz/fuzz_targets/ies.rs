//! IES LM-63: `PhotometricFile::parse` on bytes that look like IES (any encoding), then the
//! photometric web and its flux, as the renderer builds them. A `TILT=<file>` is resolved to
//! the bytes after a `\0TILT\0` marker in the input, so tilt tables are fuzzed too.
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::luminaire::{IesFile, PhotometricFile};
use photomontage_fuzz::exercise_photometry;

const TILT_MARKER: &[u8] = b"\0TILT\0";

fuzz_target!(|data: &[u8]| {
    let (ies, tilt) = match data
        .windows(TILT_MARKER.len())
        .position(|w| w == TILT_MARKER)
    {
        Some(at) => (&data[..at], Some(&data[at + TILT_MARKER.len()..])),
        None => (data, None),
    };
    let parsed = IesFile::parse_with_tilt_resolver(ies, &mut |_name| {
        tilt.map(<[u8]>::to_vec)
            .ok_or_else(|| "no tilt file in this input".to_owned())
    });
    if let Ok(file) = parsed {
        exercise_photometry(&PhotometricFile::Ies(Box::new(file)));
    }
    if let Ok(file) = PhotometricFile::parse(ies) {
        exercise_photometry(&file);
    }
});
