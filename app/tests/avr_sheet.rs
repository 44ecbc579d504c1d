//! The Render panel's Report button, AVR level and Sheet button on the courtyard sample (with the
//! small OBJ box as its planned model): the report is the library's and its bearing is on
//! screen; AVR1 shows exactly the library's wireline overlay of the solved photo,
//! and the Sheet button writes a two-page PDF whose image placement matches the report's
//! viewing distance; without a finished view, no sheet is written.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{WINDOW, add_box_model, copy_sample, harness, step_until};
use egui_kittest::kittest::Queryable;
use photomontage::verified::{AvrLevel, ViewGeometryOptions, avr_overlay, view_geometry};

#[test]
fn avr1_view_and_sheet_from_the_studio() {
    let (dir, site) = copy_sample();
    add_box_model(&site);
    let mut h = harness(&site, WINDOW);
    h.get_by_label("Solve").click();
    step_until(&mut h, "solve", |s| s.solution().is_some() && s.is_idle());
    h.get_by_label("Render").click();
    h.run();
    // The Report button: the view geometry of the current photo, as the library computes it.
    h.get_by_label("Report").click();
    h.run();
    let doc = h.state().document().unwrap().clone();
    let shown = h.state().render_panel().report.clone().expect("a report");
    let library = view_geometry(&doc, "P1", &ViewGeometryOptions::default()).unwrap();
    assert_eq!(shown, library);
    h.get_by_label("Bearing (true N)");
    // The courtyard states grid convergence 0: true and grid bearing are the same number.
    let bearing = format!("{:.3} deg", library.bearing_true_deg);
    assert_eq!(h.query_all_by_label(&bearing).count(), 2);
    // No view yet: the Sheet button is disabled, nothing is written.
    let sheet = dir.path().join("P1-avr1.pdf");
    h.state_mut().render_panel_mut().sheet_path = sheet.display().to_string();
    h.get_by_label("Sheet").click();
    h.run();
    assert!(!sheet.exists());

    h.state_mut().render_panel_mut().quality.avr = AvrLevel::Avr1;
    h.get_by_label("Start").click();
    step_until(&mut h, "AVR1 view", |s| {
        !s.render_panel().busy() && s.render_panel().montage().is_some()
    });
    let doc = h.state().document().unwrap().clone();
    let library = avr_overlay(&doc, "P1", AvrLevel::Avr1).unwrap().image;
    let montage = h.state().render_panel().montage().unwrap();
    assert_eq!(montage.avr, AvrLevel::Avr1);
    let bits = |im: &photomontage::render::RenderedImage| -> Vec<u32> {
        im.rgba.iter().flatten().map(|v| v.to_bits()).collect()
    };
    assert!(
        bits(&montage.image) == bits(&library),
        "studio AVR1 differs from the library"
    );
    assert!(library.changed_pixels > 100, "the box's edges are drawn");

    h.get_by_label("Sheet").click();
    h.run();
    assert!(sheet.exists(), "{:?}", h.state().messages());
    let pdf = std::fs::read(&sheet).unwrap();
    assert!(pdf.starts_with(b"%PDF-"));
    let text = String::from_utf8_lossy(&pdf);
    assert_eq!(
        text.matches("/Type /Page\n").count() + text.matches("/Type /Page ").count(),
        2
    );
    // The image is placed at the width the report's viewing distance refers to.
    let report = view_geometry(&doc, "P1", &ViewGeometryOptions::default()).unwrap();
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
    let want = report.viewing_distance_mm * 2.0 * (report.hfov_deg.to_radians() / 2.0).tan();
    assert!(
        (w_pt * 25.4 / 72.0 - want).abs() < 0.5,
        "{w_pt} pt vs {want} mm"
    );
}
