//! Output images carry their view: the EXIF the library writes into JPEG and PNG renders of the
//! street site (true cameras), read back with kamadak-exif (and the library's own EXIF reader)
//! and compared with the view geometry report.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use exif::{In, Tag, Value};
use photomontage::verified::image_metadata::{exif_block, write_8bit_with_exif};
use photomontage::verified::{ViewGeometryOptions, view_geometry};
use photomontage_tests::truth::site_with_true_cameras;

/// GPS angles are written as degrees, minutes and seconds to 1e-4″ (3e-8°).
const GPS_TOL_DEG: f64 = 1e-7;
/// Bearing and altitude are written as rationals over 1000.
const RATIONAL_TOL: f64 = 5e-4;

fn rational(exif: &exif::Exif, tag: Tag, ifd: In) -> f64 {
    match &exif.get_field(tag, ifd).unwrap().value {
        Value::Rational(r) => r[0].to_f64(),
        other => panic!("{tag}: {other:?}"),
    }
}

#[test]
fn jpeg_and_png_carry_the_view_geometry() {
    let doc = site_with_true_cameras("street");
    let report = view_geometry(&doc, "V2", &ViewGeometryOptions::default()).unwrap();
    let rgb = image::RgbImage::from_pixel(64, 48, image::Rgb([120, 130, 140]));
    let dir = tempfile::tempdir().unwrap();
    for name in ["v2.jpg", "v2.png"] {
        let path = dir.path().join(name);
        write_8bit_with_exif(&path, &rgb, exif_block(&report), 90).unwrap();
        // The library's reader: position, 35 mm equivalent, capture time with its offset.
        let info = photomontage::photo::read_exif(&path).unwrap();
        let gps = info.gps.unwrap();
        println!("{name}: {gps:?}, f35 {:?}", info.focal_length_35mm);
        assert!((gps.latitude_deg - report.latitude_deg.unwrap()).abs() < GPS_TOL_DEG);
        assert!((gps.longitude_deg - report.longitude_deg.unwrap()).abs() < GPS_TOL_DEG);
        assert!((gps.altitude_m.unwrap() - report.height_above_datum_m).abs() < RATIONAL_TOL);
        assert_eq!(
            info.focal_length_35mm,
            Some(report.focal_35mm_equiv_mm.round())
        );
        let taken =
            chrono::DateTime::parse_from_rfc3339(&info.taken_at_rfc3339().unwrap()).unwrap();
        let captured =
            chrono::DateTime::parse_from_rfc3339(report.capture_time.as_deref().unwrap()).unwrap();
        assert_eq!(taken, captured);
        // kamadak-exif directly: bearing, description and the JSON summary.
        let file = std::fs::File::open(&path).unwrap();
        let exif = exif::Reader::new()
            .read_from_container(&mut std::io::BufReader::new(file))
            .unwrap();
        let bearing = rational(&exif, Tag::GPSImgDirection, In::PRIMARY);
        assert!(
            (bearing - report.bearing_true_deg).abs() < RATIONAL_TOL,
            "{bearing}"
        );
        let description = exif
            .get_field(Tag::ImageDescription, In::PRIMARY)
            .unwrap()
            .display_value()
            .to_string();
        assert!(description.contains("verified view V2"), "{description}");
        let Value::Undefined(comment, _) =
            &exif.get_field(Tag::UserComment, In::PRIMARY).unwrap().value
        else {
            panic!("UserComment is not UNDEFINED");
        };
        let json: serde_json::Value = serde_json::from_slice(&comment[8..]).unwrap();
        assert_eq!(json["photo_id"], "V2");
        assert!((json["hfov_deg"].as_f64().unwrap() - report.hfov_deg).abs() < 1e-12);
        assert!((json["roll_deg"].as_f64().unwrap() - report.roll_deg).abs() < 1e-12);
    }
    // Other formats are refused, and nothing is written.
    let tif = dir.path().join("v2.tif");
    assert!(write_8bit_with_exif(&tif, &rgb, exif_block(&report), 90).is_err());
    assert!(!tif.exists());
}
