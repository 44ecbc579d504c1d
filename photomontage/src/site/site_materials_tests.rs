// Exact comparisons: the values are copied, not computed.
#![allow(clippy::float_cmp)]

use super::*;
use crate::site::Site;

fn site_from(text: &str) -> Site {
    toml::from_str(&format!("schema_version = 1\n{text}")).unwrap()
}

#[test]
fn colour_sets_diffuse_reflectance_and_overrides_library() {
    let site = site_from(
        r##"
[[materials]]
name = "facade"
colour = "#a0522d"
specular = { roughness = 0.6, f0 = 0.04 }

[[materials]]
name = "new"
diffuse_rgb = [0.2, 0.3, 0.4]
"##,
    );
    let library = MaterialLibrary {
        materials: vec![
            Material::diffuse("facade", [0.9, 0.9, 0.9]),
            Material::diffuse("kept", [0.1, 0.1, 0.1]),
        ],
    };
    let (lib, warnings) = overlay_site_materials(Some(library), &site.materials).unwrap();
    let lib = lib.unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let facade = lib.get("facade").unwrap();
    // sRGB decode of 0xa0, 0x52, 0x2d (IEC 61966-2-1).
    let expected = crate::colour::designer::linear_from_srgb8([0xa0, 0x52, 0x2d]);
    assert_eq!(facade.diffuse_rgb, expected);
    assert!(facade.specular.is_some());
    assert_eq!(lib.get("kept").unwrap().diffuse_rgb, [0.1; 3]);
    assert_eq!(lib.get("new").unwrap().diffuse_rgb, [0.2, 0.3, 0.4]);
}

#[test]
fn out_of_gamut_and_too_bright_are_clamped_with_warnings() {
    let site = site_from(
        r#"
[[materials]]
name = "neon"
colour = "lab(50, 100, 0)"

[[materials]]
name = "bright"
diffuse_rgb = [1.2, 0.5, 0.5]
"#,
    );
    let (lib, warnings) = overlay_site_materials(None, &site.materials).unwrap();
    let lib = lib.unwrap();
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    let text: Vec<String> = warnings.iter().map(ToString::to_string).collect();
    assert!(
        text[0].contains("neon") && text[0].contains("outside the sRGB gamut"),
        "{}",
        text[0]
    );
    assert!(
        text[1].contains("bright") && text[1].contains("clamped"),
        "{}",
        text[1]
    );
    assert_eq!(lib.get("bright").unwrap().diffuse_rgb, [1.0, 0.5, 0.5]);
    assert!(
        lib.get("neon")
            .unwrap()
            .diffuse_rgb
            .iter()
            .all(|c| (0.0..=1.0).contains(c))
    );
}

#[test]
fn bad_colour_names_entry_and_text() {
    let site = site_from("[[materials]]\nname = \"wall\"\ncolour = \"lab(50, 20)\"\n");
    let e = overlay_site_materials(None, &site.materials).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("wall") && text.contains("lab(50, 20)"),
        "{text}"
    );
}

#[test]
fn unknown_keys_are_refused_and_round_trip_keeps_colour() {
    let bad: Result<Site, _> =
        toml::from_str("schema_version = 1\n[[materials]]\nname = \"wall\"\ncolr = \"#fff\"\n");
    let e = bad.unwrap_err().to_string();
    assert!(e.contains("wall") && e.contains("colr"), "{e}");
    let site = site_from(
        "[[materials]]\nname = \"wall\"\ncolour = \"#ffffff\"\n\n[[palette]]\nname = \"White\"\ncolour = \"#ffffff\"\n",
    );
    let text = toml::to_string(&site).unwrap();
    let back: Site = toml::from_str(&text).unwrap();
    assert_eq!(back, site);
    assert_eq!(back.materials[0].colour.as_deref(), Some("#ffffff"));
    assert_eq!(back.palette[0].name, "White");
}

#[test]
fn names_matching_no_scene_material_warn() {
    let site = site_from("[[materials]]\nname = \"ghost\"\n\n[[materials]]\nname = \"grass\"\n");
    let w = unmatched_site_materials(&site.materials, &[Material::diffuse("grass", [0.1; 3])]);
    assert_eq!(w.len(), 1);
    assert!(w[0].to_string().contains("ghost"));
}
