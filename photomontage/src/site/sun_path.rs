//! The sun as the studio's Site & light panel shows it: the azimuth and elevation the renderer
//! uses for a photo ([`site_sun_angles`]: `lighting.sun_manual`, else the SPA at the site's sun
//! time, the one computation `site_sun_dir` and the panel share), the sun's path over one local
//! day ([`site_sun_path`]) and the sky map it is drawn on ([`sky_map_xy`]: an azimuthal
//! equidistant projection of the sky hemisphere, zenith at the centre, horizon on the unit
//! circle, north up and east right as on a site plan).
//!
//! The SPA is called with `SpaParams::at(latitude, longitude)` and the site's elevation, which
//! are exactly the inputs `photomontage sun --lat --lon --elevation-m --time` uses with its
//! default pressure, temperature and ΔT, so the panel and the CLI agree to the last bit.
//!
//! # Known limitations
//! The path is sampled every `step_min` minutes of UTC time from local midnight; a day on which
//! the clocks change is 23 or 25 hours long and sampled as such.

use chrono::{DateTime, Duration, FixedOffset, NaiveDate, NaiveTime};

use super::render_error::SiteRenderError;
pub use super::site_time::location_spa_params;
use super::site_time::{site_solar_position, site_sun_time, site_time_zone};
use super::{Site, SiteDocument};
use crate::sun::solar_position;
use crate::time_zone::SiteTimeZone;

/// Where the sun direction of a photo comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum SunSource {
    /// `lighting.sun_manual`.
    Manual,
    /// The SPA at this instant (`lighting.time`, the photo's `taken_at` or its EXIF time).
    Computed(DateTime<FixedOffset>),
}

/// Sun azimuth (true north, clockwise) and elevation of a photo, and where they come from.
#[derive(Debug, Clone, PartialEq)]
pub struct SunAngles {
    /// Azimuth east of true north, degrees.
    pub azimuth_deg: f64,
    /// Elevation above the horizon (refraction included when computed), degrees.
    pub elevation_deg: f64,
    /// Manual or computed.
    pub source: SunSource,
}

/// The sun of photo `photo_id` as the renderer places it: `sun_manual`, else the SPA at
/// [`site_sun_time`].
///
/// # Errors
/// As [`site_sun_time`] and [`site_solar_position`].
pub fn site_sun_angles(doc: &SiteDocument, photo_id: &str) -> Result<SunAngles, SiteRenderError> {
    if let Some(m) = &doc.site.lighting.sun_manual {
        return Ok(SunAngles {
            azimuth_deg: m.azimuth_deg,
            elevation_deg: m.elevation_deg,
            source: SunSource::Manual,
        });
    }
    let time = site_sun_time(doc, photo_id)?;
    let pos = site_solar_position(&doc.site, &time, photo_id)?;
    Ok(SunAngles {
        azimuth_deg: pos.azimuth_deg,
        elevation_deg: pos.elevation_deg,
        source: SunSource::Computed(time),
    })
}

/// One sample of the sun's path.
#[derive(Debug, Clone, PartialEq)]
pub struct SunPathPoint {
    /// The instant, with the local offset in force then.
    pub time: DateTime<FixedOffset>,
    /// Azimuth east of true north, degrees.
    pub azimuth_deg: f64,
    /// Elevation above the horizon, degrees (negative at night).
    pub elevation_deg: f64,
}

/// The instant local midnight starts `date`: in `zone` when given (DST-aware; where midnight is
/// skipped, the first local hour that exists), else at the fixed `offset`.
#[must_use]
pub fn local_day_start(
    date: NaiveDate,
    zone: Option<&SiteTimeZone>,
    offset: FixedOffset,
) -> Option<DateTime<FixedOffset>> {
    match zone {
        Some(z) => (0..4).find_map(|h| {
            let t = NaiveTime::from_hms_opt(h, 0, 0)?;
            z.resolve(date.and_time(t)).ok()
        }),
        None => date
            .and_hms_opt(0, 0, 0)?
            .and_local_timezone(offset)
            .single(),
    }
}

/// The local time of `instant` in `zone` (or at `fallback` when the site names no zone).
#[must_use]
pub fn in_site_zone(
    instant: &DateTime<FixedOffset>,
    zone: Option<&SiteTimeZone>,
    fallback: FixedOffset,
) -> DateTime<FixedOffset> {
    zone.map_or_else(|| instant.with_timezone(&fallback), |z| z.to_local(instant))
}

/// The sun's path on local `date` of the site, every `step_min` minutes (clamped to 1–60) from
/// local midnight to the next one, each sample in the local offset in force at that instant.
///
/// # Errors
/// [`SiteRenderError::NoSunDirection`] without `[location]` or when the date has no local
/// midnight, [`SiteRenderError::TimeZone`] for an unknown zone, [`SiteRenderError::Sun`] from
/// the SPA (a date outside its years).
pub fn site_sun_path(
    site: &Site,
    date: NaiveDate,
    fallback_offset: FixedOffset,
    step_min: u32,
) -> Result<Vec<SunPathPoint>, SiteRenderError> {
    let no_path = |reason: String| SiteRenderError::NoSunDirection {
        photo: "(sun path)".to_owned(),
        reason,
    };
    let location = site
        .location
        .as_ref()
        .ok_or_else(|| no_path("the site has no [location]".to_owned()))?;
    let zone = site_time_zone(site)?;
    let start = local_day_start(date, zone.as_ref(), fallback_offset)
        .ok_or_else(|| no_path(format!("{date} has no local midnight")))?;
    let end = local_day_start(
        date.succ_opt()
            .ok_or_else(|| no_path(format!("{date} has no next day")))?,
        zone.as_ref(),
        fallback_offset,
    )
    .ok_or_else(|| no_path(format!("the day after {date} has no local midnight")))?;
    let params = location_spa_params(location);
    let step = Duration::minutes(i64::from(step_min.clamp(1, 60)));
    let mut out = Vec::new();
    let mut t = start;
    while t <= end {
        let pos = solar_position(&t, &params)?;
        out.push(SunPathPoint {
            time: in_site_zone(&t, zone.as_ref(), fallback_offset),
            azimuth_deg: pos.azimuth_deg,
            elevation_deg: pos.elevation_deg,
        });
        t += step;
    }
    Ok(out)
}

/// Position of a sky direction on the sky map, in the unit disc: x east, y north (a site plan's
/// axes), radius `(90° − elevation) / 90°` (zenith 0, horizon 1; below the horizon > 1).
#[must_use]
pub fn sky_map_xy(azimuth_deg: f64, elevation_deg: f64) -> [f64; 2] {
    let r = (90.0 - elevation_deg) / 90.0;
    let a = azimuth_deg.to_radians();
    [r * a.sin(), r * a.cos()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::site::Location;
    use crate::sun::SpaParams;

    /// Map coordinates are a sine and a cosine of exact inputs: 1e-12 covers their rounding.
    const MAP_TOL: f64 = 1e-12;

    fn zurich() -> Site {
        Site {
            location: Some(Location {
                latitude_deg: 47.3769,
                longitude_deg: 8.5417,
                elevation_m: 408.0,
                crs: None,
                grid_convergence_deg: 0.0,
                time_zone: Some("Europe/Zurich".into()),
            }),
            ..Site::default()
        }
    }

    #[test]
    fn sky_map_puts_north_up_east_right_and_the_zenith_in_the_middle() {
        let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < MAP_TOL;
        assert!(close(sky_map_xy(0.0, 0.0), [0.0, 1.0]));
        assert!(close(sky_map_xy(90.0, 0.0), [1.0, 0.0]));
        assert!(close(sky_map_xy(180.0, 45.0), [0.0, -0.5]));
        assert!(close(sky_map_xy(270.0, 60.0), [-1.0 / 3.0, 0.0]));
        assert!(close(sky_map_xy(123.0, 90.0), [0.0, 0.0]));
    }

    #[test]
    fn solstice_path_culminates_at_ninety_minus_latitude_plus_obliquity() {
        // 21 June: declination ≈ +23.44° (obliquity), so the noon elevation is 90 − φ + 23.44
        // = 66.06° at φ = 47.3769°; refraction adds ≈ 0.007° there and the declination on the
        // day differs from the obliquity by < 0.01°: 0.05° bounds both and the 10-minute
        // sampling near the top (the elevation changes < 0.02° in 5 minutes at culmination).
        const NOON_TOL_DEG: f64 = 0.05;
        let site = zurich();
        let date = NaiveDate::from_ymd_opt(2024, 6, 21).unwrap();
        let utc = FixedOffset::east_opt(0).unwrap();
        let path = site_sun_path(&site, date, utc, 10).unwrap();
        // CEST (+02:00) all day: 24 h of 10-minute steps, both midnights included.
        assert_eq!(path.len(), 145);
        assert_eq!(path[0].time.to_rfc3339(), "2024-06-21T00:00:00+02:00");
        let top = path
            .iter()
            .max_by(|a, b| a.elevation_deg.total_cmp(&b.elevation_deg))
            .unwrap();
        let expected = 90.0 - 47.3769 + 23.44;
        assert!(
            (top.elevation_deg - expected).abs() < NOON_TOL_DEG,
            "{} vs {expected}",
            top.elevation_deg
        );
        // Culmination is due south, at about 13:26 local (solar noon at 8.54° E in CEST).
        assert!((top.azimuth_deg - 180.0).abs() < 3.0, "{}", top.azimuth_deg);
        assert_eq!(top.time.format("%H").to_string(), "13");
        // Each sample is the SPA at its instant, the call `photomontage sun` makes.
        let params = SpaParams {
            elevation_m: 408.0,
            ..SpaParams::at(47.3769, 8.5417)
        };
        for p in path.iter().step_by(17) {
            let pos = solar_position(&p.time, &params).unwrap();
            assert_eq!(pos.azimuth_deg.to_bits(), p.azimuth_deg.to_bits());
            assert_eq!(pos.elevation_deg.to_bits(), p.elevation_deg.to_bits());
        }
    }

    #[test]
    fn the_day_the_clocks_go_forward_has_23_hours() {
        let site = zurich();
        let date = NaiveDate::from_ymd_opt(2024, 3, 31).unwrap();
        let path = site_sun_path(&site, date, FixedOffset::east_opt(0).unwrap(), 60).unwrap();
        assert_eq!(path.len(), 24, "23 hourly steps, both midnights");
        assert_eq!(path[0].time.to_rfc3339(), "2024-03-31T00:00:00+01:00");
        assert_eq!(path[23].time.to_rfc3339(), "2024-04-01T00:00:00+02:00");
    }

    #[test]
    fn no_location_is_an_error_naming_it() {
        let e = site_sun_path(
            &Site::default(),
            NaiveDate::from_ymd_opt(2024, 6, 21).unwrap(),
            FixedOffset::east_opt(0).unwrap(),
            10,
        )
        .unwrap_err();
        assert!(e.to_string().contains("[location]"), "{e}");
    }
}
