//! The view geometry as an XMP packet (ISO 16684-1:2019 "XMP data model and serialization";
//! Adobe, *XMP Specification Part 2: Additional properties*, 2016, §3 for the `tiff:` and `exif:`
//! namespaces) and where each file format puts it (*XMP Specification Part 3: Storage in files*,
//! 2016): JPEG APP1 with the `http://ns.adobe.com/xap/1.0/\0` signature (§1.1.3), PNG `iTXt`
//! with keyword `XML:com.adobe.xmp`, uncompressed (§1.1.5), TIFF tag 700 (§1.1.4, written by
//! [`super::tiff_ifd`]).
//!
//! Standard properties where they exist: `tiff:ImageWidth`/`ImageLength`, `xmp:CreatorTool`,
//! `exif:FocalLengthIn35mmFilm`, `exif:DateTimeOriginal`, `exif:GPSVersionID`,
//! `exif:GPSLatitude`/`GPSLongitude` (`DDD,MM.mmmmmmmmk`), `exif:GPSAltitude` and `Ref`,
//! `exif:GPSImgDirection` and `Ref`. Every number of [`ViewMetadata`] is also given in the
//! `photomontage:` namespace ([`NAMESPACE`]) under its JSON name, as the shortest decimal that
//! reads back to the same `f64`; arrays are `rdf:Seq`.
//!
//! # Known limitations
//! A JPEG APP1 segment holds at most 65 502 bytes of packet (no extended XMP); the packet here
//! holds about 40 properties (a few kilobytes). No padding is reserved for in-place editing.

use std::fmt::Write as _;

use super::view_metadata::ViewMetadata;

/// The `photomontage:` namespace URI.
pub const NAMESPACE: &str = "urn:photomontage:view:1.0/";
/// Signature that starts a JPEG APP1 XMP segment.
pub const JPEG_XMP_SIGNATURE: &[u8] = b"http://ns.adobe.com/xap/1.0/\0";
/// Keyword of the PNG iTXt chunk holding XMP.
pub const PNG_XMP_KEYWORD: &str = "XML:com.adobe.xmp";

/// What can go wrong placing a packet into a file.
#[derive(Debug, thiserror::Error)]
pub enum XmpError {
    #[error("the XMP packet ({len} bytes) does not fit one JPEG APP1 segment")]
    TooLarge { len: usize },
    #[error("not a {format} stream: {reason}")]
    Malformed {
        format: &'static str,
        reason: String,
    },
}

fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// `DDD,MM.mmmmmmmmk` (XMP Part 2 "GPSCoordinate"); 1e-8′ ≈ 2e-5 m.
fn gps_coordinate(deg: f64, positive: char, negative: char) -> String {
    let a = deg.abs();
    let d = a.floor();
    let minutes = (a - d) * 60.0;
    let hemisphere = if deg >= 0.0 { positive } else { negative };
    format!("{d:.0},{minutes:.8}{hemisphere}")
}

/// The XMP packet of a view (UTF-8, with the `<?xpacket?>` wrapper).
#[must_use]
pub fn xmp_packet(m: &ViewMetadata) -> String {
    let mut attrs: Vec<(String, String)> = vec![
        ("tiff:ImageWidth".into(), m.image_size_px[0].to_string()),
        ("tiff:ImageLength".into(), m.image_size_px[1].to_string()),
        ("xmp:CreatorTool".into(), m.software.clone()),
        (
            "exif:FocalLengthIn35mmFilm".into(),
            format!("{:.0}", m.focal_35mm_equiv_mm.round().max(0.0)),
        ),
    ];
    if let Some(t) = &m.capture_time {
        attrs.push(("exif:DateTimeOriginal".into(), t.clone()));
    }
    if let (Some(lat), Some(lon)) = (m.latitude_deg, m.longitude_deg) {
        let h = m.height_above_datum_m;
        attrs.extend([
            ("exif:GPSVersionID".into(), "2.3.0.0".into()),
            ("exif:GPSLatitude".into(), gps_coordinate(lat, 'N', 'S')),
            ("exif:GPSLongitude".into(), gps_coordinate(lon, 'E', 'W')),
            ("exif:GPSAltitudeRef".into(), u8::from(h < 0.0).to_string()),
            (
                "exif:GPSAltitude".into(),
                format!("{:.0}/1000", (h.abs() * 1000.0).round()),
            ),
            ("exif:GPSImgDirectionRef".into(), "T".into()),
            (
                "exif:GPSImgDirection".into(),
                format!("{:.0}/1000", (m.bearing_true_deg * 1000.0).round()),
            ),
        ]);
    }
    let mut simple = |name: &str, value: String| {
        attrs.push((format!("photomontage:{name}"), value));
    };
    simple("photo_id", m.photo_id.clone());
    simple(
        "projection",
        serde_json::to_value(m.projection)
            .ok()
            .and_then(|v| v.as_str().map(str::to_owned))
            .unwrap_or_default(),
    );
    if let Some(crs) = &m.crs {
        simple("crs", crs.clone());
    }
    let numbers: [(&str, Option<f64>); 19] = [
        ("latitude_deg", m.latitude_deg),
        ("longitude_deg", m.longitude_deg),
        ("height_above_datum_m", Some(m.height_above_datum_m)),
        ("height_above_ground_m", m.height_above_ground_m),
        ("bearing_true_deg", Some(m.bearing_true_deg)),
        ("bearing_grid_deg", Some(m.bearing_grid_deg)),
        ("pitch_deg", Some(m.pitch_deg)),
        ("roll_deg", Some(m.roll_deg)),
        ("hfov_deg", Some(m.hfov_deg)),
        ("vfov_deg", Some(m.vfov_deg)),
        ("focal_px", Some(m.focal_px)),
        ("focal_35mm_equiv_mm", Some(m.focal_35mm_equiv_mm)),
        ("sun_azimuth_deg", m.sun_azimuth_deg),
        ("sun_elevation_deg", m.sun_elevation_deg),
        ("rms_px", Some(m.rms_px)),
        ("printed_image_width_mm", Some(m.printed_image_width_mm)),
        ("viewing_distance_mm", Some(m.viewing_distance_mm)),
        ("image_width_px", Some(f64::from(m.image_size_px[0]))),
        ("image_height_px", Some(f64::from(m.image_size_px[1]))),
    ];
    for (name, value) in numbers {
        if let Some(v) = value {
            simple(name, format!("{v:?}"));
        }
    }
    if let Some(t) = &m.capture_time {
        simple("capture_time", t.clone());
    }
    simple("paper", m.paper.clone());

    let mut x = String::new();
    x.push_str("<?xpacket begin=\"\u{feff}\" id=\"W5M0MpCehiHzreSzNTczkc9d\"?>\n");
    x.push_str("<x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n");
    x.push_str(" <rdf:RDF xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n");
    x.push_str("  <rdf:Description rdf:about=\"\"\n");
    x.push_str("    xmlns:tiff=\"http://ns.adobe.com/tiff/1.0/\"\n");
    x.push_str("    xmlns:exif=\"http://ns.adobe.com/exif/1.0/\"\n");
    x.push_str("    xmlns:xmp=\"http://ns.adobe.com/xap/1.0/\"\n");
    let _ = write!(x, "    xmlns:photomontage=\"{NAMESPACE}\"");
    for (name, value) in &attrs {
        let _ = write!(x, "\n    {name}=\"{}\"", escape(value));
    }
    x.push_str(">\n");
    let seqs: [(&str, Vec<String>); 4] = [
        (
            "camera_position_m",
            m.camera_position_m
                .iter()
                .map(|v| format!("{v:?}"))
                .collect(),
        ),
        (
            "sigma_center_m",
            m.sigma_center_m.iter().map(|v| format!("{v:?}")).collect(),
        ),
        (
            "principal_point_px",
            m.principal_point_px
                .iter()
                .map(|v| format!("{v:?}"))
                .collect(),
        ),
        ("source_photos", m.source_photos.clone()),
    ];
    for (name, items) in seqs {
        let _ = writeln!(x, "   <photomontage:{name}>\n    <rdf:Seq>");
        for item in items {
            let _ = writeln!(x, "     <rdf:li>{}</rdf:li>", escape(&item));
        }
        let _ = writeln!(x, "    </rdf:Seq>\n   </photomontage:{name}>");
    }
    x.push_str("  </rdf:Description>\n </rdf:RDF>\n</x:xmpmeta>\n<?xpacket end=\"r\"?>");
    x
}

/// Inserts an APP1 XMP segment into a JPEG stream, after the APPn segments at its start (so
/// after JFIF APP0 and the EXIF APP1, as XMP Part 3 §1.1.3 asks).
///
/// # Errors
/// [`XmpError::Malformed`] when `jpeg` does not start with SOI, [`XmpError::TooLarge`].
pub fn insert_into_jpeg(jpeg: &[u8], packet: &str) -> Result<Vec<u8>, XmpError> {
    let malformed = |reason: &str| XmpError::Malformed {
        format: "JPEG",
        reason: reason.to_owned(),
    };
    if jpeg.get(..2) != Some(&[0xFF, 0xD8]) {
        return Err(malformed("no SOI marker"));
    }
    let payload_len = JPEG_XMP_SIGNATURE.len() + packet.len();
    let segment_len =
        u16::try_from(payload_len + 2).map_err(|_| XmpError::TooLarge { len: packet.len() })?;
    // Walk the APPn segments (0xFFE0..=0xFFEF) that follow SOI.
    let mut at = 2;
    while let Some(&[0xFF, marker, hi, lo]) = jpeg.get(at..at + 4) {
        if !(0xE0..=0xEF).contains(&marker) {
            break;
        }
        at += 2 + usize::from(u16::from_be_bytes([hi, lo]));
    }
    if at > jpeg.len() {
        return Err(malformed("an APP segment runs past the end"));
    }
    let mut out = Vec::with_capacity(jpeg.len() + payload_len + 4);
    out.extend_from_slice(&jpeg[..at]);
    out.extend_from_slice(&[0xFF, 0xE1]);
    out.extend_from_slice(&segment_len.to_be_bytes());
    out.extend_from_slice(JPEG_XMP_SIGNATURE);
    out.extend_from_slice(packet.as_bytes());
    out.extend_from_slice(&jpeg[at..]);
    Ok(out)
}

/// CRC-32 of PNG chunks (ISO/IEC 15948 Annex D: polynomial 0xEDB88320, reflected).
fn crc32(parts: &[&[u8]]) -> u32 {
    let mut crc = 0xFFFF_FFFF_u32;
    for part in parts {
        for &b in *part {
            crc ^= u32::from(b);
            for _ in 0..8 {
                let mask = (crc & 1).wrapping_neg();
                crc = (crc >> 1) ^ (0xEDB8_8320 & mask);
            }
        }
    }
    !crc
}

/// Inserts an uncompressed `iTXt` chunk with keyword [`PNG_XMP_KEYWORD`] into a PNG stream,
/// right after `IHDR`.
///
/// # Errors
/// [`XmpError::Malformed`] when `png` does not start with the signature and `IHDR`.
pub fn insert_into_png(png: &[u8], packet: &str) -> Result<Vec<u8>, XmpError> {
    const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
    let malformed = |reason: &str| XmpError::Malformed {
        format: "PNG",
        reason: reason.to_owned(),
    };
    if png.get(..8) != Some(SIGNATURE) || png.get(12..16) != Some(b"IHDR") {
        return Err(malformed("no signature and IHDR"));
    }
    let ihdr_len = png
        .get(8..12)
        .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as usize)
        .ok_or_else(|| malformed("short IHDR"))?;
    let after_ihdr = 8 + 12 + ihdr_len;
    if after_ihdr > png.len() {
        return Err(malformed("IHDR runs past the end"));
    }
    // keyword NUL, compression flag 0, method 0, language "" NUL, translated keyword "" NUL, text.
    let mut data = PNG_XMP_KEYWORD.as_bytes().to_vec();
    data.extend_from_slice(&[0, 0, 0, 0, 0]);
    data.extend_from_slice(packet.as_bytes());
    let len = u32::try_from(data.len()).map_err(|_| XmpError::TooLarge { len: packet.len() })?;
    let mut out = Vec::with_capacity(png.len() + data.len() + 12);
    out.extend_from_slice(&png[..after_ihdr]);
    out.extend_from_slice(&len.to_be_bytes());
    out.extend_from_slice(b"iTXt");
    out.extend_from_slice(&data);
    out.extend_from_slice(&crc32(&[b"iTXt", &data]).to_be_bytes());
    out.extend_from_slice(&png[after_ihdr..]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_of_the_png_iend_chunk_is_the_published_one() {
        // Every PNG ends with IEND, length 0, CRC AE 42 60 82.
        assert_eq!(crc32(&[b"IEND"]), 0xAE42_6082);
    }

    #[test]
    fn gps_coordinates_follow_the_xmp_format() {
        assert_eq!(gps_coordinate(47.5, 'N', 'S'), "47,30.00000000N");
        assert_eq!(gps_coordinate(-8.25, 'E', 'W'), "8,15.00000000W");
    }
}
