//! Site TOML: `Site::from_toml` (syntax, schema version, validation). A site that loads must
//! serialise and load back to an equal value, as `Site::to_toml` promises.
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::site::Site;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("fuzz/site.toml");
    if let Ok(site) = Site::from_toml(text, path) {
        let again = site.to_toml().expect("a loaded site serialises");
        let back = Site::from_toml(&again, path).expect("a serialised site loads back");
        assert_eq!(back, site, "site TOML round trip changed the site");
    }
});
