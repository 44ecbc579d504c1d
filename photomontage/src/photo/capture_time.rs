//! The capture time of a photo, from the three places a photo carries it, in this order:
//!
//! 1. **EXIF `DateTimeOriginal` with `OffsetTimeOriginal`** (CIPA DC-008 Exif 2.31 §4.6.5, tags
//!    0x9003 and 0x9011): the camera's own statement of when the shutter fired, in local time
//!    with its UTC offset. Without the offset the local time is ambiguous and is not used.
//! 2. **EXIF GPS `GPSDateStamp` + `GPSTimeStamp`** (tags 0x001D and 0x0007): UTC from the
//!    satellites. Second to the camera's statement because some cameras write the time of the
//!    last fix rather than of the exposure.
//! 3. **Mapillary `MAPCaptureTime`**: the JSON object the Mapillary apps and `mapillary_tools`
//!    write into EXIF `ImageDescription` (tag 0x010E), `"MAPCaptureTime":
//!    "YYYY_MM_DD_HH_MM_SS_mmm"`, in **UTC** (`mapillary_tools` formats it from
//!    `datetime.utcfromtimestamp`; Mapillary's API gives `captured_at` as a UTC epoch). The
//!    `MAPLocalTimeZone` the early phone apps wrote beside it (iOS app 1.8, 2014: `"Europe/Berlin
//!    (GMT+2) offset 7200 (Daylight)"`) records the phone's zone and is not applied.
//!
//! The result says which reading it came from, so a report can name it.
//!
//! # Known limitations
//! Mapillary JSON is read from `ImageDescription` only, not from XMP packets or the
//! `mapillary_image_description.json` sidecar of newer `mapillary_tools` uploads. A
//! `DateTimeOriginal` without an offset is not combined with a time zone guessed from the GPS
//! position. Sub-second tags (`SubSecTimeOriginal`) are not read.

use chrono::{DateTime, FixedOffset, NaiveDate, NaiveDateTime, NaiveTime, TimeZone, Utc};
use serde::Serialize;

use super::ExifInfo;

/// Where a capture time came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CaptureTimeSource {
    /// `DateTimeOriginal` + `OffsetTimeOriginal`.
    ExifOriginal,
    /// `GPSDateStamp` + `GPSTimeStamp` (UTC).
    GpsTime,
    /// Mapillary `MAPCaptureTime` in `ImageDescription` (UTC).
    MapillaryCaptureTime,
}

impl CaptureTimeSource {
    /// How a report names it.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Self::ExifOriginal => "EXIF DateTimeOriginal + OffsetTimeOriginal",
            Self::GpsTime => "EXIF GPS date/time (UTC)",
            Self::MapillaryCaptureTime => "Mapillary MAPCaptureTime (UTC)",
        }
    }
}

/// A capture time and where it came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct CaptureTime {
    /// The time with its offset (UTC for GPS and Mapillary).
    pub time: DateTime<FixedOffset>,
    /// Which reading gave it.
    pub source: CaptureTimeSource,
}

/// `DateTimeOriginal` (`YYYY:MM:DD HH:MM:SS`) with `OffsetTimeOriginal` (`±HH:MM`).
#[must_use]
pub fn exif_original(date_time: &str, offset: &str) -> Option<DateTime<FixedOffset>> {
    let naive = NaiveDateTime::parse_from_str(date_time.trim(), "%Y:%m:%d %H:%M:%S").ok()?;
    let text = format!("{}{}", naive.format("%Y-%m-%dT%H:%M:%S"), offset.trim());
    DateTime::parse_from_rfc3339(&text).ok()
}

/// `GPSDateStamp` (`YYYY:MM:DD`) and `GPSTimeStamp` (hours, minutes, seconds as rationals), UTC.
#[must_use]
pub fn gps_time(date_stamp: &str, hms: [f64; 3]) -> Option<DateTime<FixedOffset>> {
    let date = NaiveDate::parse_from_str(date_stamp.trim(), "%Y:%m:%d").ok()?;
    let [h, m, s] = hms;
    if !(hms.iter().all(|v| v.is_finite() && *v >= 0.0) && h < 24.0 && m < 60.0 && s < 61.0) {
        return None;
    }
    let whole_s = s.floor();
    // Bounded above: h < 24, m < 60, s < 61.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let time = NaiveTime::from_hms_milli_opt(
        h as u32,
        m as u32,
        (whole_s as u32).min(59),
        ((s - whole_s) * 1000.0).round().min(999.0) as u32,
    )?;
    Some(Utc.from_utc_datetime(&date.and_time(time)).fixed_offset())
}

/// `MAPCaptureTime` from the Mapillary JSON of an `ImageDescription`, UTC. `None` when the text
/// is not a JSON object, has no `MAPCaptureTime`, or its value is not `YYYY_MM_DD_HH_MM_SS_mmm`.
#[must_use]
pub fn mapillary_capture_time(image_description: &str) -> Option<DateTime<FixedOffset>> {
    let json: serde_json::Value = serde_json::from_str(image_description.trim()).ok()?;
    let text = json.get("MAPCaptureTime")?.as_str()?;
    let naive = NaiveDateTime::parse_from_str(text.trim(), "%Y_%m_%d_%H_%M_%S_%3f").ok()?;
    Some(Utc.from_utc_datetime(&naive).fixed_offset())
}

impl ExifInfo {
    /// The capture time by the order of the module documentation, or `None` when no reading
    /// gives a time with a known offset.
    #[must_use]
    pub fn capture_time(&self) -> Option<CaptureTime> {
        let original = self
            .date_time_original
            .as_deref()
            .zip(self.offset_time_original.as_deref())
            .and_then(|(dt, off)| exif_original(dt, off))
            .map(|time| CaptureTime {
                time,
                source: CaptureTimeSource::ExifOriginal,
            });
        original
            .or_else(|| {
                self.gps_date_time_utc.map(|time| CaptureTime {
                    time,
                    source: CaptureTimeSource::GpsTime,
                })
            })
            .or_else(|| {
                self.mapillary_capture_time.map(|time| CaptureTime {
                    time,
                    source: CaptureTimeSource::MapillaryCaptureTime,
                })
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `ImageDescription` of OpenSfM's `berlin/01.jpg`, shortened (the uploader's address and
    /// device name left out).
    const BERLIN_01: &str = r#"{"MAPAppNameString":"mapillary_ios","MAPLongitude":"13.400295","MAPDeviceModel":"iPhone4,1","MAPAccelerometerVector":{"x":0.9466457,"y":0.01739691,"z":0.3218063},"MAPLocalTimeZone":"Europe\/Berlin (GMT+2) offset 7200 (Daylight)","MAPCaptureTime":"2014_05_26_12_56_02_384"}"#;

    #[test]
    fn mapillary_capture_time_is_utc_to_the_millisecond() {
        // The app's MAPLocalTimeZone (+7200 s) is not applied.
        let t = mapillary_capture_time(BERLIN_01).expect("time");
        assert_eq!(t.to_rfc3339(), "2014-05-26T12:56:02.384+00:00");
        assert_eq!(mapillary_capture_time("a plain caption"), None);
        assert_eq!(
            mapillary_capture_time(r#"{"MAPCaptureTime":"2014-05-26"}"#),
            None
        );
        assert_eq!(mapillary_capture_time(r#"{"MAPCaptureTime":12}"#), None);
    }

    #[test]
    fn gps_time_is_utc() {
        let t = gps_time("2014:05:26", [12.0, 56.0, 2.5]).expect("time");
        assert_eq!(t.to_rfc3339(), "2014-05-26T12:56:02.500+00:00");
        assert_eq!(gps_time("2014:05:26", [24.0, 0.0, 0.0]), None);
        assert_eq!(gps_time("26.05.2014", [1.0, 0.0, 0.0]), None);
    }

    #[test]
    fn precedence_original_then_gps_then_mapillary() {
        let mut exif = ExifInfo {
            mapillary_capture_time: mapillary_capture_time(BERLIN_01),
            ..ExifInfo::default()
        };
        let c = exif.capture_time().expect("mapillary");
        assert_eq!(c.source, CaptureTimeSource::MapillaryCaptureTime);
        exif.gps_date_time_utc = gps_time("2014:05:26", [12.0, 56.0, 3.0]);
        assert_eq!(
            exif.capture_time().expect("gps").source,
            CaptureTimeSource::GpsTime
        );
        // A local time without its offset is not used …
        exif.date_time_original = Some("2014:05:26 14:56:02".into());
        assert_eq!(
            exif.capture_time().expect("gps").source,
            CaptureTimeSource::GpsTime
        );
        // … with it, it comes first.
        exif.offset_time_original = Some("+02:00".into());
        let c = exif.capture_time().expect("original");
        assert_eq!(c.source, CaptureTimeSource::ExifOriginal);
        assert_eq!(c.time.to_rfc3339(), "2014-05-26T14:56:02+02:00");
    }
}
