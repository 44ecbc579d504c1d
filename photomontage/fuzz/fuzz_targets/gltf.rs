//! glTF 2.0 through `load_gltf`: bytes starting with `glTF` are written as `model.glb`, anything
//! else as `model.gltf` (JSON; buffers as data URIs, or external names that are then missing).
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::scene::ImportOptions;
use photomontage::scene::gltf::load_gltf;
use photomontage_fuzz::{check_model, clear_scratch, write_scratch};

fuzz_target!(|data: &[u8]| {
    clear_scratch();
    let name = if data.starts_with(b"glTF") {
        "model.glb"
    } else {
        "model.gltf"
    };
    let path = write_scratch(name, data);
    if let Ok(model) = load_gltf(&path, &ImportOptions::default()) {
        check_model(&model);
    }
});
