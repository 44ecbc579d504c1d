//! The instant the sun is placed for: `lighting.time`, else the photo's `taken_at`, else its EXIF
//! capture time — each either RFC 3339 with an offset or, when the site names
//! `location.time_zone`, a local clock time read in that zone (see [`crate::time_zone`]).
//!
//! Known limitations: local times are accepted as `YYYY-MM-DDTHH:MM[:SS]` (or with a space for
//! the `T`) only; fractional seconds need an explicit offset.

use chrono::{DateTime, FixedOffset, NaiveDateTime};

use super::{Location, Site, SiteDocument};
use crate::sun::{SolarPosition, SpaParams, solar_position};
use crate::time_zone::SiteTimeZone;

pub use super::render_error::SiteRenderError;

/// Local-time layouts accepted when a site names its time zone.
const LOCAL_FORMATS: [&str; 4] = [
    "%Y-%m-%dT%H:%M:%S",
    "%Y-%m-%dT%H:%M",
    "%Y-%m-%d %H:%M:%S",
    "%Y-%m-%d %H:%M",
];

/// The SPA inputs of a site location: those of `photomontage sun` with its defaults.
#[must_use]
pub fn location_spa_params(location: &Location) -> SpaParams {
    SpaParams {
        elevation_m: location.elevation_m,
        ..SpaParams::at(location.latitude_deg, location.longitude_deg)
    }
}

/// The site's `location.time_zone`, parsed; `None` when the site names none.
///
/// # Errors
/// [`SiteRenderError::TimeZone`] for a name the tz database does not know.
pub fn site_time_zone(site: &Site) -> Result<Option<SiteTimeZone>, SiteRenderError> {
    site.location
        .as_ref()
        .and_then(|l| l.time_zone.as_deref())
        .map(SiteTimeZone::parse)
        .transpose()
        .map_err(SiteRenderError::TimeZone)
}

/// Reads `text` as RFC 3339, else (with `zone`) as a local clock time in that zone.
///
/// # Errors
/// A sentence saying why the text is no instant (for the caller to name its field).
pub fn parse_site_time(
    text: &str,
    zone: Option<&SiteTimeZone>,
) -> Result<DateTime<FixedOffset>, String> {
    let text = text.trim();
    let rfc_error = match DateTime::parse_from_rfc3339(text) {
        Ok(t) => return Ok(t),
        Err(e) => e,
    };
    let Some(zone) = zone else {
        return Err(format!(
            "`{text}` is not RFC 3339 with a UTC offset ({rfc_error}); give the offset \
             (e.g. 2026-06-21T12:00:00+02:00) or set location.time_zone"
        ));
    };
    let naive = LOCAL_FORMATS
        .iter()
        .find_map(|f| NaiveDateTime::parse_from_str(text, f).ok())
        .ok_or_else(|| {
            format!(
                "`{text}` is neither RFC 3339 nor a local time YYYY-MM-DDTHH:MM[:SS] in {}",
                zone.name()
            )
        })?;
    zone.resolve(naive).map_err(|e| e.to_string())
}

/// The instant of the sun for photo `photo_id`: `lighting.time`, the photo's `taken_at`, or its
/// EXIF capture time (read in the site's time zone when EXIF has no offset).
///
/// # Errors
/// [`SiteRenderError::NoSunDirection`] when there is no usable time (naming the photo and why),
/// [`SiteRenderError::TimeZone`] for an unknown zone name.
pub fn site_sun_time(
    doc: &SiteDocument,
    photo_id: &str,
) -> Result<DateTime<FixedOffset>, SiteRenderError> {
    let site = &doc.site;
    let zone = site_time_zone(site)?;
    let no_sun = |reason: String| SiteRenderError::NoSunDirection {
        photo: photo_id.to_owned(),
        reason,
    };
    if let Some(text) = &site.lighting.time {
        return parse_site_time(text, zone.as_ref())
            .map_err(|e| no_sun(format!("lighting.time: {e}")));
    }
    let photo = site.photos.iter().find(|p| p.id == photo_id);
    if let Some(text) = photo.and_then(|p| p.taken_at.as_ref()) {
        return parse_site_time(text, zone.as_ref())
            .map_err(|e| no_sun(format!("photos.taken_at: {e}")));
    }
    let exif = photo.and_then(|p| crate::photo::read_exif(&doc.resolve(&p.file)).ok());
    let from_exif = exif
        .as_ref()
        .map(|e| e.taken_at_in_zone(zone.as_ref()))
        .transpose()
        .map_err(|e| no_sun(format!("EXIF capture time: {e}")))?
        .flatten();
    from_exif.ok_or_else(|| {
        let has_naive_exif = exif
            .as_ref()
            .is_some_and(|e| e.date_time_original.is_some());
        no_sun(if has_naive_exif && zone.is_none() {
            "its EXIF time has no UTC offset and the site names no location.time_zone".to_owned()
        } else {
            "no time (lighting.time, photos.taken_at or EXIF)".to_owned()
        })
    })
}

/// The SPA sun position at `time` for the site's `[location]` (as `photomontage sun` computes it
/// with the same latitude, longitude and elevation and its default pressure, temperature, ΔT).
///
/// # Errors
/// [`SiteRenderError::NoSunDirection`] without `[location]` (naming `photo_id`),
/// [`SiteRenderError::Sun`] from the SPA.
pub fn site_solar_position(
    site: &Site,
    time: &DateTime<FixedOffset>,
    photo_id: &str,
) -> Result<SolarPosition, SiteRenderError> {
    let loc = site
        .location
        .as_ref()
        .ok_or_else(|| SiteRenderError::NoSunDirection {
            photo: photo_id.to_owned(),
            reason: "the site has no [location]".to_owned(),
        })?;
    Ok(solar_position(time, &location_spa_params(loc))?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn local_text_in_a_zone_and_rfc3339_agree() {
        let zurich = SiteTimeZone::parse("Europe/Zurich").unwrap();
        let local = parse_site_time("2024-06-21T15:00", Some(&zurich)).unwrap();
        let rfc = parse_site_time("2024-06-21T13:00:00Z", None).unwrap();
        assert_eq!(local, rfc);
        let e = parse_site_time("2024-06-21T15:00", None).unwrap_err();
        assert!(e.contains("location.time_zone"), "{e}");
        let e = parse_site_time("June 21st", Some(&zurich)).unwrap_err();
        assert!(e.contains("Europe/Zurich"), "{e}");
    }
}
