//! DXF (ASCII or binary) through `load_dxf`: units, 3DFACE / POLYFACE / MESH entities, blocks.
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::scene::ImportOptions;
use photomontage::scene::dxf::load_dxf;
use photomontage_fuzz::{check_model, write_scratch};

fuzz_target!(|data: &[u8]| {
    let path = write_scratch("model.dxf", data);
    if let Ok(model) = load_dxf(&path, &ImportOptions::default()) {
        check_model(&model);
    }
});
