//! Inputs the coverage-guided fuzzers (`photomontage/fuzz/`, docs/fuzzing.md) found crashing,
//! checked here without the fuzzer.
//!
//! Every file under `tests/data/fuzz/<target>/` is one input exactly as libFuzzer saved it; the
//! replay test feeds each through the same entry point and input layout as the fuzz target of
//! that name, so a new finding only needs its file dropped in. The named tests beside it check
//! the clear error each fixed crash now gives, on a minimal hand-written input.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::path::{Path, PathBuf};

use photomontage::luminaire::{EulumdatFile, IesFile, PhotometricFile};
use photomontage::photo::{DecodeLimits, load_with_limits, read_exif};
use photomontage::photogrammetry::control_io::{
    parse_control_points_csv, parse_odm_gcp_list, parse_points_csv,
};
use photomontage::scene::dxf::load_dxf;
use photomontage::scene::gltf::{GltfError, load_gltf};
use photomontage::scene::obj::load_obj;
use photomontage::scene::{ImportOptions, ImportWarning, MaterialLibrary};
use photomontage::site::Site;

/// Separates the OBJ from the MTL in an `obj_mtl` input (as in `fuzz_targets/obj_mtl.rs`).
const MTL_MARKER: &[u8] = b"\n#%MTL%\n";
/// Separates the IES file from its tilt file in an `ies` input (as in `fuzz_targets/ies.rs`).
const TILT_MARKER: &[u8] = b"\0TILT\0";
/// Longest MTL name an `obj_mtl` input is written under (as in `fuzz_targets/obj_mtl.rs`).
const MAX_MTL_NAME_BYTES: usize = 200;
/// The photo target's decode limits (as in `fuzz_targets/photo.rs`).
const PHOTO_LIMITS: DecodeLimits = DecodeLimits {
    max_pixels: 16_000_000,
    max_bytes: 512 << 20,
};

fn split_at_marker<'a>(data: &'a [u8], marker: &[u8]) -> (&'a [u8], Option<&'a [u8]>) {
    match data.windows(marker.len()).position(|w| w == marker) {
        Some(at) => (&data[..at], Some(&data[at + marker.len()..])),
        None => (data, None),
    }
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Writes an `obj_mtl` input as the fuzz target does: the MTL under every plain name an
/// `mtllib` line asks for, the OBJ as `model.obj`.
fn write_obj_input(dir: &Path, data: &[u8]) -> PathBuf {
    let (obj, mtl) = split_at_marker(data, MTL_MARKER);
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
            .take(4);
        for name in names {
            write(dir, name, mtl);
        }
    }
    write(dir, "model.obj", obj)
}

/// Feeds one saved input to the entry point of the fuzz target `target`. Errors are fine; a
/// panic fails the test.
fn replay(target: &str, data: &[u8]) {
    let dir = tempfile::tempdir().unwrap();
    let text = std::str::from_utf8(data).ok();
    let options = ImportOptions::default();
    match target {
        "site_toml" => {
            if let Some(text) = text
                && let Ok(site) = Site::from_toml(text, Path::new("fuzz/site.toml"))
            {
                let again = site.to_toml().unwrap();
                assert_eq!(Site::from_toml(&again, Path::new("x")).unwrap(), site);
            }
        }
        "material_toml" => {
            let _ = text.map(MaterialLibrary::from_toml_str);
        }
        "control_csv" => {
            if let Some(text) = text {
                let _ = parse_control_points_csv(text, [0.05; 3]);
                let _ = parse_points_csv(text);
            }
        }
        "gcp_list" => {
            let _ = text.map(parse_odm_gcp_list);
        }
        "ies" => {
            let (ies, tilt) = split_at_marker(data, TILT_MARKER);
            if let Ok(file) = IesFile::parse_with_tilt_resolver(ies, &mut |_| {
                tilt.map(<[u8]>::to_vec).ok_or_else(|| "none".to_owned())
            }) && let Ok(web) = file.distribution()
            {
                let _ = web.total_flux_lm();
            }
            if let Ok(file) = PhotometricFile::parse(ies)
                && let Ok(web) = file.distribution()
            {
                let _ = web.total_flux_lm();
            }
        }
        "eulumdat" => {
            if let Ok(file) = EulumdatFile::parse(data) {
                for index in 0..4 {
                    let _ = file
                        .distribution_for_lamp_set(index)
                        .map(|w| w.total_flux_lm());
                }
            }
        }
        "obj_mtl" => {
            let _ = load_obj(&write_obj_input(dir.path(), data), &options);
        }
        "gltf" => {
            let name = if data.starts_with(b"glTF") {
                "model.glb"
            } else {
                "model.gltf"
            };
            let _ = load_gltf(&write(dir.path(), name, data), &options);
        }
        "dxf" => {
            let _ = load_dxf(&write(dir.path(), "model.dxf", data), &options);
        }
        "exif" => {
            let _ = read_exif(&write(dir.path(), "photo.jpg", data));
        }
        "photo" => {
            let _ = load_with_limits(&write(dir.path(), "photo", data), &PHOTO_LIMITS);
        }
        other => panic!("tests/data/fuzz/{other}: no fuzz target of that name"),
    }
}

#[test]
fn every_saved_fuzz_finding_replays_without_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz");
    let mut replayed = 0;
    for target in std::fs::read_dir(&root).unwrap() {
        let target = target.unwrap();
        let name = target.file_name().to_string_lossy().into_owned();
        for input in std::fs::read_dir(target.path()).unwrap() {
            let input = input.unwrap().path();
            println!("replaying {name}/{}", input.display());
            replay(&name, &std::fs::read(&input).unwrap());
            replayed += 1;
        }
    }
    // The inputs stored so far (docs/fuzzing.md); the count only grows.
    assert!(
        replayed >= 5,
        "only {replayed} saved inputs under {}",
        root.display()
    );
}

/// A triangle whose OBJ names `m.mtl`.
const TRIANGLE_OBJ: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";

/// tobj 4.0 panicked (`unwrap` in `parse_float3`) on a colour with two values; now the library
/// is reported as unreadable, naming the line, and the model loads with the default material.
#[test]
fn mtl_colour_with_two_values_is_a_named_warning() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "m.mtl", b"newmtl a\nKs 0 0 0\nKd 0.2 0.55\n");
    let obj = write(dir.path(), "model.obj", TRIANGLE_OBJ.as_bytes());
    let model = load_obj(&obj, &ImportOptions::default()).unwrap();
    assert_eq!(model.triangles_in_world_m.len(), 1);
    let reason = model
        .warnings
        .iter()
        .find_map(|w| match w {
            ImportWarning::MissingMaterialLibrary { name, reason } if name == "m.mtl" => {
                Some(reason.clone())
            }
            _ => None,
        })
        .unwrap_or_else(|| panic!("no MTL warning in {:?}", model.warnings));
    assert_eq!(
        reason,
        "m.mtl: line 3: `Kd` needs 3 numbers (r g b), found 2"
    );
}

/// A well-formed colour line still loads (the check only refuses short ones).
#[test]
fn mtl_colour_with_three_values_still_loads() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "m.mtl", b"newmtl a\r\nKd 0.2 0.55 0.1 \r\n");
    let obj = write(dir.path(), "model.obj", TRIANGLE_OBJ.as_bytes());
    let model = load_obj(&obj, &ImportOptions::default()).unwrap();
    assert!(
        model
            .warnings
            .iter()
            .all(|w| !matches!(w, ImportWarning::MissingMaterialLibrary { .. })),
        "{:?}",
        model.warnings
    );
    assert_eq!(model.materials[0].name, "a");
}

/// The `quad_nodes.gltf` fixture as JSON, to be broken one field at a time.
fn quad_fixture() -> serde_json::Value {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/quad_nodes.gltf");
    serde_json::from_str(&std::fs::read_to_string(fixture).unwrap()).unwrap()
}

/// The `GltfError::Load` reason for `json`, failing the test on any other outcome.
fn gltf_load_reason(json: &serde_json::Value) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "model.gltf", json.to_string().as_bytes());
    match load_gltf(&path, &ImportOptions::default()) {
        Err(GltfError::Load { reason, .. }) => reason,
        other => panic!("expected a load error, got {other:?}"),
    }
}

/// gltf 1.4 reached `unreachable!()` reading an index accessor of a signed type (SHORT, 5122);
/// now it is a load error naming the primitive and accessor.
#[test]
fn gltf_signed_index_accessor_is_a_load_error() {
    let mut json = quad_fixture();
    let indices = json["meshes"][0]["primitives"][0]["indices"]
        .as_u64()
        .unwrap();
    json["accessors"][indices as usize]["componentType"] = 5122.into();
    assert_eq!(
        gltf_load_reason(&json),
        format!(
            "meshes[0].primitives[0].indices (accessor {indices}) must be SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT (5121, 5123, 5125)"
        )
    );
}

/// A POSITION buffer view whose stride is shorter than a VEC3 of floats would make gltf 1.4
/// assert on a short slice; it is refused up front.
#[test]
fn gltf_position_stride_shorter_than_a_vertex_is_a_load_error() {
    let mut json = quad_fixture();
    let position = json["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap() as usize;
    let view = json["accessors"][position]["bufferView"].as_u64().unwrap() as usize;
    json["bufferViews"][view]["byteStride"] = 8.into();
    assert_eq!(
        gltf_load_reason(&json),
        format!(
            "meshes[0].primitives[0].attributes.POSITION: bufferViews[{view}].byteStride 8 is smaller than one element (12 bytes)"
        )
    );
}

/// gltf-json 1.4 panicked (index out of bounds in its validation) on a `POSITION` accessor
/// index past the end; now it is a load error naming the mesh, primitive and index.
#[test]
fn gltf_position_accessor_out_of_range_is_a_load_error() {
    let mut json = quad_fixture();
    let accessors = json["accessors"].as_array().unwrap().len();
    json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = accessors.into();
    assert_eq!(
        gltf_load_reason(&json),
        format!(
            "meshes[0].primitives[0].attributes.POSITION is accessor {accessors}, but there are {accessors} accessors"
        )
    );
}

/// gltf 1.4 subtracted the 12-byte GLB header from the declared total length unchecked (an
/// overflow panic with overflow checks on); a declared length under 12 is now a load error.
#[test]
fn glb_length_shorter_than_its_header_is_a_load_error() {
    let mut glb = b"glTF".to_vec();
    glb.extend_from_slice(&2_u32.to_le_bytes());
    glb.extend_from_slice(&0_u32.to_le_bytes());
    glb.extend_from_slice(&8_u32.to_le_bytes());
    glb.extend_from_slice(b"JSON{}      ");
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "model.glb", &glb);
    match load_gltf(&path, &ImportOptions::default()) {
        Err(GltfError::Load { reason, .. }) => assert_eq!(
            reason,
            "GLB header declares a total length of 0 bytes, less than the 12-byte header itself"
        ),
        other => panic!("expected a load error, got {other:?}"),
    }
}
