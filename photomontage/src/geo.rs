//! Site coordinates in a projected coordinate reference system (UTM zones north and south,
//! national grids) to geodetic latitude/longitude on WGS84, as the sun position needs them.
//! The projection mathematics are the `proj4rs` crate's (a Rust port of PROJ.4; UTM uses its
//! extended transverse Mercator, Poder/Engsager), not reimplemented here.
//!
//! Supported: any PROJ.4 string `proj4rs` understands, plus presets for UTM (`+proj=utm +zone=N
//! [+south] +datum=WGS84`), Swiss LV95 (EPSG:2056) and the British National Grid (EPSG:27700),
//! both with their standard 7-parameter `+towgs84` datum shifts.
//!
//! Control coordinates may come in another CRS than the site's ([`SourceCrs`]: the header of an
//! OpenDroneMap `gcp_list.txt`, geographic WGS 84 included) and are reprojected with
//! [`SourceCrs::to_projected`]; [`utm_zone_of`] picks a UTM zone when no target is named.
//!
//! # Known limitations
//! - Grid-based datum shifts (NTv2, OSTN15) are not available, so national-grid conversions carry
//!   the metre-level error of the 3/7-parameter shift; for the sun position 1 km is only 0.01°,
//!   far below what matters.
//! - Heights are passed through unchanged (no geoid model): a GPS height stays ellipsoidal, an
//!   orthometric height stays orthometric.
//! - EPSG codes beyond the presets are not looked up (no EPSG database); give a PROJ.4 string.

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
    /// A CRS name that is neither a PROJ.4 string nor one of the supported EPSG codes.
    #[error(
        "unknown coordinate system {name:?}: give a PROJ.4 string or one of EPSG:2056, \
         EPSG:27700, EPSG:326NN, EPSG:327NN"
    )]
    UnknownName {
        /// The name given.
        name: String,
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

/// Latitude step of [`ProjectedCrs::grid_convergence_deg`]: 1e-5° (about 1 m), where the
/// meridian's curvature in the grid moves its direction by far less than 1e-6°.
pub const CONVERGENCE_STEP_DEG: f64 = 1e-5;

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

    /// A CRS from the name a site file gives (`location.crs`): a PROJ.4 string (`+proj=…`),
    /// `EPSG:2056` (Swiss LV95), `EPSG:27700` (British National Grid), `EPSG:326NN` or
    /// `EPSG:327NN` (UTM zone NN north or south on WGS84). Case and surrounding blanks are
    /// ignored.
    ///
    /// # Errors
    /// [`GeoError::UnknownName`] for any other name, [`GeoError::InvalidDefinition`] for a PROJ.4
    /// string `proj4rs` rejects, [`GeoError::UtmZoneOutOfRange`].
    pub fn from_name(name: &str) -> Result<Self, GeoError> {
        let trimmed = name.trim();
        if trimmed.starts_with('+') {
            return Self::from_proj_string(trimmed);
        }
        let unknown = || GeoError::UnknownName {
            name: name.to_owned(),
        };
        let code = trimmed
            .to_ascii_uppercase()
            .strip_prefix("EPSG:")
            .and_then(|c| c.parse::<u32>().ok())
            .ok_or_else(unknown)?;
        match code {
            2056 => Self::from_proj_string(SWISS_LV95),
            27700 => Self::from_proj_string(BRITISH_NATIONAL_GRID),
            32601..=32660 => Self::utm(
                u8::try_from(code - 32600).map_err(|_| unknown())?,
                Hemisphere::North,
            ),
            32701..=32760 => Self::utm(
                u8::try_from(code - 32700).map_err(|_| unknown())?,
                Hemisphere::South,
            ),
            _ => Err(unknown()),
        }
    }

    /// Grid convergence at a projected point, in the site file's convention: the angle from grid
    /// north (+northing) to true north, degrees, clockwise. Computed numerically: the point is
    /// converted to latitude/longitude, moved [`CONVERGENCE_STEP_DEG`] north along its meridian
    /// and converted back; the direction of that step in the grid is true north.
    ///
    /// # Errors
    /// [`GeoError::Conversion`] when the point (or its neighbour) cannot be converted.
    pub fn grid_convergence_deg(&self, easting_m: f64, northing_m: f64) -> Result<f64, GeoError> {
        let (lat, lon) = self.to_lat_lon_deg(easting_m, northing_m)?;
        // Step away from the pole so the neighbour exists.
        let step = if lat > 0.0 {
            -CONVERGENCE_STEP_DEG
        } else {
            CONVERGENCE_STEP_DEG
        };
        let (e1, n1) = self.from_lat_lon_deg(lat + step, lon)?;
        let (de, dn) = if step > 0.0 {
            (e1 - easting_m, n1 - northing_m)
        } else {
            (easting_m - e1, northing_m - n1)
        };
        Ok(de.atan2(dn).to_degrees())
    }

    /// The PROJ.4 definition.
    #[must_use]
    pub fn definition(&self) -> &str {
        &self.definition
    }

    /// The name a site file gives this CRS (`location.crs`): `EPSG:2056`, `EPSG:27700`,
    /// `EPSG:326NN` / `EPSG:327NN` for the presets [`Self::from_name`] knows, else the PROJ.4
    /// definition itself. [`Self::from_name`] of the result gives this CRS back.
    #[must_use]
    pub fn site_name(&self) -> String {
        if self.definition == SWISS_LV95 {
            return "EPSG:2056".to_owned();
        }
        if self.definition == BRITISH_NATIONAL_GRID {
            return "EPSG:27700".to_owned();
        }
        for zone in 1..=60_u8 {
            for (hemisphere, base) in [(Hemisphere::North, 32600), (Hemisphere::South, 32700)] {
                if Self::utm(zone, hemisphere).is_ok_and(|u| u.definition == self.definition) {
                    return format!("EPSG:{}", base + u32::from(zone));
                }
            }
        }
        self.definition.clone()
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

/// PROJ.4 definition of geographic WGS 84 (EPSG:4326), longitude and latitude in degrees.
pub const WGS84_GEOGRAPHIC: &str = "+proj=longlat +ellps=WGS84 +datum=WGS84 +no_defs";

/// The CRS control coordinates are given in (the header of a GCP list): geographic longitude and
/// latitude in degrees, or a projected grid in metres.
// One value per control list, never stored in bulk: the size difference costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum SourceCrs {
    /// Longitude (x) and latitude (y) in degrees on the datum of `definition` (PROJ's
    /// `+proj=longlat` axis order, which is also OpenDroneMap's and OpenSfM's for `WGS84`).
    Geographic {
        /// The PROJ.4 definition.
        definition: String,
        /// The parsed definition (boxed: it is the larger variant's bulk).
        proj: Box<Proj>,
    },
    /// Easting and northing in metres.
    Projected(ProjectedCrs),
}

impl SourceCrs {
    /// The CRS a GCP-list header names: `WGS84`, `WGS 84` or `EPSG:4326` (geographic WGS 84),
    /// OpenDroneMap's `WGS84 UTM 32N` / `WGS84 UTM 32S`, a PROJ.4 string (`+proj=longlat …` is
    /// geographic, any other projected) or one of the EPSG codes [`ProjectedCrs::from_name`]
    /// knows. Case and surrounding blanks are ignored.
    ///
    /// # Errors
    /// [`GeoError::UnknownName`], [`GeoError::InvalidDefinition`] or
    /// [`GeoError::UtmZoneOutOfRange`] for a header that names no CRS `proj4rs` can use.
    pub fn from_header(header: &str) -> Result<Self, GeoError> {
        let trimmed = header.trim();
        let upper = trimmed.to_ascii_uppercase();
        let compact: String = upper.split_whitespace().collect();
        if compact == "WGS84" || compact == "EPSG:4326" {
            return Self::geographic(WGS84_GEOGRAPHIC);
        }
        if let Some(zone) = compact.strip_prefix("WGS84UTM") {
            let unknown = || GeoError::UnknownName {
                name: header.to_owned(),
            };
            let (digits, hemisphere) = match zone.chars().last() {
                Some('N') => (&zone[..zone.len() - 1], Hemisphere::North),
                Some('S') => (&zone[..zone.len() - 1], Hemisphere::South),
                _ => return Err(unknown()),
            };
            let zone: u8 = digits.parse().map_err(|_| unknown())?;
            return ProjectedCrs::utm(zone, hemisphere).map(Self::Projected);
        }
        if trimmed.starts_with('+') {
            let proj =
                Proj::from_proj_string(trimmed).map_err(|e| GeoError::InvalidDefinition {
                    definition: trimmed.to_owned(),
                    message: e.to_string(),
                })?;
            if proj.is_latlong() {
                return Ok(Self::Geographic {
                    definition: trimmed.to_owned(),
                    proj: Box::new(proj),
                });
            }
        }
        ProjectedCrs::from_name(trimmed).map(Self::Projected)
    }

    fn geographic(definition: &str) -> Result<Self, GeoError> {
        let proj = Proj::from_proj_string(definition).map_err(|e| GeoError::InvalidDefinition {
            definition: definition.to_owned(),
            message: e.to_string(),
        })?;
        Ok(Self::Geographic {
            definition: definition.to_owned(),
            proj: Box::new(proj),
        })
    }

    /// Whether coordinates are longitude/latitude in degrees.
    #[must_use]
    pub fn is_geographic(&self) -> bool {
        matches!(self, Self::Geographic { .. })
    }

    /// The PROJ.4 definition.
    #[must_use]
    pub fn definition(&self) -> &str {
        match self {
            Self::Geographic { definition, .. } => definition,
            Self::Projected(p) => p.definition(),
        }
    }

    /// A point `(x, y)` of this CRS (longitude, latitude in degrees, or easting, northing in
    /// metres) in `target`'s easting and northing (metres). Heights are not touched.
    ///
    /// # Errors
    /// [`GeoError::Conversion`] when the point cannot be converted.
    pub fn to_projected(
        &self,
        x: f64,
        y: f64,
        target: &ProjectedCrs,
    ) -> Result<(f64, f64), GeoError> {
        let fail = |message: String| GeoError::Conversion { x, y, message };
        let (source, mut point) = match self {
            Self::Geographic { proj, .. } => {
                if !(-90.0..=90.0).contains(&y) || !x.is_finite() {
                    return Err(fail("latitude or longitude out of range".to_owned()));
                }
                (&**proj, (x.to_radians(), y.to_radians(), 0.0))
            }
            Self::Projected(p) if p.definition() == target.definition() => return Ok((x, y)),
            Self::Projected(p) => (&p.projected, (x, y, 0.0)),
        };
        proj4rs::transform::transform(source, &target.projected, &mut point)
            .map_err(|e| fail(e.to_string()))?;
        if point.0.is_finite() && point.1.is_finite() {
            Ok((point.0, point.1))
        } else {
            Err(fail("result is not finite".to_owned()))
        }
    }

    /// WGS 84 latitude and longitude (degrees) of a point of this CRS.
    ///
    /// # Errors
    /// [`GeoError::Conversion`] when the point cannot be converted.
    pub fn to_lat_lon_deg(&self, x: f64, y: f64) -> Result<(f64, f64), GeoError> {
        match self {
            Self::Projected(p) => p.to_lat_lon_deg(x, y),
            Self::Geographic { proj, .. } => {
                let wgs84 = Proj::from_proj_string(WGS84_GEOGRAPHIC).map_err(|e| {
                    GeoError::InvalidDefinition {
                        definition: WGS84_GEOGRAPHIC.to_owned(),
                        message: e.to_string(),
                    }
                })?;
                let mut point = (x.to_radians(), y.to_radians(), 0.0);
                proj4rs::transform::transform(proj, &wgs84, &mut point).map_err(|e| {
                    GeoError::Conversion {
                        x,
                        y,
                        message: e.to_string(),
                    }
                })?;
                Ok((point.1.to_degrees(), point.0.to_degrees()))
            }
        }
    }
}

/// The standard UTM zone (1…60, 6° wide from 180°W) and hemisphere of a WGS 84 position. The
/// Norway and Svalbard exceptions of the military grid are not applied.
///
/// # Errors
/// [`GeoError::Conversion`] for a latitude outside ±90° or a non-finite longitude.
pub fn utm_zone_of(latitude_deg: f64, longitude_deg: f64) -> Result<(u8, Hemisphere), GeoError> {
    if !(-90.0..=90.0).contains(&latitude_deg) || !longitude_deg.is_finite() {
        return Err(GeoError::Conversion {
            x: latitude_deg,
            y: longitude_deg,
            message: "latitude or longitude out of range".to_owned(),
        });
    }
    let lon = (longitude_deg + 180.0).rem_euclid(360.0);
    // 0 ≤ lon < 360, so the quotient is 0…59 (360 itself wraps to 0).
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let zone = ((lon / 6.0).floor() as u8).min(59) + 1;
    let hemisphere = if latitude_deg >= 0.0 {
        Hemisphere::North
    } else {
        Hemisphere::South
    };
    Ok((zone, hemisphere))
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

    /// Convergence against the ellipsoidal series (Snyder 1987, eq. 8-11 with its second term):
    /// γ = Δλ sin φ (1 + Δλ² cos²φ (1 + 3η² + 2η⁴)/3), good to ~1e-6° at Δλ = 3°.
    const CONVERGENCE_TOL_DEG: f64 = 1e-4;

    #[test]
    fn grid_convergence_follows_snyder_and_the_site_sign() {
        let zone32 = ProjectedCrs::from_name("EPSG:32632").expect("valid");
        // On the central meridian (9°E) grid north is true north.
        let (e, n) = zone32.from_lat_lon_deg(47.0, 9.0).expect("converts");
        assert!(zone32.grid_convergence_deg(e, n).expect("converts").abs() < 1e-6);
        // 3° east of it at 47°N: meridians lean towards the pole, so true north lies
        // anticlockwise of grid north and the site's convention (clockwise) is negative.
        let (lat, dlon) = (47.0_f64.to_radians(), 3.0_f64.to_radians());
        let e2 = 0.006_694_379_990_14; // WGS84 first eccentricity squared
        let eta2 = e2 / (1.0 - e2) * lat.cos().powi(2);
        let gamma = dlon
            * lat.sin()
            * (1.0
                + dlon * dlon * lat.cos().powi(2) * (1.0 + 3.0 * eta2 + 2.0 * eta2 * eta2) / 3.0);
        let (e, n) = zone32.from_lat_lon_deg(47.0, 12.0).expect("converts");
        let got = zone32.grid_convergence_deg(e, n).expect("converts");
        assert!(
            (got + gamma.to_degrees()).abs() < CONVERGENCE_TOL_DEG,
            "{got} vs {}",
            -gamma.to_degrees()
        );
        // Southern hemisphere, west of the central meridian: again from the series.
        let south = ProjectedCrs::from_name(" epsg:32733 ").expect("valid");
        let (e, n) = south.from_lat_lon_deg(-33.0, 13.0).expect("converts");
        let (lat, dlon) = ((-33.0_f64).to_radians(), (-2.0_f64).to_radians());
        let eta2 = e2 / (1.0 - e2) * lat.cos().powi(2);
        let gamma = dlon
            * lat.sin()
            * (1.0
                + dlon * dlon * lat.cos().powi(2) * (1.0 + 3.0 * eta2 + 2.0 * eta2 * eta2) / 3.0);
        let got = south.grid_convergence_deg(e, n).expect("converts");
        assert!(
            (got + gamma.to_degrees()).abs() < CONVERGENCE_TOL_DEG,
            "{got}"
        );
    }

    #[test]
    fn site_names_round_trip() {
        for name in [
            "EPSG:2056",
            "EPSG:27700",
            "EPSG:32633",
            "EPSG:32733",
            "EPSG:32601",
        ] {
            let crs = ProjectedCrs::from_name(name).expect("valid");
            assert_eq!(crs.site_name(), name);
        }
        let custom = "+proj=tmerc +lat_0=0 +lon_0=9 +k=1 +x_0=0 +y_0=0 +ellps=GRS80 +units=m";
        let crs = ProjectedCrs::from_name(custom).expect("valid");
        assert_eq!(crs.site_name(), custom);
    }

    #[test]
    fn names_of_coordinate_systems() {
        assert!(ProjectedCrs::from_name("EPSG:2056").is_ok());
        assert!(ProjectedCrs::from_name("EPSG:27700").is_ok());
        assert!(ProjectedCrs::from_name("+proj=utm +zone=11 +datum=WGS84").is_ok());
        assert!(matches!(
            ProjectedCrs::from_name("EPSG:4326"),
            Err(GeoError::UnknownName { .. })
        ));
        assert!(ProjectedCrs::from_name("EPSG:32661").is_err());
        assert!(ProjectedCrs::from_name("Swiss grid").is_err());
    }

    #[test]
    fn bad_inputs() {
        assert!(ProjectedCrs::utm(0, Hemisphere::North).is_err());
        assert!(ProjectedCrs::utm(61, Hemisphere::North).is_err());
        assert!(ProjectedCrs::from_proj_string("+proj=nonsense").is_err());
        let zone = ProjectedCrs::utm(32, Hemisphere::North).expect("valid");
        assert!(zone.from_lat_lon_deg(95.0, 8.0).is_err());
    }

    #[test]
    fn gcp_list_headers() {
        for wgs in [
            "WGS84",
            " wgs 84 ",
            "EPSG:4326",
            "+proj=longlat +datum=WGS84 +no_defs",
        ] {
            assert!(
                SourceCrs::from_header(wgs).expect(wgs).is_geographic(),
                "{wgs}"
            );
        }
        let odm = SourceCrs::from_header("WGS84 UTM 32N").expect("ODM form");
        assert!(!odm.is_geographic());
        let zone32 = ProjectedCrs::utm(32, Hemisphere::North).expect("valid");
        assert_eq!(odm.definition(), zone32.definition());
        let south = SourceCrs::from_header("WGS84 UTM 17S").expect("ODM form");
        assert!(south.definition().contains("+south"));
        assert!(SourceCrs::from_header("EPSG:2056").is_ok());
        assert!(SourceCrs::from_header("+proj=utm +zone=11 +datum=WGS84").is_ok());
        assert!(matches!(
            SourceCrs::from_header("NAD83 / State Plane"),
            Err(GeoError::UnknownName { .. })
        ));
        assert!(SourceCrs::from_header("WGS84 UTM 61N").is_err());
        assert!(SourceCrs::from_header("WGS84 UTM 32X").is_err());
        assert!(SourceCrs::from_header("+proj=nonsense").is_err());
    }

    #[test]
    fn geographic_to_utm_matches_the_projected_crs_itself() {
        // 45°N on zone 31's central meridian: the closed form of `utm_on_the_central_meridian`.
        let wgs = SourceCrs::from_header("WGS84").expect("valid");
        let zone31 = ProjectedCrs::utm(31, Hemisphere::North).expect("valid");
        let (e, n) = wgs.to_projected(3.0, 45.0, &zone31).expect("converts");
        assert!((e - 500_000.0).abs() < UTM_TOL_M);
        assert!((n - 0.9996 * 4_984_944.378).abs() < 0.01, "{n}");
        // Projected to projected: zone 31 → zone 32 agrees with going through lat/lon.
        let source = SourceCrs::Projected(zone31.clone());
        let zone32 = ProjectedCrs::utm(32, Hemisphere::North).expect("valid");
        let (e32, n32) = source.to_projected(e, n, &zone32).expect("converts");
        let (e_ref, n_ref) = zone32.from_lat_lon_deg(45.0, 3.0).expect("converts");
        assert!((e32 - e_ref).abs() < UTM_TOL_M && (n32 - n_ref).abs() < UTM_TOL_M);
        // Same CRS: identity.
        assert_eq!(source.to_projected(e, n, &zone31).expect("same"), (e, n));
        let (lat, lon) = wgs.to_lat_lon_deg(3.0, 45.0).expect("converts");
        assert!((lat - 45.0).abs() < 1e-12 && (lon - 3.0).abs() < 1e-12);
        assert!(wgs.to_projected(3.0, 95.0, &zone31).is_err());
    }

    #[test]
    fn utm_zones() {
        assert_eq!(
            utm_zone_of(52.5, 13.4).expect("ok"),
            (33, Hemisphere::North)
        );
        assert_eq!(
            utm_zone_of(-33.9, 18.4).expect("ok"),
            (34, Hemisphere::South)
        );
        assert_eq!(
            utm_zone_of(0.0, -180.0).expect("ok"),
            (1, Hemisphere::North)
        );
        assert_eq!(
            utm_zone_of(0.0, 179.999).expect("ok"),
            (60, Hemisphere::North)
        );
        assert_eq!(utm_zone_of(0.0, 180.0).expect("ok"), (1, Hemisphere::North));
        assert_eq!(utm_zone_of(47.0, 9.0).expect("ok"), (32, Hemisphere::North));
        assert!(utm_zone_of(91.0, 0.0).is_err());
    }
}
