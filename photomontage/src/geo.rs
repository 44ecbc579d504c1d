//! Site coordinates in a projected coordinate reference system (UTM zones north and south,
//! national grids) to geodetic latitude/longitude on WGS84, as the sun position needs them.
//! The projection mathematics are the `proj4rs` crate's (a Rust port of PROJ.4; UTM uses its
//! extended transverse Mercator, Poder/Engsager), not reimplemented here.
//!
//! Supported: any PROJ.4 string `proj4rs` understands, plus presets for UTM (`+proj=utm +zone=N
//! [+south] +datum=WGS84`), Swiss LV95 (EPSG:2056) and the British National Grid (EPSG:27700),
//! both with their standard 7-parameter `+towgs84` datum shifts.
//!
//! # Known limitations
//! - Grid-based datum shifts (NTv2, OSTN15) are not available, so national-grid conversions carry
//!   the metre-level error of the 3/7-parameter shift; for the sun position 1 km is only 0.01°,
//!   far below what matters.
//! - Heights are passed through unchanged (no geoid model).

use proj4rs::proj::Proj;

/// Errors of the coordinate conversions.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeoError {
    /// A UTM zone outside 1…60.
    #[error("UTM zone {zone} is outside 1…60")]
    UtmZoneOutOfRange {
        /// Zone given.
        zone: u8,
    },
    /// The projection definition was rejected by `proj4rs`.
    #[error("invalid projection definition {definition:?}: {message}")]
    InvalidDefinition {
        /// The definition given.
        definition: String,
        /// What `proj4rs` said.
        message: String,
    },
    /// The conversion of a point failed (outside the projection's domain, NaN, …).
    #[error("cannot convert ({x}, {y}): {message}")]
    Conversion {
        /// First coordinate given (easting or latitude).
        x: f64,
        /// Second coordinate given (northing or longitude).
        y: f64,
        /// What went wrong.
        message: String,
    },
}

/// Hemisphere of a UTM zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Hemisphere {
    /// Northern (false northing 0 m).
    North,
    /// Southern (false northing 10 000 000 m).
    South,
}

/// A projected CRS and the geographic WGS84 CRS it converts to.
#[derive(Clone)]
pub struct ProjectedCrs {
    definition: String,
    projected: Proj,
    wgs84: Proj,
}

impl std::fmt::Debug for ProjectedCrs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ProjectedCrs")
            .field("definition", &self.definition)
            .finish_non_exhaustive()
    }
}

/// PROJ.4 definition of Swiss LV95 (EPSG:2056).
pub const SWISS_LV95: &str = "+proj=somerc +lat_0=46.9524055555556 +lon_0=7.43958333333333 +k_0=1 +x_0=2600000 +y_0=1200000 +ellps=bessel +towgs84=674.374,15.056,405.346,0,0,0,0 +units=m +no_defs";

/// PROJ.4 definition of the British National Grid (EPSG:27700).
pub const BRITISH_NATIONAL_GRID: &str = "+proj=tmerc +lat_0=49 +lon_0=-2 +k=0.9996012717 +x_0=400000 +y_0=-100000 +ellps=airy +towgs84=446.448,-125.157,542.06,0.15,0.247,0.842,-20.489 +units=m +no_defs";

impl ProjectedCrs {
    /// A CRS from a PROJ.4 definition string.
    ///
    /// # Errors
    /// [`GeoError::InvalidDefinition`] when `proj4rs` rejects it.
    pub fn from_proj_string(definition: &str) -> Result<Self, GeoError> {
        let invalid = |e: proj4rs::errors::Error| GeoError::InvalidDefinition {
            definition: definition.to_owned(),
            message: e.to_string(),
        };
        let projected = Proj::from_proj_string(definition).map_err(invalid)?;
        let wgs84 = Proj::from_proj_string("+proj=longlat +ellps=WGS84 +datum=WGS84 +no_defs")
            .map_err(invalid)?;
        Ok(Self {
            definition: definition.to_owned(),
            projected,
            wgs84,
        })
    }

    /// UTM zone `zone` (1…60) on WGS84.
    ///
    /// # Errors
    /// [`GeoError::UtmZoneOutOfRange`] outside 1…60.
    pub fn utm(zone: u8, hemisphere: Hemisphere) -> Result<Self, GeoError> {
        if !(1..=60).contains(&zone) {
            return Err(GeoError::UtmZoneOutOfRange { zone });
        }
        let south = match hemisphere {
            Hemisphere::North => "",
            Hemisphere::South => " +south",
        };
        Self::from_proj_string(&format!(
            "+proj=utm +zone={zone}{south} +datum=WGS84 +units=m +no_defs"
        ))
    }

    /// The PROJ.4 definition.
    #[must_use]
    pub fn definition(&self) -> &str {
        &self.definition
    }

    /// WGS84 latitude and longitude (degrees) of a projected point (metres).
    ///
    /// # Errors
    /// [`GeoError::Conversion`] when the point cannot be converted.
    pub fn to_lat_lon_deg(&self, easting_m: f64, northing_m: f64) -> Result<(f64, f64), GeoError> {
        let mut point = (easting_m, northing_m, 0.0);
        proj4rs::transform::transform(&self.projected, &self.wgs84, &mut point).map_err(|e| {
            GeoError::Conversion {
                x: easting_m,
                y: northing_m,
                message: e.to_string(),
            }
        })?;
        let (lon, lat) = (point.0.to_degrees(), point.1.to_degrees());
        if lat.is_finite() && lon.is_finite() {
            Ok((lat, lon))
        } else {
            Err(GeoError::Conversion {
                x: easting_m,
                y: northing_m,
                message: "result is not finite".to_owned(),
            })
        }
    }

    /// Projected easting and northing (metres) of a WGS84 latitude and longitude (degrees).
    ///
    /// # Errors
    /// [`GeoError::Conversion`] when the point cannot be converted.
    pub fn from_lat_lon_deg(
        &self,
        latitude_deg: f64,
        longitude_deg: f64,
    ) -> Result<(f64, f64), GeoError> {
        let fail = |message: String| GeoError::Conversion {
            x: latitude_deg,
            y: longitude_deg,
            message,
        };
        if !(-90.0..=90.0).contains(&latitude_deg) || !longitude_deg.is_finite() {
            return Err(fail("latitude or longitude out of range".to_owned()));
        }
        let mut point = (longitude_deg.to_radians(), latitude_deg.to_radians(), 0.0);
        proj4rs::transform::transform(&self.wgs84, &self.projected, &mut point)
            .map_err(|e| fail(e.to_string()))?;
        if point.0.is_finite() && point.1.is_finite() {
            Ok((point.0, point.1))
        } else {
            Err(fail("result is not finite".to_owned()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// UTM closed forms: proj4rs's extended TM is accurate to well below 1 mm in a zone.
    const UTM_TOL_M: f64 = 1e-3;

    #[test]
    fn utm_on_the_central_meridian() {
        let zone31 = ProjectedCrs::utm(31, Hemisphere::North).expect("valid");
        // Equator on the central meridian (3°E): exactly (500 000, 0).
        let (e, n) = zone31.from_lat_lon_deg(0.0, 3.0).expect("converts");
        assert!((e - 500_000.0).abs() < UTM_TOL_M && n.abs() < UTM_TOL_M);
        // 45°N on the central meridian: 0.9996 × WGS84 meridian arc to 45° (4 984 944.378 m).
        let (e, n) = zone31.from_lat_lon_deg(45.0, 3.0).expect("converts");
        assert!((e - 500_000.0).abs() < UTM_TOL_M);
        assert!((n - 0.9996 * 4_984_944.378).abs() < 0.01, "{n}");
        // And back.
        let (lat, lon) = zone31.to_lat_lon_deg(e, n).expect("converts");
        assert!((lat - 45.0).abs() < 1e-9 && (lon - 3.0).abs() < 1e-9);
        // Southern hemisphere: false northing 10 000 km.
        let south = ProjectedCrs::utm(31, Hemisphere::South).expect("valid");
        let (lat, lon) = south
            .to_lat_lon_deg(500_000.0, 10_000_000.0)
            .expect("converts");
        assert!(lat.abs() < 1e-9 && (lon - 3.0).abs() < 1e-9);
        // Off-meridian round trip (Zurich in zone 32).
        let zone32 = ProjectedCrs::utm(32, Hemisphere::North).expect("valid");
        let (e, n) = zone32.from_lat_lon_deg(47.37, 8.54).expect("converts");
        let (lat, lon) = zone32.to_lat_lon_deg(e, n).expect("converts");
        assert!((lat - 47.37).abs() < 1e-9 && (lon - 8.54).abs() < 1e-9);
    }

    #[test]
    fn swiss_lv95_example() {
        // swisstopo, "Approximate formulas for the transformation between Swiss projection
        // coordinates and WGS84": E 2 700 000, N 1 100 000 ↔ 46°02′38.87″N, 8°43′49.79″E. The
        // approximate formulas are good to about 1 m (≈1e-5°).
        let lv95 = ProjectedCrs::from_proj_string(SWISS_LV95).expect("valid");
        let (lat, lon) = lv95
            .to_lat_lon_deg(2_700_000.0, 1_100_000.0)
            .expect("converts");
        let want_lat = 46.0 + 2.0 / 60.0 + 38.87 / 3600.0;
        let want_lon = 8.0 + 43.0 / 60.0 + 49.79 / 3600.0;
        assert!((lat - want_lat).abs() < 3e-5, "{lat}");
        assert!((lon - want_lon).abs() < 3e-5, "{lon}");
    }

    #[test]
    fn bad_inputs() {
        assert!(ProjectedCrs::utm(0, Hemisphere::North).is_err());
        assert!(ProjectedCrs::utm(61, Hemisphere::North).is_err());
        assert!(ProjectedCrs::from_proj_string("+proj=nonsense").is_err());
        let zone = ProjectedCrs::utm(32, Hemisphere::North).expect("valid");
        assert!(zone.from_lat_lon_deg(95.0, 8.0).is_err());
    }
}
