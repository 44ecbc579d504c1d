//! EXIF metadata a photomontage needs (CIPA DC-008 "Exif 2.3"): camera make and model, focal
//! length (actual and 35 mm equivalent), focal-plane resolution, the original date and time with
//! its offset, the GPS position and time, Mapillary's `MAPCaptureTime` (in `ImageDescription`)
//! and the orientation. Read with kamadak-exif. The capture time's order of precedence is
//! [`super::capture_time`]'s.
//!
//! The initial focal length in pixels is taken, in order of trust, from
//! 1. the focal-plane resolution (pixels per unit on the sensor), rescaled when the stored image
//!    is smaller than the size EXIF describes;
//! 2. the 35 mm equivalent focal length the camera states (diagonal of 43.27 mm), which
//!    accounts for crop modes and digital zoom;
//! 3. a sensor-width table for known camera models ([`super::sensor_table`], make and model
//!    matched robustly), for bodies that state neither.
//!
//! When none applies, [`focal_px_from_exif`] says exactly which tags are missing.
//!
//! # Known limitations
//! Maker notes are not read, so lenses that report no focal length give no estimate; the sensor
//! table holds only the sample data's bodies and a few common ones.

use exif::{In, Tag, Value};
use serde::Serialize;
use std::path::Path;

use super::PhotoError;

/// Diagonal of the 36 × 24 mm frame that "35 mm equivalent" focal lengths refer to.
pub const FULL_FRAME_DIAGONAL_MM: f64 = 43.266_615_305_567_87;

/// GPS position from EXIF (WGS 84 unless `GPSMapDatum` says otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GpsPosition {
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    pub altitude_m: Option<f64>,
}

/// The EXIF fields the studio uses; every field is optional.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ExifInfo {
    pub make: Option<String>,
    pub model: Option<String>,
    pub focal_length_mm: Option<f64>,
    pub focal_length_35mm: Option<f64>,
    /// Focal-plane resolution in pixels per millimetre (x, y).
    pub focal_plane_px_per_mm: Option<[f64; 2]>,
    /// Image size EXIF states (PixelXDimension × PixelYDimension), as stored (not rotated).
    pub exif_image_size_px: Option<[u32; 2]>,
    /// DateTimeOriginal as written (`YYYY:MM:DD HH:MM:SS`).
    pub date_time_original: Option<String>,
    /// OffsetTimeOriginal (`+HH:MM`), when present.
    pub offset_time_original: Option<String>,
    /// GPSDateStamp + GPSTimeStamp (UTC), when both are present and valid.
    pub gps_date_time_utc: Option<chrono::DateTime<chrono::FixedOffset>>,
    /// Mapillary `MAPCaptureTime` from the JSON in ImageDescription (UTC), when present.
    pub mapillary_capture_time: Option<chrono::DateTime<chrono::FixedOffset>>,
    pub gps: Option<GpsPosition>,
    /// Orientation tag 1–8 (1 when absent).
    pub orientation: u16,
}

impl ExifInfo {
    /// The capture time as RFC 3339 ([`ExifInfo::capture_time`]: `DateTimeOriginal` with its
    /// offset, else GPS time, else Mapillary `MAPCaptureTime`).
    #[must_use]
    pub fn taken_at_rfc3339(&self) -> Option<String> {
        self.capture_time().map(|c| c.time.to_rfc3339())
    }

    /// The original capture time: with its own offset (`OffsetTimeOriginal`) when EXIF has one,
    /// else read as local time in `zone` (daylight saving time applied); `None` without a
    /// `DateTimeOriginal` that parses, or without an offset and a zone.
    ///
    /// # Errors
    /// [`crate::time_zone::TimeZoneError`] when the local time is ambiguous or skipped in `zone`.
    pub fn taken_at_in_zone(
        &self,
        zone: Option<&crate::time_zone::SiteTimeZone>,
    ) -> Result<Option<chrono::DateTime<chrono::FixedOffset>>, crate::time_zone::TimeZoneError>
    {
        if let Some(text) = self.taken_at_rfc3339() {
            return Ok(chrono::DateTime::parse_from_rfc3339(&text).ok());
        }
        let (Some(dt), Some(zone)) = (self.date_time_original.as_ref(), zone) else {
            return Ok(None);
        };
        let Ok(naive) = chrono::NaiveDateTime::parse_from_str(dt.trim(), "%Y:%m:%d %H:%M:%S")
        else {
            return Ok(None);
        };
        zone.resolve(naive).map(Some)
    }

    /// `make model` for display.
    #[must_use]
    pub fn camera_name(&self) -> Option<String> {
        match (&self.make, &self.model) {
            (Some(make), Some(model)) if model.to_lowercase().starts_with(&make.to_lowercase()) => {
                Some(model.clone())
            }
            (Some(make), Some(model)) => Some(format!("{make} {model}")),
            (None, Some(model)) => Some(model.clone()),
            (Some(make), None) => Some(make.clone()),
            (None, None) => None,
        }
    }
}

fn ascii(exif: &exif::Exif, tag: Tag) -> Option<String> {
    let field = exif.get_field(tag, In::PRIMARY)?;
    match &field.value {
        Value::Ascii(parts) => {
            let bytes = parts.first()?;
            let s = String::from_utf8_lossy(bytes)
                .trim_matches(char::from(0))
                .trim()
                .to_string();
            (!s.is_empty()).then_some(s)
        }
        _ => None,
    }
}

fn number(exif: &exif::Exif, tag: Tag) -> Option<f64> {
    let field = exif.get_field(tag, In::PRIMARY)?;
    let v = match &field.value {
        Value::Rational(r) => r.first().map(exif::Rational::to_f64),
        Value::SRational(r) => r.first().map(exif::SRational::to_f64),
        Value::Short(s) => s.first().map(|v| f64::from(*v)),
        Value::Long(l) => l.first().map(|v| f64::from(*v)),
        _ => None,
    }?;
    v.is_finite().then_some(v)
}

fn dms(exif: &exif::Exif, tag: Tag) -> Option<f64> {
    let field = exif.get_field(tag, In::PRIMARY)?;
    match &field.value {
        Value::Rational(r) if r.len() == 3 => {
            Some(r[0].to_f64() + r[1].to_f64() / 60.0 + r[2].to_f64() / 3600.0)
        }
        _ => None,
    }
}

/// GPSDateStamp + GPSTimeStamp (three rationals), UTC.
fn gps_date_time(exif: &exif::Exif) -> Option<chrono::DateTime<chrono::FixedOffset>> {
    let date = ascii(exif, Tag::GPSDateStamp)?;
    let field = exif.get_field(Tag::GPSTimeStamp, In::PRIMARY)?;
    match &field.value {
        Value::Rational(r) if r.len() == 3 => {
            super::capture_time::gps_time(&date, [r[0].to_f64(), r[1].to_f64(), r[2].to_f64()])
        }
        _ => None,
    }
}

/// Reads the EXIF block of a photo.
///
/// # Errors
/// [`PhotoError::Missing`] when the file does not exist, [`PhotoError::Exif`] when there is no
/// readable EXIF (callers treat that as a warning, not a failure).
pub fn read_exif(path: &Path) -> Result<ExifInfo, PhotoError> {
    let file = std::fs::File::open(path).map_err(|_| PhotoError::Missing {
        path: path.to_path_buf(),
    })?;
    let mut reader = std::io::BufReader::new(file);
    let exif = exif::Reader::new()
        .read_from_container(&mut reader)
        .map_err(|e| PhotoError::Exif {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;

    // Focal-plane resolution: unit 2 = inch, 3 = cm, 4 = mm (Exif 2.3 §4.6.5).
    let unit_mm = match number(&exif, Tag::FocalPlaneResolutionUnit).map(|u| u as u32) {
        Some(3) => 10.0,
        Some(4) => 1.0,
        Some(5) => 0.001,
        _ => 25.4,
    };
    let focal_plane_px_per_mm = match (
        number(&exif, Tag::FocalPlaneXResolution),
        number(&exif, Tag::FocalPlaneYResolution),
    ) {
        (Some(x), Some(y)) if x > 0.0 && y > 0.0 => Some([x / unit_mm, y / unit_mm]),
        (Some(x), None) if x > 0.0 => Some([x / unit_mm, x / unit_mm]),
        _ => None,
    };
    let exif_image_size_px = match (
        number(&exif, Tag::PixelXDimension),
        number(&exif, Tag::PixelYDimension),
    ) {
        (Some(w), Some(h)) if w >= 1.0 && h >= 1.0 => Some([w as u32, h as u32]),
        _ => None,
    };
    let gps = match (dms(&exif, Tag::GPSLatitude), dms(&exif, Tag::GPSLongitude)) {
        (Some(lat), Some(lon)) => {
            let south = ascii(&exif, Tag::GPSLatitudeRef).is_some_and(|r| r.starts_with('S'));
            let west = ascii(&exif, Tag::GPSLongitudeRef).is_some_and(|r| r.starts_with('W'));
            let below = exif
                .get_field(Tag::GPSAltitudeRef, In::PRIMARY)
                .and_then(|f| f.value.get_uint(0))
                == Some(1);
            Some(GpsPosition {
                latitude_deg: if south { -lat } else { lat },
                longitude_deg: if west { -lon } else { lon },
                altitude_m: number(&exif, Tag::GPSAltitude).map(|a| if below { -a } else { a }),
            })
        }
        _ => None,
    };
    Ok(ExifInfo {
        make: ascii(&exif, Tag::Make),
        model: ascii(&exif, Tag::Model),
        focal_length_mm: number(&exif, Tag::FocalLength).filter(|f| *f > 0.0),
        focal_length_35mm: number(&exif, Tag::FocalLengthIn35mmFilm).filter(|f| *f > 0.0),
        focal_plane_px_per_mm,
        exif_image_size_px,
        date_time_original: ascii(&exif, Tag::DateTimeOriginal),
        offset_time_original: ascii(&exif, Tag::OffsetTimeOriginal),
        gps_date_time_utc: gps_date_time(&exif),
        mapillary_capture_time: ascii(&exif, Tag::ImageDescription)
            .as_deref()
            .and_then(super::capture_time::mapillary_capture_time),
        gps,
        orientation: exif
            .get_field(Tag::Orientation, In::PRIMARY)
            .and_then(|f| f.value.get_uint(0))
            .and_then(|o| u16::try_from(o).ok())
            .filter(|o| (1..=8).contains(o))
            .unwrap_or(1),
    })
}

/// Why EXIF gives no focal length in pixels, naming the missing tags (Exif 2.3 tag numbers).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FocalMissing {
    /// Neither focal-length tag is present.
    #[error("EXIF has no FocalLength (tag 0x920A) and no FocalLengthIn35mmFilm (tag 0xA405)")]
    NoFocalLength,
    /// The focal length in mm is given but nothing converts it to pixels.
    #[error(
        "EXIF gives FocalLength {focal_mm} mm but no sensor size: {focal_plane}, camera {camera} \
         is not in the sensor table, and FocalLengthIn35mmFilm (tag 0xA405) is absent"
    )]
    NoSensorSize {
        /// FocalLength as given.
        focal_mm: f64,
        /// What is wrong with FocalPlaneXResolution.
        focal_plane: String,
        /// `make model` as EXIF writes them, or "(no Make/Model)".
        camera: String,
    },
}

/// Sensor width range (mm) a focal-plane resolution must imply to be believed: from the
/// smallest phone sensors to medium format.
const PLAUSIBLE_SENSOR_WIDTH_MM: std::ops::RangeInclusive<f64> = 2.0..=60.0;

impl ExifInfo {
    /// Sensor width and height (mm, as stored): from the focal-plane resolution and the image
    /// size EXIF states when that is plausible, else from the sensor table.
    #[must_use]
    pub fn sensor_size_mm(&self) -> Option<[f64; 2]> {
        if let (Some(res), Some([w, h])) = (self.focal_plane_px_per_mm, self.exif_image_size_px) {
            let size = [f64::from(w) / res[0], f64::from(h) / res[1]];
            if PLAUSIBLE_SENSOR_WIDTH_MM.contains(&size[0].max(size[1])) {
                return Some(size);
            }
        }
        super::sensor_table::sensor_size_mm(self.make.as_deref(), self.model.as_deref())
    }

    /// The 35 mm-equivalent focal length (mm): EXIF's FocalLengthIn35mmFilm when given, else
    /// FocalLength × 43.27 mm / sensor diagonal (the diagonal convention of
    /// [`FULL_FRAME_DIAGONAL_MM`]).
    #[must_use]
    pub fn focal_35mm_equiv_mm(&self) -> Option<f64> {
        if let Some(f35) = self.focal_length_35mm {
            return Some(f35);
        }
        let f_mm = self.focal_length_mm?;
        let [w, h] = self.sensor_size_mm()?;
        Some(f_mm * FULL_FRAME_DIAGONAL_MM / w.hypot(h))
    }
}

/// The focal length in pixels for a photo of `image_size_px` (as displayed), as
/// [`initial_focal_px`] finds it.
///
/// # Errors
/// [`FocalMissing`] naming the missing EXIF tags.
pub fn focal_px_from_exif(
    exif: &ExifInfo,
    image_size_px: [u32; 2],
) -> Result<FocalEstimate, FocalMissing> {
    if let Some(estimate) = initial_focal_px(exif, image_size_px) {
        return Ok(estimate);
    }
    let Some(focal_mm) = exif.focal_length_mm else {
        return Err(FocalMissing::NoFocalLength);
    };
    let focal_plane = match (exif.focal_plane_px_per_mm, exif.exif_image_size_px) {
        (None, _) => "FocalPlaneXResolution (tag 0xA20E) is absent".to_owned(),
        (Some(res), size) => {
            let long = size.map_or(image_size_px[0].max(image_size_px[1]), |[w, h]| w.max(h));
            format!(
                "FocalPlaneXResolution {:.1} px/mm implies a {:.2} mm wide sensor for {long} px{}",
                res[0],
                f64::from(long) / res[0],
                if size.is_none() {
                    " (PixelXDimension, tag 0xA002, is absent, so the image may be a downscaled copy)"
                } else {
                    ""
                }
            )
        }
    };
    Err(FocalMissing::NoSensorSize {
        focal_mm,
        focal_plane,
        camera: exif
            .camera_name()
            .map_or_else(|| "(no Make/Model)".to_owned(), |c| format!("`{c}`")),
    })
}

/// Where an initial focal length came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FocalSource {
    FocalPlaneResolution,
    SensorTable,
    Equivalent35mm,
}

/// An initial focal length in pixels with its provenance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FocalEstimate {
    pub focal_px: f64,
    pub source: FocalSource,
}

/// The initial focal length in pixels for a photo of `image_size_px` (as displayed), or `None`
/// when EXIF gives nothing to go on.
#[must_use]
pub fn initial_focal_px(exif: &ExifInfo, image_size_px: [u32; 2]) -> Option<FocalEstimate> {
    let long_side = f64::from(image_size_px[0].max(image_size_px[1]));
    let short_side = f64::from(image_size_px[0].min(image_size_px[1]));
    if let (Some(f_mm), Some(res)) = (exif.focal_length_mm, exif.focal_plane_px_per_mm) {
        // The resolution refers to the size EXIF states; a downscaled copy scales it.
        let scale = exif
            .exif_image_size_px
            .map_or(1.0, |[w, h]| long_side / f64::from(w.max(h)));
        // Plausibility: the implied sensor must be 2–60 mm wide, else the tag is bogus.
        let sensor_mm = long_side / (res[0] * scale);
        if PLAUSIBLE_SENSOR_WIDTH_MM.contains(&sensor_mm) {
            return Some(FocalEstimate {
                focal_px: f_mm * res[0] * scale,
                source: FocalSource::FocalPlaneResolution,
            });
        }
    }
    // The camera's own 35 mm statement before the nominal sensor table: it accounts for crop
    // modes and digital zoom (the Panasonic FZ30 sample's tag is 17 % longer than its
    // FocalLength on the full nominal sensor).
    if let Some(f35) = exif.focal_length_35mm {
        return Some(FocalEstimate {
            focal_px: f35 * long_side.hypot(short_side) / FULL_FRAME_DIAGONAL_MM,
            source: FocalSource::Equivalent35mm,
        });
    }
    let (f_mm, [w_mm, h_mm]) = (
        exif.focal_length_mm?,
        super::sensor_table::sensor_size_mm(exif.make.as_deref(), exif.model.as_deref())?,
    );
    Some(FocalEstimate {
        focal_px: f_mm * long_side / w_mm.max(h_mm),
        source: FocalSource::SensorTable,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 50 mm lens on a full-frame 6000 × 4000 sensor (36 mm wide) is 8333.3 px.
    #[test]
    fn equivalent_35mm_full_frame_closed_form() {
        let exif = ExifInfo {
            focal_length_35mm: Some(50.0),
            ..ExifInfo::default()
        };
        let est = initial_focal_px(&exif, [6000, 4000]).unwrap();
        assert_eq!(est.source, FocalSource::Equivalent35mm);
        assert!(
            (est.focal_px - 50.0 / 36.0 * 6000.0).abs() < 1e-6,
            "{est:?}"
        );
    }

    #[test]
    fn focal_plane_resolution_rescales_to_stored_size() {
        // 8000 px/inch stated for a 2272-wide image, stored at 480 wide.
        let exif = ExifInfo {
            focal_length_mm: Some(21.3),
            focal_plane_px_per_mm: Some([8000.0 / 25.4, 8000.0 / 25.4]),
            exif_image_size_px: Some([2272, 1704]),
            ..ExifInfo::default()
        };
        let est = initial_focal_px(&exif, [480, 360]).unwrap();
        let expected = 21.3 * 8000.0 / 25.4 * 480.0 / 2272.0;
        assert!((est.focal_px - expected).abs() < 1e-9);
    }

    #[test]
    fn nothing_known_gives_none() {
        assert!(initial_focal_px(&ExifInfo::default(), [100, 100]).is_none());
    }

    #[test]
    fn rfc3339_needs_an_offset() {
        let mut exif = ExifInfo {
            date_time_original: Some("2008:05:30 15:56:01".into()),
            ..ExifInfo::default()
        };
        assert_eq!(exif.taken_at_rfc3339(), None);
        exif.offset_time_original = Some("+02:00".into());
        assert_eq!(
            exif.taken_at_rfc3339().as_deref(),
            Some("2008-05-30T15:56:01+02:00")
        );
    }

    #[test]
    fn offset_less_time_is_read_in_the_site_zone() {
        let zurich = crate::time_zone::SiteTimeZone::parse("Europe/Zurich").unwrap();
        let mut exif = ExifInfo {
            date_time_original: Some("2024:06:21 15:00:00".into()),
            ..ExifInfo::default()
        };
        assert_eq!(exif.taken_at_in_zone(None).unwrap(), None);
        let t = exif.taken_at_in_zone(Some(&zurich)).unwrap().unwrap();
        assert_eq!(t.to_utc().to_rfc3339(), "2024-06-21T13:00:00+00:00");
        // EXIF's own offset wins over the zone.
        exif.offset_time_original = Some("+05:00".into());
        let t = exif.taken_at_in_zone(Some(&zurich)).unwrap().unwrap();
        assert_eq!(t.to_utc().to_rfc3339(), "2024-06-21T10:00:00+00:00");
        // The skipped spring-forward hour is an error, not a guess.
        exif.offset_time_original = None;
        exif.date_time_original = Some("2024:03:31 02:30:00".into());
        assert!(exif.taken_at_in_zone(Some(&zurich)).is_err());
    }

    #[test]
    fn missing_tags_are_named() {
        assert_eq!(
            focal_px_from_exif(&ExifInfo::default(), [100, 100]),
            Err(FocalMissing::NoFocalLength)
        );
        let unknown = ExifInfo {
            make: Some("ACME".into()),
            model: Some("Cam 1".into()),
            focal_length_mm: Some(7.0),
            ..ExifInfo::default()
        };
        let e = focal_px_from_exif(&unknown, [100, 100])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("FocalPlaneXResolution (tag 0xA20E) is absent"),
            "{e}"
        );
        assert!(e.contains("`ACME Cam 1`") && e.contains("0xA405"), "{e}");
        // A focal-plane resolution implying a 0.25 mm sensor is named with its numbers.
        let bogus = ExifInfo {
            focal_plane_px_per_mm: Some([400.0, 400.0]),
            ..unknown
        };
        let e = focal_px_from_exif(&bogus, [100, 60])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("0.25 mm wide sensor") && e.contains("0xA002"),
            "{e}"
        );
    }

    #[test]
    fn equivalent_35mm_from_the_sensor_diagonal() {
        // 50 mm on a 36 × 24 mm sensor is 50 mm equivalent; the tag wins when present.
        let mut exif = ExifInfo {
            focal_length_mm: Some(50.0),
            focal_plane_px_per_mm: Some([100.0, 100.0]),
            exif_image_size_px: Some([3600, 2400]),
            ..ExifInfo::default()
        };
        let eq = exif.focal_35mm_equiv_mm().unwrap();
        assert!((eq - 50.0).abs() < 1e-9, "{eq}");
        exif.focal_length_35mm = Some(52.0);
        assert_eq!(exif.focal_35mm_equiv_mm(), Some(52.0));
    }
}
