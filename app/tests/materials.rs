//! The Materials tab: a palette colour applied to a scene material is one undoable edit that
//! reaches the scene every renderer uses (`site_scene`), undo restores the site exactly, and an
//! out-of-gamut colour shows the gamut warning.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;

use egui_kittest::kittest::Queryable;
use photomontage::colour::designer::linear_from_srgb8;
use photomontage::site::render::site_scene;

#[test]
fn palette_colour_sets_material_undo_restores_and_gamut_warns() {
    let (_dir, site) = common::copy_sample();
    let mut text = std::fs::read_to_string(&site).unwrap();
    text.push_str(
        "\n[[palette]]\nname = \"Sienna\"\ncolour = \"#a0522d\"\n\n[[palette]]\nname = \"Neon\"\ncolour = \"lab(50, 100, 0)\"\n",
    );
    std::fs::write(&site, text).unwrap();
    let mut h = common::harness(&site, common::WINDOW);
    let before = h.state().document().unwrap().site.clone();
    h.get_by_label("Materials tab").click();
    h.run();
    h.get_by_label("Material brick").click();
    h.run();
    h.get_by_label("Use Sienna").click();
    h.run();
    let doc = h.state().document().unwrap();
    let entry = doc
        .site
        .materials
        .iter()
        .find(|m| m.material.name == "brick")
        .expect("brick is a site material now");
    assert_eq!(entry.colour.as_deref(), Some("#a0522d"));
    // The scene the renderer builds carries the colour as linear sRGB.
    let scene = site_scene(doc).unwrap();
    let brick = scene
        .scene
        .materials()
        .iter()
        .find(|m| m.name == "brick")
        .unwrap();
    assert_eq!(brick.diffuse_rgb, linear_from_srgb8([0xa0, 0x52, 0x2d]));
    assert!(
        h.query_by_label_contains("Outside the sRGB gamut")
            .is_none()
    );

    h.state_mut().undo();
    h.run();
    assert_eq!(h.state().document().unwrap().site, before);

    h.get_by_label("Use Neon").click();
    h.run();
    // The edit is applied after the frame of the click; the next frame shows its warning.
    h.step();
    h.run();
    let site_now = &h.state().document().unwrap().site;
    assert!(
        h.query_by_label_contains("Outside the sRGB gamut")
            .is_some(),
        "{:?} {:?}",
        site_now.materials,
        h.state().messages()
    );
    let doc = h.state().document().unwrap();
    let brick = site_scene(doc).unwrap();
    assert!(
        brick
            .warnings
            .iter()
            .any(|w| w.to_string().contains("outside the sRGB gamut"))
    );
}

/// A reflectance above 1 typed into the site file is clamped by the scene build; the Materials
/// tab shows that warning for the material (issue 17, bad input).
#[test]
fn a_reflectance_above_one_shows_its_clamp_warning() {
    let (_dir, site) = common::copy_sample();
    let mut text = std::fs::read_to_string(&site).unwrap();
    text.push_str("\n[[materials]]\nname = \"brick\"\ndiffuse_rgb = [1.2, 0.5, 0.5]\n");
    std::fs::write(&site, text).unwrap();
    let mut h = common::harness(&site, common::WINDOW);
    h.get_by_label("Materials tab").click();
    h.run();
    h.get_by_label("Material brick").click();
    h.run();
    let warning = h.get_by_label_contains("outside [0, 1]; clamped to");
    let shown = format!("{warning:?}");
    assert!(shown.contains("1.2"), "{shown}");
    // Another material shows none.
    h.get_by_label("Material plaster").click();
    h.run();
    assert!(
        h.query_by_label_contains("outside [0, 1]; clamped to")
            .is_none()
    );
}
