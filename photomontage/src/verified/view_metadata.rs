//! The view geometry an output image carries, in the three forms image files hold it:
//! - **EXIF** (CIPA DC-008-2016 "Exif 2.31"): the camera position as GPS latitude, longitude and
//!   altitude, the bearing as `GPSImgDirection` (true north), capture time with offset, the 35 mm
//!   equivalent as `FocalLengthIn35mmFilm`, `Software`, a one-line `ImageDescription` and the key
//!   numbers as JSON in `UserComment` ([`exif_ifds`], [`exif_block`]);
//! - **XMP** (ISO 16684-1:2019, Adobe *XMP Specification Part 2* for the `exif:`/`tiff:`
//!   properties): [`super::xmp::xmp_packet`];
//! - **OpenEXR header attributes** (OpenEXR "Standard Attributes": `owner`, `comments`,
//!   `capDate`, `utcOffset`, `longitude`, `latitude`, `altitude`, `software`,
//!   `horizontalFieldOfView`, `verticalFieldOfView`, plus `photomontage.view` with the JSON):
//!   [`exr_attributes`].
//!
//! All three are made from one [`ViewMetadata`], the report's key numbers, which is also what a
//! farm part carries so that a merged image is written exactly as the whole render.
//!
//! # Known limitations
//! `GPSAltitude` (and the EXR `altitude`) is the camera's survey height, which equals the height
//! above sea level only where the survey datum is sea level. EXIF rationals keep GPS angles to
//! 1e-4″ and the bearing and altitude to 1/1000; the JSON, the XMP and the EXR `photomontage.view`
//! keep every number exactly (shortest round-trip decimal).

use serde::{Deserialize, Serialize};

use super::geometry::{ViewGeometry, ViewProjection};
use super::tiff_ifd::{
    BYTE, Entry, MetadataIfds, UNDEFINED, ascii, bytes, rationals, shorts, tiff_bytes,
};

/// Name of the EXR header attribute (and of the JSON in EXIF `UserComment`) holding the view.
pub const EXR_VIEW_ATTRIBUTE: &str = "photomontage.view";

/// The report's key numbers, as an image carries them. Angles in degrees; `None` where the
/// report has none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ViewMetadata {
    pub photo_id: String,
    pub projection: ViewProjection,
    pub source_photos: Vec<String>,
    /// Projection centre [E, N, H] in the survey CRS.
    pub camera_position_m: [f64; 3],
    pub crs: Option<String>,
    pub latitude_deg: Option<f64>,
    pub longitude_deg: Option<f64>,
    pub height_above_datum_m: f64,
    pub height_above_ground_m: Option<f64>,
    pub bearing_true_deg: f64,
    pub bearing_grid_deg: f64,
    pub pitch_deg: f64,
    pub roll_deg: f64,
    pub hfov_deg: f64,
    pub vfov_deg: f64,
    pub focal_px: f64,
    pub focal_35mm_equiv_mm: f64,
    pub principal_point_px: [f64; 2],
    pub image_size_px: [u32; 2],
    /// RFC 3339 with offset.
    pub capture_time: Option<String>,
    pub sun_azimuth_deg: Option<f64>,
    pub sun_elevation_deg: Option<f64>,
    pub rms_px: f64,
    pub sigma_center_m: [f64; 3],
    /// Paper of the sheet the viewing distance is for (`A3`, ...).
    pub paper: String,
    pub printed_image_width_mm: f64,
    pub viewing_distance_mm: f64,
    /// `photomontage VERSION`.
    pub software: String,
}

/// `photomontage VERSION`.
#[must_use]
pub fn software_name() -> String {
    format!("photomontage {}", env!("CARGO_PKG_VERSION"))
}

impl From<&ViewGeometry> for ViewMetadata {
    fn from(r: &ViewGeometry) -> Self {
        Self {
            photo_id: r.photo_id.clone(),
            projection: r.projection,
            source_photos: r.source_photos.clone(),
            camera_position_m: r.camera_position_m,
            crs: r.crs.clone(),
            latitude_deg: r.latitude_deg,
            longitude_deg: r.longitude_deg,
            height_above_datum_m: r.height_above_datum_m,
            height_above_ground_m: r.height_above_ground_m,
            bearing_true_deg: r.bearing_true_deg,
            bearing_grid_deg: r.bearing_grid_deg,
            pitch_deg: r.pitch_deg,
            roll_deg: r.roll_deg,
            hfov_deg: r.hfov_deg,
            vfov_deg: r.vfov_deg,
            focal_px: r.focal_px,
            focal_35mm_equiv_mm: r.focal_35mm_equiv_mm,
            principal_point_px: r.principal_point_px,
            image_size_px: r.image_size_px,
            capture_time: r.capture_time.clone(),
            sun_azimuth_deg: r.sun_azimuth_deg,
            sun_elevation_deg: r.sun_elevation_deg,
            rms_px: r.rms_px,
            sigma_center_m: r.sigma_center_m,
            paper: r.paper.name().to_owned(),
            printed_image_width_mm: r.printed_image_width_mm,
            viewing_distance_mm: r.viewing_distance_mm,
            software: software_name(),
        }
    }
}

impl ViewMetadata {
    /// The JSON, ASCII only (other characters as `\uXXXX` escapes), so that it fits EXIF
    /// `UserComment` (ASCII) and an EXR text attribute (Latin-1).
    #[must_use]
    pub fn to_ascii_json(&self) -> String {
        let text = serde_json::to_string(self).unwrap_or_default();
        let mut out = String::with_capacity(text.len());
        for c in text.chars() {
            if c.is_ascii() {
                out.push(c);
            } else {
                let mut units = [0_u16; 2];
                for u in c.encode_utf16(&mut units) {
                    out.push_str(&format!("\\u{u:04x}"));
                }
            }
        }
        out
    }

    /// The one-line description (EXIF `ImageDescription`, EXR `comments`).
    #[must_use]
    pub fn description(&self) -> String {
        let what = match self.projection {
            ViewProjection::Photo => "verified view",
            ViewProjection::Planar => "verified planar view",
            ViewProjection::Cylindrical => "verified cylindrical view",
        };
        format!(
            "photomontage {what} {}: bearing {:.3} deg true, pitch {:.3} deg, roll {:.3} deg, \
             HFoV {:.3} deg, 35 mm equivalent {:.2} mm, viewing distance {:.1} mm ({})",
            self.photo_id,
            self.bearing_true_deg,
            self.pitch_deg,
            self.roll_deg,
            self.hfov_deg,
            self.focal_35mm_equiv_mm,
            self.viewing_distance_mm,
            self.paper
        )
    }

    /// The capture time parsed, when there is one.
    #[must_use]
    pub fn capture_time_parsed(&self) -> Option<chrono::DateTime<chrono::FixedOffset>> {
        self.capture_time
            .as_deref()
            .and_then(|t| chrono::DateTime::parse_from_rfc3339(t).ok())
    }
}

/// Degrees as degrees, minutes, seconds (seconds to 1e-4″ ≈ 3 mm).
fn dms(deg: f64) -> [f64; 3] {
    let a = deg.abs();
    let d = a.floor();
    let m = ((a - d) * 60.0).floor();
    [d, m, (a - d - m / 60.0) * 3600.0]
}

/// IFD0 (description, software), Exif and GPS IFD entries of a view.
#[must_use]
pub fn exif_ifds(m: &ViewMetadata) -> MetadataIfds {
    let mut comment = b"ASCII\0\0\0".to_vec();
    comment.extend(m.to_ascii_json().bytes());
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let f35 = m.focal_35mm_equiv_mm.round().clamp(0.0, 65535.0) as u16;
    let mut exif = vec![
        bytes(0x9286, UNDEFINED, &comment), // UserComment
        shorts(0xA405, &[f35]),             // FocalLengthIn35mmFilm
    ];
    if let Some(t) = m.capture_time_parsed() {
        exif.push(ascii(0x9003, &t.format("%Y:%m:%d %H:%M:%S").to_string()));
        exif.push(ascii(0x9011, &t.format("%:z").to_string()));
    }
    let mut gps = Vec::new();
    if let (Some(lat), Some(lon)) = (m.latitude_deg, m.longitude_deg) {
        let h = m.height_above_datum_m;
        gps.extend([
            bytes(0x0000, BYTE, &[2, 3, 0, 0]),
            ascii(0x0001, if lat >= 0.0 { "N" } else { "S" }),
            rationals(0x0002, &dms(lat), 10_000),
            ascii(0x0003, if lon >= 0.0 { "E" } else { "W" }),
            rationals(0x0004, &dms(lon), 10_000),
            bytes(0x0005, BYTE, &[u8::from(h < 0.0)]),
            rationals(0x0006, &[h], 1000),
            ascii(0x0010, "T"),
            rationals(0x0011, &[m.bearing_true_deg], 1000),
        ]);
    }
    let ifd0: Vec<Entry> = vec![ascii(0x010E, &m.description()), ascii(0x0131, &m.software)];
    MetadataIfds { ifd0, exif, gps }
}

/// The EXIF block (TIFF structure, little-endian, without the `Exif\0\0` prefix) of a view.
#[must_use]
pub fn exif_block(m: &ViewMetadata) -> Vec<u8> {
    tiff_bytes(&exif_ifds(m), None)
}

/// The view as OpenEXR layer attributes: the standard ones that apply and
/// [`EXR_VIEW_ATTRIBUTE`] with the JSON. Only one attribute goes into the `other` map (a hash
/// map), so the written header's bytes do not depend on its iteration order.
#[must_use]
pub fn exr_attributes(m: &ViewMetadata) -> exr::prelude::LayerAttributes {
    use exr::prelude::{AttributeValue, LayerAttributes, Text};
    let text = |s: &str| Text::new_or_none(s);
    let mut a = LayerAttributes {
        owner: text(&m.software),
        comments: text(&m.description()),
        software_name: text(&m.software),
        #[allow(clippy::cast_possible_truncation)]
        horizontal_field_of_view: Some(m.hfov_deg as f32),
        #[allow(clippy::cast_possible_truncation)]
        vertical_field_of_view: Some(m.vfov_deg as f32),
        ..LayerAttributes::default()
    };
    if let Some(t) = m.capture_time_parsed() {
        // OpenEXR: capDate is local time "YYYY:MM:DD hh:mm:ss", utcOffset = UTC − local, seconds.
        a.capture_date = text(&t.format("%Y:%m:%d %H:%M:%S").to_string());
        a.utc_offset = Some(-(t.offset().local_minus_utc() as f32));
    }
    if let (Some(lat), Some(lon)) = (m.latitude_deg, m.longitude_deg) {
        #[allow(clippy::cast_possible_truncation)]
        {
            a.latitude = Some(lat as f32);
            a.longitude = Some(lon as f32);
            a.altitude = Some(m.height_above_datum_m as f32);
        }
    }
    if let Some(json) = text(&m.to_ascii_json()) {
        a.other
            .insert(Text::from(EXR_VIEW_ATTRIBUTE), AttributeValue::Text(json));
    }
    a
}
