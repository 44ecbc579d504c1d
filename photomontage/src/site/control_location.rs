//! The site's `[location]` from its control points, for a site whose location is still empty
//! (issue 15): the centroid of the control points in the projected survey CRS is converted to
//! WGS 84 latitude and longitude ([`crate::geo::ProjectedCrs`], proj4rs), the grid convergence is
//! computed there ([`ProjectedCrs::grid_convergence_deg`]) and the CRS is named as the site file
//! names it (`EPSG:326NN` for a UTM zone). The sun position (NREL SPA) needs only latitude and
//! longitude to a few hundredths of a degree: a centroid is exact enough for any site.
//!
//! A geographic control list (WGS 84) is first reprojected into its centroid's UTM zone
//! ([`crate::photogrammetry::control_io::OdmGcpList::reprojected`]); the location then names that
//! zone, so later imports and the solve use the same grid.
//!
//! # Known limitations
//! `elevation_m` is the mean control height as given: a GPS list's heights are ellipsoidal or in
//! whatever vertical frame the list used (OpenSfM's `berlin` list has the square at ≈ 0 m), so
//! the elevation is only as good as that frame; the SPA's refraction term is insensitive to it.
//! Disabled control points are left out; control points with their own `crs` are left out too
//! (they are not in the site's grid).

use super::{ControlPoint, Location};
use crate::geo::{GeoError, ProjectedCrs};

/// Errors of [`location_from_control`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControlLocationError {
    /// No enabled control point in the site's grid.
    #[error("no enabled control point in the site's grid to place the site by")]
    NoControl,
    /// The centroid cannot be converted to latitude/longitude.
    #[error("the control points' centroid ({easting_m:.3}, {northing_m:.3}) in {crs}: {source}")]
    Conversion {
        /// Centroid easting.
        easting_m: f64,
        /// Centroid northing.
        northing_m: f64,
        /// Name of the CRS.
        crs: String,
        /// What the conversion said.
        source: GeoError,
    },
}

/// The location of a site whose enabled control points (those without a `crs` of their own) are
/// in `crs`, named `crs_name` in the site file: [`location_from_points`] of their coordinates.
///
/// # Errors
/// As [`location_from_points`].
pub fn location_from_control(
    control_points: &[ControlPoint],
    crs: &ProjectedCrs,
    crs_name: &str,
) -> Result<Location, ControlLocationError> {
    let points: Vec<[f64; 3]> = control_points
        .iter()
        .filter(|c| c.enabled && c.crs.is_none())
        .map(|c| c.xyz)
        .collect();
    location_from_points(&points, crs, crs_name)
}

/// The location of a site from points in `crs` (named `crs_name` in the site file): latitude and
/// longitude of their centroid, their mean height, the grid convergence at the centroid.
/// Non-finite points are left out.
///
/// # Errors
/// [`ControlLocationError::NoControl`] without usable points,
/// [`ControlLocationError::Conversion`] when the centroid lies outside the projection.
pub fn location_from_points(
    points_in_world: &[[f64; 3]],
    crs: &ProjectedCrs,
    crs_name: &str,
) -> Result<Location, ControlLocationError> {
    let used: Vec<&[f64; 3]> = points_in_world
        .iter()
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    if used.is_empty() {
        return Err(ControlLocationError::NoControl);
    }
    #[allow(clippy::cast_precision_loss)] // a site holds far fewer than 2^52 points
    let count = used.len() as f64;
    let sum = used
        .iter()
        .fold([0.0; 3], |s, p| [s[0] + p[0], s[1] + p[1], s[2] + p[2]]);
    let [easting_m, northing_m, height_m] = sum.map(|v| v / count);
    let fail = |source| ControlLocationError::Conversion {
        easting_m,
        northing_m,
        crs: crs_name.to_owned(),
        source,
    };
    let (latitude_deg, longitude_deg) = crs.to_lat_lon_deg(easting_m, northing_m).map_err(fail)?;
    let grid_convergence_deg = crs
        .grid_convergence_deg(easting_m, northing_m)
        .map_err(fail)?;
    Ok(Location {
        latitude_deg,
        longitude_deg,
        elevation_m: height_m,
        crs: Some(crs_name.to_owned()),
        grid_convergence_deg,
        time_zone: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// proj4rs round trip of a centroid: far below a millimetre, i.e. 1e-8°.
    const ROUND_TRIP_DEG: f64 = 1e-8;
    /// UTM grid convergence closed form γ = atan(tan(λ−λ₀)·sin φ) (spherical, Snyder 1987
    /// eq. 8-14 leading term); the ellipsoidal terms add < 0.001° at 52° N, 1.6° from the
    /// central meridian.
    const CONVERGENCE_CLOSED_FORM_DEG: f64 = 2e-3;

    fn point(id: &str, xyz: [f64; 3]) -> ControlPoint {
        ControlPoint {
            id: id.into(),
            xyz,
            sigma_m: [0.01; 3],
            crs: None,
            enabled: true,
        }
    }

    #[test]
    fn centroid_of_utm_control_gives_latitude_longitude_and_convergence() {
        let zone33 = ProjectedCrs::from_name("EPSG:32633").expect("valid");
        // Two points around the Berliner Dom portal, whose centroid is 52.5192 N 13.4006 E.
        let (e, n) = zone33.from_lat_lon_deg(52.5192, 13.4006).expect("converts");
        let mut points = vec![
            point("a", [e - 10.0, n + 4.0, 2.0]),
            point("b", [e + 10.0, n - 4.0, 6.0]),
            // Left out: disabled, and in another CRS.
            ControlPoint {
                enabled: false,
                ..point("c", [e + 900.0, n, 100.0])
            },
            ControlPoint {
                crs: Some("EPSG:2056".into()),
                ..point("d", [2_600_000.0, 1_200_000.0, 400.0])
            },
        ];
        let loc = location_from_control(&points, &zone33, "EPSG:32633").expect("location");
        assert!(
            (loc.latitude_deg - 52.5192).abs() < ROUND_TRIP_DEG,
            "{loc:?}"
        );
        assert!(
            (loc.longitude_deg - 13.4006).abs() < ROUND_TRIP_DEG,
            "{loc:?}"
        );
        assert!((loc.elevation_m - 4.0).abs() < 1e-12);
        assert_eq!(loc.crs.as_deref(), Some("EPSG:32633"));
        // West of the central meridian 15° E in the north the meridians lean east towards it:
        // true north lies clockwise of grid north, so the site file's convergence is positive
        // (the negative of the textbook γ, which is measured from true to grid north).
        let closed_form = -((13.4006_f64 - 15.0).to_radians().tan()
            * 52.5192_f64.to_radians().sin())
        .atan()
        .to_degrees();
        assert!(
            (loc.grid_convergence_deg - closed_form).abs() < CONVERGENCE_CLOSED_FORM_DEG,
            "{} vs {closed_form}",
            loc.grid_convergence_deg
        );
        for p in &mut points {
            p.enabled = false;
        }
        assert_eq!(
            location_from_control(&points, &zone33, "EPSG:32633"),
            Err(ControlLocationError::NoControl)
        );
    }

    #[test]
    fn a_centroid_outside_the_projection_is_named() {
        let zone33 = ProjectedCrs::from_name("EPSG:32633").expect("valid");
        let e = location_from_control(&[point("x", [f64::MAX / 2.0, 1e300, 0.0])], &zone33, "z")
            .expect_err("outside");
        assert!(e.to_string().contains("centroid"), "{e}");
    }
}
