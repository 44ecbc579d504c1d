//! The verified-view sheet (PDF) of the `street` sample site, read back with poppler-utils
//! (`pdfinfo`, `pdffonts`, `pdftotext`; Debian's package, installed by `.ci/run`): page size,
//! embedded font, every number of the JSON report in the text, and the image's printed width
//! from the PDF's own placement matrix against `viewing distance × 2·tan(HFoV/2)`. Without
//! poppler-utils the test prints a notice and skips, unless `CI=true`, where it fails.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::path::Path;
use std::process::Command;

use photomontage::colour::{ToneCurve, ToneMap, encode_srgb8};
use photomontage::verified::avr::{AvrLevel, avr_overlay};
use photomontage::verified::cylindrical_view::CylindricalOptions;
use photomontage::verified::sheet::{SheetFormat, sheet_for_geometry, sheet_for_view, write_sheet};
use photomontage::verified::standard_view::{StandardView, make_view};
use photomontage::verified::{PaperSize, ViewGeometryOptions, ViewProjection, view_geometry};
use photomontage_tests::truth::site_with_true_cameras;
use std::sync::atomic::AtomicBool;

/// The bound on the printed image width against the viewing-distance formula.
const PRINTED_WIDTH_TOL_MM: f64 = 0.5;
/// pdfinfo prints the page size in points to 2 decimals.
const PAGE_SIZE_TOL_PT: f64 = 0.01;

/// Runs a poppler tool, or `None` (after a notice) when it is not installed outside CI.
fn poppler(tool: &str, args: &[&str]) -> Option<String> {
    match Command::new(tool).args(args).output() {
        Ok(out) => {
            assert!(out.status.success(), "{tool} {args:?} failed: {:?}", out);
            Some(String::from_utf8_lossy(&out.stdout).into_owned())
        }
        Err(e) => {
            let in_ci = std::env::var("CI").is_ok_and(|v| v == "true");
            assert!(!in_ci, "CI=true but {tool} (poppler-utils) cannot run: {e}");
            eprintln!("NOTICE: skipping, {tool} (poppler-utils) is not installed: {e}");
            None
        }
    }
}

fn sheet_image(doc: &photomontage::site::SiteDocument, id: &str) -> image::RgbImage {
    let overlay = avr_overlay(doc, id, AvrLevel::Avr1).unwrap();
    let [w, h] = overlay.image.size_px;
    let tone = ToneMap {
        exposure_stops: 0.0,
        curve: ToneCurve::Clamp,
    };
    image::RgbImage::from_fn(w, h, |x, y| {
        let p = overlay.image.rgba[(y * w + x) as usize];
        image::Rgb(encode_srgb8([p[0], p[1], p[2]], &tone))
    })
}

/// The placement matrix `w 0 0 h x y cm` written just before `/Im0 Do` (content streams are
/// uncompressed), in points.
fn image_placement_pt(pdf: &[u8]) -> [f64; 4] {
    let text = String::from_utf8_lossy(pdf);
    let at = text.find("/Im0 Do").unwrap();
    let before = &text[..at];
    let cm = before.rfind(" cm").unwrap();
    let numbers: Vec<f64> = before[..cm]
        .split_whitespace()
        .rev()
        .take(6)
        .map(|t| t.parse().unwrap())
        .collect();
    // Reversed: y x h 0 0 w.
    [numbers[5], numbers[2], numbers[1], numbers[0]]
}

fn number_strings(report: &serde_json::Value) -> Vec<String> {
    // (key, decimals) as the sheet states them.
    let scalars = [
        ("latitude_deg", 7),
        ("longitude_deg", 7),
        ("height_above_datum_m", 3),
        ("ground_level_m", 3),
        ("height_above_ground_m", 3),
        ("bearing_true_deg", 3),
        ("bearing_grid_deg", 3),
        ("grid_convergence_deg", 3),
        ("crs_grid_convergence_deg", 3),
        ("pitch_deg", 3),
        ("roll_deg", 3),
        ("focal_px", 2),
        ("focal_35mm_equiv_mm", 2),
        ("hfov_deg", 3),
        ("vfov_deg", 3),
        ("sun_azimuth_deg", 3),
        ("sun_elevation_deg", 3),
        ("rms_px", 3),
        ("distance_to_proposal_nearest_m", 3),
        ("distance_to_proposal_centroid_m", 3),
        ("printed_image_width_mm", 1),
        ("viewing_distance_mm", 1),
    ];
    let arrays = [
        ("camera_position_m", 3),
        ("principal_point_px", 2),
        ("sigma_center_m", 3),
        ("proposal_centroid_m", 3),
    ];
    let mut out = Vec::new();
    for (key, digits) in scalars {
        let v = report[key].as_f64().unwrap_or_else(|| panic!("{key}"));
        out.push(format!("{v:.digits$}"));
    }
    for (key, digits) in arrays {
        for v in report[key].as_array().unwrap() {
            out.push(format!("{:.digits$}", v.as_f64().unwrap()));
        }
    }
    for k in ["k1", "k2", "k3", "p1", "p2"] {
        out.push(format!("{:.6}", report["distortion"][k].as_f64().unwrap()));
    }
    for k in report["image_size_px"].as_array().unwrap() {
        out.push(k.as_u64().unwrap().to_string());
    }
    for row in report["residuals"].as_array().unwrap() {
        for v in row["observed_px"].as_array().unwrap() {
            out.push(format!("{:.2}", v.as_f64().unwrap()));
        }
        for v in row["residual_px"].as_array().unwrap() {
            out.push(format!("{:.3}", v.as_f64().unwrap()));
        }
        out.push(format!("{:.3}", row["residual_norm_px"].as_f64().unwrap()));
        out.push(format!("{:.3}", row["sigma_px"].as_f64().unwrap()));
        out.push(format!("{:.2}", row["normalised"].as_f64().unwrap()));
    }
    out
}

fn check_sheet(paper: PaperSize, page_pt: [f64; 2]) {
    let doc = site_with_true_cameras("street");
    let options = ViewGeometryOptions {
        paper,
        ..ViewGeometryOptions::default()
    };
    let report = view_geometry(&doc, "V1", &options).unwrap();
    let pdf = sheet_for_view(
        &doc,
        "V1",
        &sheet_image(&doc, "V1"),
        AvrLevel::Avr1,
        &options,
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sheet.pdf");
    write_sheet(&path, &pdf).unwrap();
    // Only the sheet is left in the folder (the temporary file was renamed).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    // The printed width from the placement matrix against the formula (computed here).
    let [w_pt, h_pt, _, _] = image_placement_pt(&pdf);
    let printed_mm = w_pt * 25.4 / 72.0;
    let want_mm = report.viewing_distance_mm * 2.0 * (report.hfov_deg.to_radians() / 2.0).tan();
    println!(
        "{}: image printed {printed_mm:.3} mm wide (formula {want_mm:.3} mm), viewing distance \
         {:.1} mm",
        paper.name(),
        report.viewing_distance_mm
    );
    assert!((printed_mm - want_mm).abs() < PRINTED_WIDTH_TOL_MM);
    assert!((h_pt / w_pt - 960.0 / 1280.0).abs() < 1e-4, "aspect kept");

    let p = path.to_str().unwrap();
    let Some(info) = poppler("pdfinfo", &[p]) else {
        return;
    };
    println!("{info}");
    assert!(info.contains("Pages:           2"), "{info}");
    let size_line = info.lines().find(|l| l.starts_with("Page size:")).unwrap();
    let dims: Vec<f64> = size_line
        .split_whitespace()
        .filter_map(|t| t.parse().ok())
        .collect();
    assert!(
        (dims[0] - page_pt[0]).abs() < PAGE_SIZE_TOL_PT
            && (dims[1] - page_pt[1]).abs() < PAGE_SIZE_TOL_PT,
        "{size_line}"
    );
    let fonts = poppler("pdffonts", &[p]).unwrap();
    let font_line = fonts
        .lines()
        .find(|l| l.starts_with("DejaVuSansMono"))
        .unwrap();
    assert!(
        font_line.contains(" yes "),
        "font not embedded: {font_line}"
    );
    let text = poppler("pdftotext", &["-layout", p, "-"]).unwrap();
    let json = serde_json::to_value(&report).unwrap();
    let missing: Vec<String> = number_strings(&json)
        .into_iter()
        .filter(|s| !text.contains(s.as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "numbers of the report missing from the PDF text: {missing:?}"
    );
    assert!(text.contains("Viewing distance") && text.contains("AVR1") && text.contains("Type 4"));
    assert!(text.contains("Methodology") && text.contains("check the print scale"));
}

#[test]
fn a3_sheet_of_the_street() {
    // ISO 216 A3: 420 × 297 mm = 1190.55 × 841.89 pt.
    check_sheet(PaperSize::A3, [1190.55, 841.89]);
}

#[test]
fn a1_sheet_of_the_street() {
    // A1: 841 × 594 mm = 2383.94 × 1683.78 pt.
    check_sheet(PaperSize::A1, [2383.94, 1683.78]);
}

#[test]
fn bad_input_leaves_no_pdf() {
    let doc = site_with_true_cameras("street");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sheet.pdf");
    // An image of the wrong size is refused by name before anything is written.
    let small = image::RgbImage::new(64, 48);
    let err = sheet_for_view(
        &doc,
        "V1",
        &small,
        AvrLevel::Avr3,
        &ViewGeometryOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("V1"), "{err}");
    // A view without a solved camera.
    let unsolved = photomontage::site::SiteDocument::load(
        &photomontage_tests::sample_site("street").join("site.toml"),
    )
    .unwrap();
    let err = sheet_for_view(
        &unsolved,
        "V2",
        &small,
        AvrLevel::Avr3,
        &ViewGeometryOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("V2") && err.contains("not solved"), "{err}");
    // A folder that does not exist: the write fails and leaves nothing.
    let bad = dir.path().join("missing").join("sheet.pdf");
    assert!(write_sheet(&bad, b"%PDF-1.7").is_err());
    assert!(!bad.exists() && !Path::new(&dir.path().join("missing")).exists());
    assert!(!path.exists());
}

#[test]
fn html_sheet_of_the_street() {
    use photomontage::verified::sheet::{SheetFormat, sheet_for_view_as};
    let doc = site_with_true_cameras("street");
    let options = ViewGeometryOptions::default();
    let report = view_geometry(&doc, "V1", &options).unwrap();
    let html = sheet_for_view_as(
        &doc,
        "V1",
        &sheet_image(&doc, "V1"),
        AvrLevel::Avr1,
        &options,
        SheetFormat::Html,
    )
    .unwrap();
    let html = String::from_utf8(html).unwrap();
    // The image's CSS width against the viewing-distance formula (computed here).
    let style = html.split("img.view {").nth(1).unwrap();
    let width_mm: f64 = style
        .split("width: ")
        .nth(1)
        .unwrap()
        .split("mm")
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let want_mm = report.viewing_distance_mm * 2.0 * (report.hfov_deg.to_radians() / 2.0).tan();
    assert!(
        (width_mm - want_mm).abs() < PRINTED_WIDTH_TOL_MM,
        "{width_mm} vs {want_mm}"
    );
    assert!(html.contains("@page { size: 420mm 297mm;"));
    // The image is embedded as a JPEG (base64 of the SOI marker FF D8 FF is "/9j/").
    assert!(html.contains("src=\"data:image/jpeg;base64,/9j/"));
    let json = serde_json::to_value(&report).unwrap();
    let missing: Vec<String> = number_strings(&json)
        .into_iter()
        .filter(|s| !html.contains(s.as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "numbers missing from the HTML: {missing:?}"
    );
    assert!(html.contains("TGN 06/19 Type 4") && html.contains("Methodology"));
}

/// The sheet of a re-projected view (planar or cylindrical) of the street site, AVR1: page size,
/// every number of its report in the text, and the printed width against the view's own
/// viewing-distance formula (`d · 2·tan(HFoV/2)` flat, `d · HFoV` for a cylinder).
fn check_reprojected_sheet(view: StandardView, paper: PaperSize, page_pt: [f64; 2]) {
    let doc = site_with_true_cameras("street");
    let options = ViewGeometryOptions {
        paper,
        ..ViewGeometryOptions::default()
    };
    let made = make_view(
        &doc,
        &view,
        Some(AvrLevel::Avr1),
        &options,
        &|_| {},
        &AtomicBool::new(false),
    )
    .unwrap();
    let report = &made.geometry;
    let tone = ToneMap {
        exposure_stops: 0.0,
        curve: ToneCurve::Clamp,
    };
    let [w, h] = made.image.size_px;
    let rgb = image::RgbImage::from_fn(w, h, |x, y| {
        let p = made.image.rgba[(y * w + x) as usize];
        image::Rgb(encode_srgb8([p[0], p[1], p[2]], &tone))
    });
    let pdf = sheet_for_geometry(&doc, report, &rgb, AvrLevel::Avr1, SheetFormat::Pdf).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sheet.pdf");
    write_sheet(&path, &pdf).unwrap();

    let [w_pt, h_pt, _, _] = image_placement_pt(&pdf);
    let printed_mm = w_pt * 25.4 / 72.0;
    let hfov = report.hfov_deg.to_radians();
    let want_mm = match report.projection {
        ViewProjection::Cylindrical => report.viewing_distance_mm * hfov,
        _ => report.viewing_distance_mm * 2.0 * (hfov / 2.0).tan(),
    };
    println!(
        "{} {:?}: {w}×{h} px, HFoV {:.3}°, printed {printed_mm:.3} mm (formula {want_mm:.3} mm), \
         viewing distance {:.1} mm",
        paper.name(),
        report.projection,
        report.hfov_deg,
        report.viewing_distance_mm
    );
    assert!((printed_mm - want_mm).abs() < PRINTED_WIDTH_TOL_MM);
    assert!(
        (h_pt / w_pt - f64::from(h) / f64::from(w)).abs() < 1e-4,
        "aspect kept"
    );

    let p = path.to_str().unwrap();
    let Some(info) = poppler("pdfinfo", &[p]) else {
        return;
    };
    assert!(info.contains("Pages:           2"), "{info}");
    let size_line = info.lines().find(|l| l.starts_with("Page size:")).unwrap();
    let dims: Vec<f64> = size_line
        .split_whitespace()
        .filter_map(|t| t.parse().ok())
        .collect();
    assert!(
        (dims[0] - page_pt[0]).abs() < PAGE_SIZE_TOL_PT
            && (dims[1] - page_pt[1]).abs() < PAGE_SIZE_TOL_PT,
        "{size_line}"
    );
    let text = poppler("pdftotext", &["-layout", p, "-"]).unwrap();
    let json = serde_json::to_value(report).unwrap();
    let missing: Vec<String> = number_strings(&json)
        .into_iter()
        .filter(|s| !text.contains(s.as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "numbers of the report missing from the PDF text: {missing:?}"
    );
    let projection = match report.projection {
        ViewProjection::Cylindrical => "cylindrical, from",
        _ => "planar, from",
    };
    assert!(text.contains(projection), "{projection}");
    if report.projection == ViewProjection::Cylindrical {
        assert!(text.contains("curve it about the eye"));
    }
}

#[test]
fn a3_sheet_of_a_50mm_planar_view() {
    check_reprojected_sheet(
        StandardView::Planar {
            photo: "V1".into(),
            focal_equiv_mm: 50.0,
            size_px: Some([640, 480]),
        },
        PaperSize::A3,
        [1190.55, 841.89],
    );
}

#[test]
fn a2_sheet_of_a_cylindrical_view() {
    // A2: 594 × 420 mm = 1683.78 × 1190.55 pt.
    check_reprojected_sheet(
        StandardView::Cylindrical {
            photos: vec!["V1".into()],
            options: CylindricalOptions::default(),
        },
        PaperSize::A2,
        [1683.78, 1190.55],
    );
}

#[test]
fn reprojected_views_refuse_bad_input_by_photo() {
    let doc = site_with_true_cameras("street");
    let make = |view: &StandardView| {
        make_view(
            &doc,
            view,
            Some(AvrLevel::Avr1),
            &ViewGeometryOptions::default(),
            &|_| {},
            &AtomicBool::new(false),
        )
        .map(|_| ())
        .unwrap_err()
        .to_string()
    };
    // A panorama from photos metres apart names a photo and the rule.
    let err = make(&StandardView::Cylindrical {
        photos: vec!["V1".into(), "V3".into()],
        options: CylindricalOptions::default(),
    });
    assert!(
        err.contains("was not taken from the same point")
            && (err.contains("V1") || err.contains("V3")),
        "{err}"
    );
    // A focal length that cannot be converted.
    let err = make(&StandardView::Planar {
        photo: "V2".into(),
        focal_equiv_mm: -5.0,
        size_px: None,
    });
    assert!(err.contains("V2") && err.contains("35 mm"), "{err}");
    // A view with no solved camera.
    let unsolved = photomontage::site::SiteDocument::load(
        &photomontage_tests::sample_site("street").join("site.toml"),
    )
    .unwrap();
    let err = make_view(
        &unsolved,
        &StandardView::Planar {
            photo: "V2".into(),
            focal_equiv_mm: 50.0,
            size_px: None,
        },
        Some(AvrLevel::Avr1),
        &ViewGeometryOptions::default(),
        &|_| {},
        &AtomicBool::new(false),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(err.contains("V2") && err.contains("not solved"), "{err}");
    // No proposal: a site without visible models.
    let mut bare = site_with_true_cameras("street");
    for m in &mut bare.site.models {
        m.visible = false;
    }
    let err = make_view(
        &bare,
        &StandardView::Cylindrical {
            photos: vec!["V1".into()],
            options: CylindricalOptions::default(),
        },
        Some(AvrLevel::Avr1),
        &ViewGeometryOptions::default(),
        &|_| {},
        &AtomicBool::new(false),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("V1") && err.contains("no visible model"),
        "{err}"
    );
}
