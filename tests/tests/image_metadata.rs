//! Output images carry their view: the EXIF and XMP the library writes into JPEG, PNG and TIFF
//! renders and the header attributes of EXR renders of the street site (true cameras), read
//! back with independent readers — kamadak-exif for EXIF, quick-xml for the XMP packet, the exr
//! crate for the EXR header — and compared with the view geometry report.
#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use std::collections::BTreeMap;

use exif::{Context, In, Tag, Value};
use photomontage::render::{OutputLayers, RenderedImage};
use photomontage::verified::image_metadata::{
    encode_8bit_with_view, write_8bit_with_view, write_render,
};
use photomontage::verified::view_metadata::EXR_VIEW_ATTRIBUTE;
use photomontage::verified::xmp::{JPEG_XMP_SIGNATURE, NAMESPACE, PNG_XMP_KEYWORD};
use photomontage::verified::{ViewGeometryOptions, ViewMetadata, view_geometry};
use photomontage_tests::truth::site_with_true_cameras;
use quick_xml::events::Event;

/// GPS angles are written as degrees, minutes and seconds to 1e-4″ (3e-8°).
const GPS_TOL_DEG: f64 = 1e-7;
/// Bearing and altitude are written as rationals over 1000.
const RATIONAL_TOL: f64 = 5e-4;
/// XMP GPS coordinates carry minutes to 8 decimals (2e-10°).
const XMP_GPS_TOL_DEG: f64 = 1e-9;

fn rational(exif: &exif::Exif, tag: Tag, ifd: In) -> f64 {
    match &exif.get_field(tag, ifd).unwrap().value {
        Value::Rational(r) => r[0].to_f64(),
        other => panic!("{tag}: {other:?}"),
    }
}

fn street_v2() -> (photomontage::verified::ViewGeometry, ViewMetadata) {
    let doc = site_with_true_cameras("street");
    let report = view_geometry(&doc, "V2", &ViewGeometryOptions::default()).unwrap();
    let metadata = ViewMetadata::from(&report);
    (report, metadata)
}

/// The XMP packet inside a JPEG (APP1 with the XMP signature), PNG (iTXt with the XMP keyword)
/// or TIFF (tag 700) file, found by walking the file's own structure.
fn xmp_of(bytes: &[u8], ext: &str) -> String {
    match ext {
        "jpg" => {
            let mut at = 2;
            loop {
                assert_eq!(bytes[at], 0xFF, "JPEG marker at {at}");
                let marker = bytes[at + 1];
                let len = usize::from(u16::from_be_bytes([bytes[at + 2], bytes[at + 3]]));
                let payload = &bytes[at + 4..at + 2 + len];
                if marker == 0xE1 && payload.starts_with(JPEG_XMP_SIGNATURE) {
                    return String::from_utf8(payload[JPEG_XMP_SIGNATURE.len()..].to_vec())
                        .unwrap();
                }
                assert!(marker != 0xDA, "no XMP APP1 before the scan");
                at += 2 + len;
            }
        }
        "png" => {
            let mut at = 8;
            while at + 8 <= bytes.len() {
                let len = u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
                let kind = &bytes[at + 4..at + 8];
                let data = &bytes[at + 8..at + 8 + len];
                if kind == b"iTXt" && data.starts_with(PNG_XMP_KEYWORD.as_bytes()) {
                    // keyword NUL, flag, method, language NUL, translated NUL.
                    let text = &data[PNG_XMP_KEYWORD.len() + 5..];
                    return String::from_utf8(text.to_vec()).unwrap();
                }
                at += 12 + len;
            }
            panic!("no XMP iTXt chunk");
        }
        "tif" => {
            let exif = exif::Reader::new().read_raw(bytes.to_vec()).unwrap();
            let field = exif
                .get_field(Tag(Context::Tiff, 700), In::PRIMARY)
                .unwrap();
            let Value::Byte(packet) = &field.value else {
                panic!("tag 700 is {:?}", field.value);
            };
            String::from_utf8(packet.clone()).unwrap()
        }
        other => panic!("{other}"),
    }
}

/// Every property of the packet's `rdf:Description`: attributes by qualified name, and the
/// `rdf:li` items of each `photomontage:` sequence (as `name[i]`). Also checks the namespace.
fn xmp_properties(packet: &str) -> BTreeMap<String, String> {
    let mut reader = quick_xml::Reader::from_str(packet);
    let mut out = BTreeMap::new();
    let mut sequence: Option<(String, usize)> = None;
    let mut in_li = false;
    let mut saw_namespace = false;
    loop {
        match reader.read_event().unwrap() {
            Event::Start(e) | Event::Empty(e) => {
                let name = String::from_utf8(e.name().as_ref().to_vec()).unwrap();
                if name == "rdf:Description" {
                    for a in e.attributes() {
                        let a = a.unwrap();
                        let key = String::from_utf8(a.key.as_ref().to_vec()).unwrap();
                        let value = a
                            .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                            .unwrap()
                            .into_owned();
                        if key == "xmlns:photomontage" {
                            saw_namespace = value == NAMESPACE;
                        }
                        out.insert(key, value);
                    }
                } else if let Some(prop) = name.strip_prefix("photomontage:") {
                    sequence = Some((prop.to_owned(), 0));
                } else if name == "rdf:li" {
                    in_li = true;
                }
            }
            Event::Text(t) if in_li => {
                let (prop, i) = sequence.as_mut().unwrap();
                out.insert(format!("{prop}[{i}]"), t.decode().unwrap().into_owned());
                *i += 1;
            }
            Event::End(e) if e.name().as_ref() == b"rdf:li" => in_li = false,
            Event::Eof => break,
            _ => {}
        }
    }
    assert!(saw_namespace, "photomontage namespace declared");
    out
}

fn number(props: &BTreeMap<String, String>, key: &str) -> f64 {
    props
        .get(key)
        .unwrap_or_else(|| panic!("{key} missing"))
        .parse()
        .unwrap()
}

/// `DDD,MM.mmmmmmmmk` to signed degrees.
fn xmp_gps(text: &str) -> f64 {
    let (deg, rest) = text.split_once(',').unwrap();
    let (minutes, hemisphere) = rest.split_at(rest.len() - 1);
    let v = deg.parse::<f64>().unwrap() + minutes.parse::<f64>().unwrap() / 60.0;
    if matches!(hemisphere, "S" | "W") {
        -v
    } else {
        v
    }
}

/// Every number of the metadata equals the packet's (exactly: shortest round-trip decimals).
fn assert_xmp_matches(props: &BTreeMap<String, String>, m: &ViewMetadata) {
    let json = serde_json::to_value(m).unwrap();
    let mut checked = 0;
    for (key, value) in json.as_object().unwrap() {
        match value {
            serde_json::Value::Number(n) => {
                let v = n.as_f64().unwrap();
                assert_eq!(
                    number(props, &format!("photomontage:{key}")).to_bits(),
                    v.to_bits(),
                    "{key}"
                );
                checked += 1;
            }
            serde_json::Value::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    let name = format!("{key}[{i}]");
                    match item {
                        serde_json::Value::Number(n) if key == "image_size_px" => {
                            let axis = ["image_width_px", "image_height_px"][i];
                            assert_eq!(
                                number(props, &format!("photomontage:{axis}")).to_bits(),
                                n.as_f64().unwrap().to_bits()
                            );
                        }
                        serde_json::Value::Number(n) => {
                            assert_eq!(
                                number(props, &name).to_bits(),
                                n.as_f64().unwrap().to_bits(),
                                "{name}"
                            );
                        }
                        serde_json::Value::String(s) => assert_eq!(&props[&name], s, "{name}"),
                        other => panic!("{name}: {other}"),
                    }
                    checked += 1;
                }
            }
            serde_json::Value::String(s) if key != "software" => {
                assert_eq!(&props[&format!("photomontage:{key}")], s, "{key}");
                checked += 1;
            }
            _ => {}
        }
    }
    // photo_id, projection, crs, capture_time, paper + 19 numbers + 4 arrays (3+3+2+1) + size.
    assert!(checked >= 30, "only {checked} values checked");
    assert_eq!(props["xmp:CreatorTool"], m.software);
    assert_eq!(
        props["exif:FocalLengthIn35mmFilm"],
        format!("{:.0}", m.focal_35mm_equiv_mm.round())
    );
    assert_eq!(
        Some(props["exif:DateTimeOriginal"].as_str()),
        m.capture_time.as_deref()
    );
    assert!(
        (xmp_gps(&props["exif:GPSLatitude"]) - m.latitude_deg.unwrap()).abs() < XMP_GPS_TOL_DEG
    );
    assert!(
        (xmp_gps(&props["exif:GPSLongitude"]) - m.longitude_deg.unwrap()).abs() < XMP_GPS_TOL_DEG
    );
    assert_eq!(
        props["tiff:ImageWidth"].parse::<u32>().unwrap(),
        m.image_size_px[0]
    );
}

#[test]
fn jpeg_png_and_tiff_carry_the_view_geometry_as_exif_and_xmp() {
    let (report, metadata) = street_v2();
    let rgb = image::RgbImage::from_fn(64, 48, |x, y| image::Rgb([x as u8 * 3, y as u8 * 5, 140]));
    let dir = tempfile::tempdir().unwrap();
    for ext in ["jpg", "png", "tif"] {
        let path = dir.path().join(format!("v2.{ext}"));
        write_8bit_with_view(&path, &rgb, &metadata, 90).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        // The image itself decodes (TIFF and PNG losslessly).
        let decoded = image::load_from_memory(&bytes).unwrap().to_rgb8();
        assert_eq!(decoded.dimensions(), (64, 48), "{ext}");
        if ext != "jpg" {
            assert_eq!(decoded.as_raw(), rgb.as_raw(), "{ext} pixels");
        }
        // The library's reader: position, 35 mm equivalent, capture time with its offset.
        let info = photomontage::photo::read_exif(&path).unwrap();
        let gps = info.gps.unwrap();
        println!("{ext}: {gps:?}, f35 {:?}", info.focal_length_35mm);
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
        let exif = exif::Reader::new()
            .read_from_container(&mut std::io::Cursor::new(&bytes))
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
        let from_comment: ViewMetadata = serde_json::from_slice(&comment[8..]).unwrap();
        assert_eq!(from_comment, metadata, "{ext} UserComment");
        // XMP, parsed as XML: every number equal to the report's.
        let props = xmp_properties(&xmp_of(&bytes, ext));
        assert_xmp_matches(&props, &metadata);
        assert_eq!(
            number(&props, "photomontage:hfov_deg").to_bits(),
            report.hfov_deg.to_bits()
        );
        assert_eq!(
            number(&props, "camera_position_m[2]").to_bits(),
            report.camera_position_m[2].to_bits()
        );
    }
    // Other formats are refused, and nothing is written.
    let bmp = dir.path().join("v2.bmp");
    assert!(write_8bit_with_view(&bmp, &rgb, &metadata, 90).is_err());
    assert!(!bmp.exists());
    // The bytes are deterministic (farm merges rely on it).
    let path = dir.path().join("again.tif");
    assert_eq!(
        encode_8bit_with_view(&path, &rgb, &metadata, 90).unwrap(),
        encode_8bit_with_view(&path, &rgb, &metadata, 90).unwrap()
    );
}

#[test]
fn exr_renders_carry_the_view_geometry_as_header_attributes() {
    use exr::prelude::{AttributeValue, Text};
    let (report, metadata) = street_v2();
    let [w, h] = [16_u32, 8];
    let image = RenderedImage {
        size_px: [w, h],
        rgba: (0..w * h).map(|i| [i as f32, 0.5, 0.25, 1.0]).collect(),
        changed_pixels: 0,
        primary_rays: 0,
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v2.exr");
    let tone = photomontage::colour::ToneMap::clamp_with_exposure(0.0);
    write_render(
        &path,
        &image,
        &OutputLayers::default(),
        &tone,
        Some(&metadata),
    )
    .unwrap();
    let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
    let a = &meta.headers[0].own_attributes;
    let Some(AttributeValue::Text(json)) = a.other.get(&Text::from(EXR_VIEW_ATTRIBUTE)) else {
        panic!("no {EXR_VIEW_ATTRIBUTE}: {:?}", a.other.keys());
    };
    let from_exr: ViewMetadata = serde_json::from_str(&json.to_string()).unwrap();
    assert_eq!(from_exr, metadata);
    assert_eq!(from_exr.hfov_deg.to_bits(), report.hfov_deg.to_bits());
    let software = format!("photomontage {}", env!("CARGO_PKG_VERSION"));
    assert_eq!(a.software_name.as_ref().unwrap().to_string(), software);
    assert_eq!(a.owner.as_ref().unwrap().to_string(), software);
    assert!(
        a.comments
            .as_ref()
            .unwrap()
            .to_string()
            .contains("verified view V2")
    );
    // Standard attributes are single-precision floats.
    assert_eq!(a.latitude, Some(report.latitude_deg.unwrap() as f32));
    assert_eq!(a.longitude, Some(report.longitude_deg.unwrap() as f32));
    assert_eq!(a.altitude, Some(report.height_above_datum_m as f32));
    assert_eq!(a.horizontal_field_of_view, Some(report.hfov_deg as f32));
    assert_eq!(a.vertical_field_of_view, Some(report.vfov_deg as f32));
    // capDate is local time, utcOffset = UTC − local in seconds (OpenEXR standard attributes).
    let captured =
        chrono::DateTime::parse_from_rfc3339(report.capture_time.as_deref().unwrap()).unwrap();
    assert_eq!(
        a.capture_date.as_ref().unwrap().to_string(),
        captured.format("%Y:%m:%d %H:%M:%S").to_string()
    );
    assert_eq!(
        a.utc_offset,
        Some(-(captured.offset().local_minus_utc() as f32))
    );
    // The pixels are untouched.
    let read = exr::prelude::read_first_rgba_layer_from_file(
        &path,
        |size, _| vec![[0.0_f32; 4]; size.0 * size.1],
        |px: &mut Vec<[f32; 4]>, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            px[pos.1 * 16 + pos.0] = [r, g, b, a];
        },
    )
    .unwrap();
    assert_eq!(read.layer_data.channel_data.pixels, image.rgba);
}
