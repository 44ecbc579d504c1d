//! EULUMDAT (.ldt): `EulumdatFile::parse`, then the web of every lamp set and its flux.
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::luminaire::{EulumdatFile, PhotometricFile};
use photomontage_fuzz::exercise_photometry;

fuzz_target!(|data: &[u8]| {
    if let Ok(file) = EulumdatFile::parse(data) {
        for index in 0..4 {
            if let Ok(web) = file.distribution_for_lamp_set(index) {
                let flux_lm = web.total_flux_lm();
                assert!(
                    flux_lm.is_finite(),
                    "lamp set {index}: flux {flux_lm} not finite"
                );
            }
        }
        exercise_photometry(&PhotometricFile::Eulumdat(Box::new(file)));
    }
});
