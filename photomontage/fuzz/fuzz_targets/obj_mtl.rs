//! Wavefront OBJ + MTL through `load_obj`. The input is the OBJ text, optionally followed by
//! `\n#%MTL%\n` and the MTL text; the MTL is written under every plain file name an `mtllib`
//! line asks for, beside the OBJ, so material parsing is reached from the OBJ's own references.
#![no_main]

use libfuzzer_sys::fuzz_target;
use photomontage::scene::ImportOptions;
use photomontage::scene::obj::load_obj;
use photomontage_fuzz::{check_model, clear_scratch, write_scratch};

const MTL_MARKER: &[u8] = b"\n#%MTL%\n";
/// Most MTL names written per input (an OBJ may name many libraries).
const MAX_MTL_FILES: usize = 4;
/// Longest MTL name written (file systems refuse names over 255 bytes).
const MAX_MTL_NAME_BYTES: usize = 200;

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.windows(MTL_MARKER.len()).position(|w| w == MTL_MARKER) {
        Some(at) => (&data[..at], Some(&data[at + MTL_MARKER.len()..])),
        None => (data, None),
    };
    clear_scratch();
    if let Some(mtl) = mtl {
        let text = String::from_utf8_lossy(obj);
        let names = text
            .lines()
            .filter_map(|l| l.trim_start().strip_prefix("mtllib"))
            .flat_map(str::split_whitespace)
            .filter(|n| {
                !n.is_empty()
                    && n.len() <= MAX_MTL_NAME_BYTES
                    && !n.contains(['/', '\\', '\0'])
                    && *n != "."
                    && *n != ".."
            })
            .take(MAX_MTL_FILES);
        for name in names {
            write_scratch(name, mtl);
        }
    }
    let path = write_scratch("model.obj", obj);
    if let Ok(model) = load_obj(&path, &ImportOptions::default()) {
        check_model(&model);
    }
});
