//! `photomontage view` and `photomontage sheet` for re-projected views on the small CLI test
//! site: the written images carry the view's own geometry (TIFF: EXIF and XMP in tag 700; EXR:
//! the `photomontage.view` attribute), a cylindrical sheet is written, and bad input (an unsolved
//! photo, a focal length that cannot be converted) is refused naming the photo, leaving nothing.
#![allow(clippy::unwrap_used)]

mod common;

use std::path::Path;
use std::process::{Command, Output};

/// `focal_35mm_equiv_mm` of a planar view is the requested value up to float rounding.
const FOCAL_TOL_MM: f64 = 1e-9;

fn pm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_photomontage"))
        .args(args)
        .output()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "failed: {}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn fails(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "should fail with {needles:?}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
}

#[test]
fn views_carry_their_geometry_and_their_sheets_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let site = common::make_site(dir.path());
    let d = |name: &str| dir.path().join(name);

    // A 50 mm planar view with the montage, as TIFF: EXIF and XMP of the view.
    let tif = d("planar.tif");
    ok(&pm(&[
        "view",
        s(&site),
        "--from",
        "p1",
        "--focal-equiv-mm",
        "50",
        "--montage",
        "--out",
        s(&tif),
    ]));
    assert!(tif.with_extension("camera.json").exists());
    let bytes = std::fs::read(&tif).unwrap();
    let exif = exif::Reader::new().read_raw(bytes.clone()).unwrap();
    let description = exif
        .get_field(exif::Tag::ImageDescription, exif::In::PRIMARY)
        .unwrap()
        .display_value()
        .to_string();
    assert!(description.contains("planar view p1"), "{description}");
    let f35 = exif
        .get_field(exif::Tag::FocalLengthIn35mmFilm, exif::In::PRIMARY)
        .unwrap()
        .value
        .get_uint(0);
    assert_eq!(f35, Some(50));
    let exif::Value::Undefined(comment, _) = &exif
        .get_field(exif::Tag::UserComment, exif::In::PRIMARY)
        .unwrap()
        .value
    else {
        panic!("UserComment");
    };
    let json: serde_json::Value = serde_json::from_slice(&comment[8..]).unwrap();
    assert_eq!(json["projection"], "planar");
    assert!((json["focal_35mm_equiv_mm"].as_f64().unwrap() - 50.0).abs() < FOCAL_TOL_MM);
    let xmp = exif
        .get_field(exif::Tag(exif::Context::Tiff, 700), exif::In::PRIMARY)
        .unwrap();
    let exif::Value::Byte(packet) = &xmp.value else {
        panic!("XMP tag type");
    };
    let packet = String::from_utf8(packet.clone()).unwrap();
    assert!(
        packet.contains("photomontage:projection=\"planar\""),
        "{packet}"
    );
    let decoded = image::load_from_memory(&bytes).unwrap();
    assert_eq!(
        [decoded.width(), decoded.height()],
        json["image_size_px"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| u32::try_from(v.as_u64().unwrap()).unwrap())
            .collect::<Vec<_>>()[..]
    );

    // A cylindrical view as EXR: the header holds the cylinder's geometry.
    let exr_path = d("cylinder.exr");
    ok(&pm(&[
        "view",
        s(&site),
        "--from",
        "p1",
        "--projection",
        "cylindrical",
        "--out",
        s(&exr_path),
    ]));
    let meta = exr::meta::MetaData::read_from_file(&exr_path, false).unwrap();
    let attributes = &meta.headers[0].own_attributes;
    let Some(exr::prelude::AttributeValue::Text(text)) = attributes
        .other
        .get(&exr::prelude::Text::from("photomontage.view"))
    else {
        panic!("no photomontage.view");
    };
    let view: serde_json::Value = serde_json::from_str(&text.to_string()).unwrap();
    assert_eq!(view["projection"], "cylindrical");
    let width_px = view["image_size_px"][0].as_f64().unwrap();
    let hfov = (width_px / view["focal_px"].as_f64().unwrap()).to_degrees();
    assert!((view["hfov_deg"].as_f64().unwrap() - hfov).abs() < 1e-9);
    // Viewing distance of a cylinder: printed width / HFoV in radians.
    let want = view["printed_image_width_mm"].as_f64().unwrap() / hfov.to_radians();
    assert!((view["viewing_distance_mm"].as_f64().unwrap() - want).abs() < 1e-9);

    // The sheet of the cylinder (AVR1 drawn into the photo, composed on the cylinder).
    let pdf = d("cylinder.pdf");
    let out = ok(&pm(&[
        "sheet",
        s(&site),
        "--view",
        "p1",
        "--projection",
        "cylindrical",
        "--avr",
        "1",
        "--paper",
        "A2",
        "--out",
        s(&pdf),
    ]));
    assert!(out.contains("A2 AVR1 sheet of view p1"), "{out}");
    let text = String::from_utf8_lossy(&std::fs::read(&pdf).unwrap()).into_owned();
    assert!(text.starts_with("%PDF-"));
    assert!(text.contains("curve it about the eye"));

    // Bad input: named, nothing written.
    let bad_pdf = d("bad.pdf");
    fails(
        &pm(&[
            "sheet",
            s(&site),
            "--view",
            "p1,p2",
            "--projection",
            "cylindrical",
            "--avr",
            "1",
            "--out",
            s(&bad_pdf),
        ]),
        &["p2", "not solved"],
    );
    fails(
        &pm(&[
            "sheet",
            s(&site),
            "--view",
            "p2",
            "--projection",
            "planar",
            "--avr",
            "1",
            "--out",
            s(&bad_pdf),
        ]),
        &["p2", "not solved"],
    );
    assert!(!bad_pdf.exists());
    let bad_png = d("bad.png");
    fails(
        &pm(&[
            "view",
            s(&site),
            "--from",
            "p1",
            "--focal-equiv-mm",
            "-5",
            "--out",
            s(&bad_png),
        ]),
        &["p1", "35 mm"],
    );
    assert!(!bad_png.exists());
}
