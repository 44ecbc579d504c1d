//! The Render panel's re-projected views and sheet paper on the courtyard sample (with the small
//! OBJ box as its planned model), driven by their labels: "planar 50 mm" makes exactly the
//! library's planar view (`photomontage::verified::standard_view::make_view`) with its geometry;
//! "paper A2" puts its sheet on A2 with the image at the width the view's viewing distance refers
//! to; "cylindrical" with the photos typed into "panorama photos" makes the library's panorama, and
//! photos not taken from one point are refused with the library's message.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::sync::atomic::AtomicBool;

use common::{WINDOW, add_box_model, copy_sample, harness, step_until};
use egui_kittest::kittest::Queryable;
use photomontage::verified::cylindrical_view::CylindricalOptions;
use photomontage::verified::reprojected_geometry::with_paper;
use photomontage::verified::standard_view::{StandardView, make_view};
use photomontage::verified::{AvrLevel, PaperSize, ViewGeometryOptions, ViewProjection};
use photomontage_studio::render_views::ViewKind;

/// The bound on the printed image width against the viewing-distance formula.
const PRINTED_WIDTH_TOL_MM: f64 = 0.5;
/// pdf-writer writes coordinates as f32: 1e-3 pt is well above their rounding.
const PAGE_SIZE_TOL_PT: f64 = 1e-3;

fn bits(im: &photomontage::render::RenderedImage) -> Vec<u32> {
    im.rgba.iter().flatten().map(|v| v.to_bits()).collect()
}

/// The numbers after `key [` in the PDF text.
fn numbers_after(text: &str, key: &str) -> Vec<f64> {
    let at = text.find(key).unwrap() + key.len();
    let end = at + text[at..].find(']').unwrap();
    text[at..end]
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

fn run_until_made(h: &mut egui_kittest::Harness<'static, photomontage_studio::Studio>, what: &str) {
    let before = h.state().messages().len();
    h.get_by_label("Start").click();
    step_until(h, what, |s| {
        !s.render_panel().busy() && s.messages().len() > before
    });
}

#[test]
fn planar_and_cylindrical_views_and_the_sheet_paper_from_the_studio() {
    let (dir, site) = copy_sample();
    add_box_model(&site);
    let mut h = harness(&site, WINDOW);
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Render").click();
    h.run();
    h.state_mut().render_panel_mut().quality.avr = AvrLevel::Avr1;

    // Planar 50 mm: the library's view and geometry.
    h.get_by_label("planar 50 mm").click();
    h.run();
    assert_eq!(
        h.state().render_panel().view_choice.kind,
        ViewKind::Planar50
    );
    run_until_made(&mut h, "planar view");
    let doc = h.state().document().unwrap().clone();
    let planar = StandardView::Planar {
        photo: "P1".into(),
        focal_equiv_mm: 50.0,
        size_px: None,
    };
    let library = make_view(
        &doc,
        &planar,
        Some(AvrLevel::Avr1),
        &ViewGeometryOptions::default(),
        &|_| {},
        &AtomicBool::new(false),
    )
    .unwrap();
    let montage = h.state().render_panel().montage().expect("a planar view");
    assert!(
        bits(&montage.image) == bits(&library.image),
        "studio planar view differs"
    );
    let geometry = montage.geometry.clone().expect("the view's geometry");
    assert_eq!(geometry, library.geometry);
    assert_eq!(geometry.projection, ViewProjection::Planar);
    assert!((geometry.focal_35mm_equiv_mm - 50.0).abs() < 1e-9);

    // Paper A2: the sheet's page and the printed width follow the view's geometry.
    h.get_by_label("paper A2").click();
    h.run();
    assert_eq!(h.state().render_panel().view_choice.paper, PaperSize::A2);
    let sheet = dir.path().join("P1-planar50-a2.pdf");
    h.state_mut().render_panel_mut().sheet_path = sheet.display().to_string();
    h.get_by_label("Sheet").click();
    h.run();
    assert!(sheet.exists(), "{:?}", h.state().messages());
    let pdf = std::fs::read(&sheet).unwrap();
    let text = String::from_utf8_lossy(&pdf);
    let media = numbers_after(&text, "/MediaBox [");
    let [w_mm, h_mm] = PaperSize::A2.size_mm();
    assert!(
        (media[2] - w_mm * 72.0 / 25.4).abs() < PAGE_SIZE_TOL_PT,
        "{media:?}"
    );
    assert!(
        (media[3] - h_mm * 72.0 / 25.4).abs() < PAGE_SIZE_TOL_PT,
        "{media:?}"
    );
    let a2 = with_paper(&geometry, PaperSize::A2);
    let at = text.find("/Im0 Do").unwrap();
    let before = &text[..at];
    let cm = before.rfind(" cm").unwrap();
    let w_pt: f64 = before[..cm]
        .split_whitespace()
        .rev()
        .nth(5)
        .unwrap()
        .parse()
        .unwrap();
    let want = a2.viewing_distance_mm * 2.0 * (a2.hfov_deg.to_radians() / 2.0).tan();
    assert!(
        (w_pt * 25.4 / 72.0 - want).abs() < PRINTED_WIDTH_TOL_MM,
        "{w_pt} pt vs {want} mm"
    );

    // Cylindrical of P1: the library's panorama.
    h.get_by_label("cylindrical").click();
    h.run();
    h.get_by_label("panorama photos").click();
    h.get_by_label("panorama photos").type_text("P1");
    h.run();
    run_until_made(&mut h, "cylindrical view");
    let cylinder = StandardView::Cylindrical {
        photos: vec!["P1".into()],
        options: CylindricalOptions::default(),
    };
    let library = make_view(
        &doc,
        &cylinder,
        Some(AvrLevel::Avr1),
        &ViewGeometryOptions {
            paper: PaperSize::A2,
            ground_level_m: None,
        },
        &|_| {},
        &AtomicBool::new(false),
    )
    .unwrap();
    let montage = h.state().render_panel().montage().expect("a panorama");
    assert!(
        bits(&montage.image) == bits(&library.image),
        "studio panorama differs"
    );
    assert_eq!(montage.geometry.as_ref(), Some(&library.geometry));

    // P1 and P2 stand metres apart: refused, naming the rule, and the panorama stays.
    h.state_mut()
        .render_panel_mut()
        .view_choice
        .panorama_photos
        .clear();
    h.run();
    h.get_by_label("panorama photos").click();
    h.run();
    h.get_by_label("panorama photos").type_text("P1,P2");
    h.run();
    assert_eq!(
        h.state().render_panel().view_choice.panorama_photos,
        "P1,P2"
    );
    run_until_made(&mut h, "refused panorama");
    let last = h.state().messages().last().unwrap();
    assert!(last.is_error, "{}", last.text);
    assert!(
        last.text.contains("was not taken from the same point"),
        "{}",
        last.text
    );
    let montage = h
        .state()
        .render_panel()
        .montage()
        .expect("the panorama stays");
    assert_eq!(montage.geometry.as_ref(), Some(&library.geometry));
}
