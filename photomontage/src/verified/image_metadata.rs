//! The view geometry written into an output image's EXIF (CIPA DC-008-2016 "Exif 2.31": TIFF
//! structure, Exif and GPS IFDs), so a montage file carries its camera and view: the camera
//! position as GPS latitude, longitude and altitude, the bearing as `GPSImgDirection` (true
//! north), capture time with offset, the 35 mm-equivalent focal length, `Software`, a one-line
//! `ImageDescription` and the report's key numbers as JSON in `UserComment`.
//!
//! JPEG and PNG are written through the `image` crate's encoders with this block
//! ([`write_8bit_with_exif`]); the block itself is little-endian TIFF built here.
//!
//! # Known limitations
//! Not yet for TIFF output (the `image` crate's TIFF encoder takes no EXIF) or EXR attributes;
//! no XMP packet. `GPSAltitude` is the camera's survey height, which equals the height above sea
//! level only where the survey datum is sea level.

use std::path::Path;

use image::ImageEncoder;
use serde::Serialize;

use super::geometry::ViewGeometry;

/// What can go wrong writing an image with metadata.
#[derive(Debug, thiserror::Error)]
pub enum ImageMetadataError {
    #[error("{path}: only .jpg/.jpeg and .png carry the view's EXIF here")]
    UnsupportedFormat { path: String },
    #[error("cannot write {path}: {message}")]
    Write { path: String, message: String },
}

/// The report's key numbers, as `UserComment` JSON.
#[derive(Debug, Serialize)]
struct ViewSummary<'a> {
    photo_id: &'a str,
    camera_position_m: [f64; 3],
    crs: Option<&'a str>,
    bearing_true_deg: f64,
    bearing_grid_deg: f64,
    pitch_deg: f64,
    roll_deg: f64,
    hfov_deg: f64,
    vfov_deg: f64,
    focal_px: f64,
    focal_35mm_equiv_mm: f64,
    principal_point_px: [f64; 2],
    height_above_ground_m: Option<f64>,
    viewing_distance_mm: f64,
}

/// One IFD entry: tag, type, count and the value bytes (little-endian).
#[derive(Clone)]
struct Entry {
    tag: u16,
    kind: u16,
    count: u32,
    bytes: Vec<u8>,
}

const ASCII: u16 = 2;
const SHORT: u16 = 3;
const LONG: u16 = 4;
const RATIONAL: u16 = 5;
const BYTE: u16 = 1;
const UNDEFINED: u16 = 7;

fn ascii(tag: u16, text: &str) -> Entry {
    let mut bytes: Vec<u8> = text.bytes().filter(u8::is_ascii).collect();
    bytes.push(0);
    Entry {
        tag,
        kind: ASCII,
        count: u32::try_from(bytes.len()).unwrap_or(u32::MAX),
        bytes,
    }
}

fn rationals(tag: u16, values: &[f64], denominator: u32) -> Entry {
    let mut bytes = Vec::new();
    for v in values {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let n = (v.abs() * f64::from(denominator))
            .round()
            .min(f64::from(u32::MAX)) as u32;
        bytes.extend(n.to_le_bytes());
        bytes.extend(denominator.to_le_bytes());
    }
    Entry {
        tag,
        kind: RATIONAL,
        count: u32::try_from(values.len()).unwrap_or(u32::MAX),
        bytes,
    }
}

/// Degrees as degrees, minutes, seconds (seconds to 1e-4″ ≈ 3 mm).
fn dms(deg: f64) -> [f64; 3] {
    let a = deg.abs();
    let d = a.floor();
    let m = ((a - d) * 60.0).floor();
    [d, m, (a - d - m / 60.0) * 3600.0]
}

/// Appends one IFD (entries sorted by tag, values longer than 4 bytes after it) to `out`.
fn write_ifd(out: &mut Vec<u8>, entries: &mut [Entry], next_ifd: u32) {
    entries.sort_by_key(|e| e.tag);
    let start = out.len();
    let count = u16::try_from(entries.len()).unwrap_or(u16::MAX);
    let data_start = start + 2 + 12 * entries.len() + 4;
    let mut data: Vec<u8> = Vec::new();
    out.extend(count.to_le_bytes());
    for e in entries.iter() {
        out.extend(e.tag.to_le_bytes());
        out.extend(e.kind.to_le_bytes());
        out.extend(e.count.to_le_bytes());
        if e.bytes.len() <= 4 {
            let mut v = e.bytes.clone();
            v.resize(4, 0);
            out.extend(v);
        } else {
            let offset = u32::try_from(data_start + data.len()).unwrap_or(u32::MAX);
            out.extend(offset.to_le_bytes());
            data.extend(&e.bytes);
            if data.len() % 2 == 1 {
                data.push(0); // word alignment
            }
        }
    }
    out.extend(next_ifd.to_le_bytes());
    out.extend(data);
}

fn long(tag: u16, v: u32) -> Entry {
    Entry {
        tag,
        kind: LONG,
        count: 1,
        bytes: v.to_le_bytes().to_vec(),
    }
}

/// The EXIF block (TIFF structure, little-endian, without the `Exif\0\0` prefix) of a view.
#[must_use]
pub fn exif_block(r: &ViewGeometry) -> Vec<u8> {
    let summary = ViewSummary {
        photo_id: &r.photo_id,
        camera_position_m: r.camera_position_m,
        crs: r.crs.as_deref(),
        bearing_true_deg: r.bearing_true_deg,
        bearing_grid_deg: r.bearing_grid_deg,
        pitch_deg: r.pitch_deg,
        roll_deg: r.roll_deg,
        hfov_deg: r.hfov_deg,
        vfov_deg: r.vfov_deg,
        focal_px: r.focal_px,
        focal_35mm_equiv_mm: r.focal_35mm_equiv_mm,
        principal_point_px: r.principal_point_px,
        height_above_ground_m: r.height_above_ground_m,
        viewing_distance_mm: r.viewing_distance_mm,
    };
    let json = serde_json::to_string(&summary).unwrap_or_default();
    let mut comment = b"ASCII\0\0\0".to_vec();
    comment.extend(json.bytes());
    let mut exif = vec![
        Entry {
            tag: 0x9286, // UserComment
            kind: UNDEFINED,
            count: u32::try_from(comment.len()).unwrap_or(u32::MAX),
            bytes: comment,
        },
        Entry {
            tag: 0xA405, // FocalLengthIn35mmFilm
            kind: SHORT,
            count: 1,
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            bytes: (r.focal_35mm_equiv_mm.round().clamp(0.0, 65535.0) as u16)
                .to_le_bytes()
                .to_vec(),
        },
    ];
    if let Some(t) = r
        .capture_time
        .as_deref()
        .and_then(|t| chrono::DateTime::parse_from_rfc3339(t).ok())
    {
        exif.push(ascii(0x9003, &t.format("%Y:%m:%d %H:%M:%S").to_string()));
        exif.push(ascii(0x9011, &t.format("%:z").to_string()));
    }
    let mut gps = Vec::new();
    if let (Some(lat), Some(lon)) = (r.latitude_deg, r.longitude_deg) {
        gps.push(Entry {
            tag: 0x0000,
            kind: BYTE,
            count: 4,
            bytes: vec![2, 3, 0, 0],
        });
        gps.push(ascii(0x0001, if lat >= 0.0 { "N" } else { "S" }));
        gps.push(rationals(0x0002, &dms(lat), 10_000));
        gps.push(ascii(0x0003, if lon >= 0.0 { "E" } else { "W" }));
        gps.push(rationals(0x0004, &dms(lon), 10_000));
        let h = r.height_above_datum_m;
        gps.push(Entry {
            tag: 0x0005,
            kind: BYTE,
            count: 1,
            bytes: vec![u8::from(h < 0.0)],
        });
        gps.push(rationals(0x0006, &[h], 1000));
        gps.push(ascii(0x0010, "T"));
        gps.push(rationals(0x0011, &[r.bearing_true_deg], 1000));
    }
    let description = format!(
        "photomontage verified view {}: bearing {:.3} deg true, pitch {:.3} deg, roll {:.3} deg, \
         HFoV {:.3} deg, 35 mm equivalent {:.2} mm, viewing distance {:.1} mm ({})",
        r.photo_id,
        r.bearing_true_deg,
        r.pitch_deg,
        r.roll_deg,
        r.hfov_deg,
        r.focal_35mm_equiv_mm,
        r.viewing_distance_mm,
        r.paper.name()
    );
    // Layout: header (8) | IFD0 | Exif IFD | GPS IFD; pointers patched in a second pass.
    let build = |exif_at: u32, gps_at: u32| -> (Vec<u8>, u32, u32) {
        let mut ifd0 = vec![
            ascii(0x010E, &description),
            ascii(
                0x0131,
                &format!("photomontage {}", env!("CARGO_PKG_VERSION")),
            ),
            long(0x8769, exif_at),
        ];
        if !gps.is_empty() {
            ifd0.push(long(0x8825, gps_at));
        }
        let mut out = b"II\x2a\x00\x08\x00\x00\x00".to_vec();
        write_ifd(&mut out, &mut ifd0, 0);
        let exif_pos = u32::try_from(out.len()).unwrap_or(u32::MAX);
        write_ifd(&mut out, &mut exif.clone(), 0);
        let gps_pos = u32::try_from(out.len()).unwrap_or(u32::MAX);
        if !gps.is_empty() {
            write_ifd(&mut out, &mut gps.clone(), 0);
        }
        (out, exif_pos, gps_pos)
    };
    // The IFD sizes do not depend on the pointer values: the first pass finds the offsets.
    let (_, exif_at, gps_at) = build(0, 0);
    build(exif_at, gps_at).0
}

/// The EXIF block of `photo_id`'s view geometry (default options).
///
/// # Errors
/// Any [`super::ViewGeometryError`] (an unsolved photo, ...).
pub fn view_exif(
    doc: &crate::site::SiteDocument,
    photo_id: &str,
) -> Result<Vec<u8>, super::ViewGeometryError> {
    super::view_geometry(doc, photo_id, &super::ViewGeometryOptions::default())
        .map(|r| exif_block(&r))
}

/// Writes a render as [`crate::render::output::write_output`] does, except that JPEG and PNG
/// carry `exif` when it is given (the view geometry: see [`view_exif`]).
///
/// # Errors
/// [`ImageMetadataError::Write`].
pub fn write_render(
    path: &Path,
    image: &crate::render::RenderedImage,
    layers: &crate::render::OutputLayers,
    tone_map: &crate::colour::ToneMap,
    exif: Option<Vec<u8>>,
) -> Result<(), ImageMetadataError> {
    use crate::render::output::{JPEG_QUALITY, OutputFormat, write_output};
    let fail = |message: String| ImageMetadataError::Write {
        path: path.display().to_string(),
        message,
    };
    let format = OutputFormat::from_path(path).map_err(|e| fail(e.to_string()))?;
    match (format, exif) {
        (OutputFormat::Jpeg | OutputFormat::Png, Some(exif)) => {
            let [w, h] = image.size_px;
            let rgb = image::RgbImage::from_fn(w, h, |x, y| {
                let p = image.rgba[(y * w + x) as usize];
                image::Rgb(crate::colour::encode_srgb8([p[0], p[1], p[2]], tone_map))
            });
            write_8bit_with_exif(path, &rgb, exif, JPEG_QUALITY)
        }
        _ => write_output(path, image, layers, tone_map)
            .map(|_| ())
            .map_err(|e| fail(e.to_string())),
    }
}

/// Writes `rgb` as JPEG (`quality`) or PNG (by the extension of `path`) with `exif` embedded,
/// through a temporary file and a rename.
///
/// # Errors
/// [`ImageMetadataError::UnsupportedFormat`] for other extensions, [`ImageMetadataError::Write`].
pub fn write_8bit_with_exif(
    path: &Path,
    rgb: &image::RgbImage,
    exif: Vec<u8>,
    quality: u8,
) -> Result<(), ImageMetadataError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let fail = |message: String| ImageMetadataError::Write {
        path: path.display().to_string(),
        message,
    };
    let mut bytes = Vec::new();
    let (w, h) = rgb.dimensions();
    match ext.as_deref() {
        Some("jpg" | "jpeg") => {
            let mut enc = image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, quality);
            enc.set_exif_metadata(exif)
                .map_err(|e| fail(e.to_string()))?;
            enc.write_image(rgb.as_raw(), w, h, image::ExtendedColorType::Rgb8)
                .map_err(|e| fail(e.to_string()))?;
        }
        Some("png") => {
            let mut enc = image::codecs::png::PngEncoder::new(&mut bytes);
            enc.set_exif_metadata(exif)
                .map_err(|e| fail(e.to_string()))?;
            enc.write_image(rgb.as_raw(), w, h, image::ExtendedColorType::Rgb8)
                .map_err(|e| fail(e.to_string()))?;
        }
        _ => {
            return Err(ImageMetadataError::UnsupportedFormat {
                path: path.display().to_string(),
            });
        }
    }
    crate::site::write_atomically(path, &bytes).map_err(|e| fail(e.to_string()))
}
