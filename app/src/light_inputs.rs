//! The Site & light tab's typed values, checked before anything is written
//! ([`crate::light_panel`]): finite numbers, a location in range with a known IANA time zone
//! (and the tz database's "did you mean"), times read in the site's zone, the location from the
//! control points, and the sky models the site file names. Each refusal is a sentence naming
//! the field, shown in the panel.

use photomontage::site::{Location, SiteDocument, SkyModelName, site_time::parse_site_time};
use photomontage::time_zone::SiteTimeZone;

/// Reads a finite number from `text`, naming `field` when it is not one.
///
/// # Errors
/// A sentence for the panel.
pub fn finite(text: &str, field: &str) -> Result<f64, String> {
    let t = text.trim();
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("{field}: `{t}` is not a finite number")),
        Err(_) => Err(format!("{field}: `{t}` is not a number")),
    }
}

/// The location typed in the panel, checked, keeping the CRS and grid convergence of `old`.
///
/// # Errors
/// A sentence naming the field: not a finite number, latitude outside −90…90, longitude
/// outside −180…180, a time zone the tz database does not know (with its "did you mean").
pub fn typed_location(
    latitude: &str,
    longitude: &str,
    elevation: &str,
    time_zone: &str,
    old: Option<&Location>,
) -> Result<Location, String> {
    let lat = finite(latitude, "latitude")?;
    let lon = finite(longitude, "longitude")?;
    let elevation_m = if elevation.trim().is_empty() {
        0.0
    } else {
        finite(elevation, "elevation")?
    };
    if !(-90.0..=90.0).contains(&lat) {
        return Err(format!("latitude {lat} is outside −90…90°"));
    }
    if !(-180.0..=180.0).contains(&lon) {
        return Err(format!("longitude {lon} is outside −180…180°"));
    }
    let zone = match time_zone.trim() {
        "" => None,
        name => Some(
            SiteTimeZone::parse(name)
                .map_err(|e| format!("time zone: {e}"))?
                .name()
                .to_owned(),
        ),
    };
    Ok(Location {
        latitude_deg: lat,
        longitude_deg: lon,
        elevation_m,
        crs: old.and_then(|l| l.crs.clone()),
        grid_convergence_deg: old.map_or(0.0, |l| l.grid_convergence_deg),
        time_zone: zone,
    })
}

/// Every sky model the site file names: uniform, CIE overcast, the 15 CIE general skies and
/// the Perez all-weather sky.
#[must_use]
pub fn sky_models() -> Vec<SkyModelName> {
    let mut out = vec![SkyModelName::Uniform, SkyModelName::CieOvercast];
    out.extend((1..=15).map(SkyModelName::CieGeneral));
    out.push(SkyModelName::Perez);
    out
}
/// A time typed in the panel: empty → `None`; else RFC 3339, or a local time in the site's
/// zone, stored as RFC 3339 with its offset.
///
/// # Errors
/// A sentence naming `field` and why the text is no instant.
pub fn typed_time(
    text: &str,
    zone: Option<&SiteTimeZone>,
    field: &str,
) -> Result<Option<String>, String> {
    if text.trim().is_empty() {
        return Ok(None);
    }
    parse_site_time(text, zone)
        .map(|t| Some(t.to_rfc3339()))
        .map_err(|e| format!("{field}: {e}"))
}

/// The location from the site's enabled control points in `crs`, keeping the time zone.
///
/// # Errors
/// A sentence: an unknown CRS or what `location_from_control` says.
pub fn from_control(doc: &SiteDocument, crs: &str) -> Result<Location, String> {
    let name = crs.trim();
    if name.is_empty() {
        return Err("From control points: type the control points' CRS (e.g. EPSG:2056)".into());
    }
    let projected = photomontage::geo::ProjectedCrs::from_name(name)
        .map_err(|e| format!("CRS `{name}`: {e}"))?;
    let mut loc = photomontage::site::control_location::location_from_control(
        &doc.site.control_points,
        &projected,
        name,
    )
    .map_err(|e| e.to_string())?;
    loc.time_zone = doc.site.location.as_ref().and_then(|l| l.time_zone.clone());
    Ok(loc)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[allow(clippy::float_cmp)] // an empty elevation is exactly 0
    fn typed_location_refuses_bad_values_naming_them() {
        let ok = typed_location("47.5", "8.5", "", "europe/zurich ", None);
        // Zone names are matched exactly; the hint names the right spelling.
        let e = ok.unwrap_err();
        assert!(e.contains("did you mean `Europe/Zurich`"), "{e}");
        let loc = typed_location("47.5", "8.5", "", "Europe/Zurich", None).unwrap();
        assert_eq!(loc.time_zone.as_deref(), Some("Europe/Zurich"));
        assert_eq!(loc.elevation_m, 0.0);
        for (lat, lon, elev, want) in [
            ("95", "8", "0", "latitude 95 is outside"),
            ("45", "-181", "0", "longitude -181 is outside"),
            ("NaN", "8", "0", "latitude: `NaN` is not a finite number"),
            ("45", "8", "inf", "elevation: `inf` is not a finite number"),
            ("north", "8", "0", "latitude: `north` is not a number"),
        ] {
            let e = typed_location(lat, lon, elev, "", None).unwrap_err();
            assert!(e.contains(want), "{e} lacks {want}");
        }
    }

    #[test]
    fn all_eighteen_site_sky_models_are_offered_once() {
        let m = sky_models();
        assert_eq!(m.len(), 18);
        for name in [
            "uniform",
            "cie_overcast",
            "cie_general:1",
            "cie_general:15",
            "perez",
        ] {
            assert!(m.iter().any(|s| s.to_string() == name), "{name}");
        }
    }

    #[test]
    fn local_times_are_stored_with_the_offset_of_the_zone() {
        let z = SiteTimeZone::parse("Europe/Zurich").unwrap();
        assert_eq!(
            typed_time("2024-01-15 09:30", Some(&z), "t").unwrap(),
            Some("2024-01-15T09:30:00+01:00".to_owned())
        );
        assert_eq!(typed_time("  ", Some(&z), "t").unwrap(), None);
        let e = typed_time("2024-03-31T02:30", Some(&z), "lighting time").unwrap_err();
        assert!(
            e.starts_with("lighting time: ") && e.contains("does not exist"),
            "{e}"
        );
    }
}
