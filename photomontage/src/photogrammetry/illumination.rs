//! Illumination geometry measured in the photos (Durisch 1992 §4.1, with the quantities of
//! §3.3): the zenith direction d̂_h from two points on one vertical edge, and the direction to
//! the sun d̂_s from an object point and the point where its shadow falls, both intersected in
//! space beforehand (e.g. with [`super::intersect`]).
//!
//! # Known limitations
//! The directions are only as good as the two 3-D points; their σ is not propagated here. The
//! sun is treated as a point at infinity (parallel light), as in Durisch.

use nalgebra::{Point3, Unit, Vector3};

/// Errors of the illumination-geometry helpers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IlluminationError {
    #[error("non-finite coordinate in {what}")]
    NonFinite { what: &'static str },
    #[error("the two points coincide ({separation_m} m apart): no direction")]
    Coincident { separation_m: f64 },
}

/// Points closer than this (metres) define no direction.
const MIN_SEPARATION_M: f64 = 1e-9;

fn direction(
    from: Point3<f64>,
    to: Point3<f64>,
    what: &'static str,
) -> Result<Unit<Vector3<f64>>, IlluminationError> {
    if !(from
        .coords
        .iter()
        .chain(to.coords.iter())
        .all(|v| v.is_finite()))
    {
        return Err(IlluminationError::NonFinite { what });
    }
    let d = to - from;
    let separation_m = d.norm();
    if separation_m <= MIN_SEPARATION_M {
        return Err(IlluminationError::Coincident { separation_m });
    }
    Ok(Unit::new_unchecked(d / separation_m))
}

/// Unit direction to the zenith (d̂_h) from the bottom and top of a vertical edge.
///
/// # Errors
/// Non-finite input or coincident points.
pub fn zenith_dir_from_vertical_edge(
    bottom: Point3<f64>,
    top: Point3<f64>,
) -> Result<Unit<Vector3<f64>>, IlluminationError> {
    direction(bottom, top, "vertical edge")
}

/// Unit direction towards the sun (d̂_s): from the shadow point through the object point that
/// casts it.
///
/// # Errors
/// Non-finite input or coincident points.
pub fn sun_dir_from_shadow(
    object_point: Point3<f64>,
    shadow_point: Point3<f64>,
) -> Result<Unit<Vector3<f64>>, IlluminationError> {
    direction(shadow_point, object_point, "object/shadow pair")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed-form directions are exact up to one rounding of a normalisation.
    const DIRECTION_TOLERANCE: f64 = 1e-12;

    #[test]
    fn zenith_of_a_tilted_edge() {
        let z =
            zenith_dir_from_vertical_edge(Point3::new(1.0, 2.0, 0.0), Point3::new(1.0, 5.0, 4.0))
                .expect("distinct");
        assert!((z.into_inner() - Vector3::new(0.0, 0.6, 0.8)).norm() < DIRECTION_TOLERANCE);
    }

    #[test]
    fn sun_at_known_elevation_and_azimuth() {
        // A 10 m pole at the origin; the sun at elevation 30°, azimuth 135° (south-east, x east,
        // y north): the shadow tip lies 10/tan 30° m away, opposite the sun.
        let (elevation, azimuth) = (30.0_f64.to_radians(), 135.0_f64.to_radians());
        let length = 10.0 / elevation.tan();
        let shadow = Point3::new(-length * azimuth.sin(), -length * azimuth.cos(), 0.0);
        let sun = sun_dir_from_shadow(Point3::new(0.0, 0.0, 10.0), shadow).expect("distinct");
        let expected = Vector3::new(
            elevation.cos() * azimuth.sin(),
            elevation.cos() * azimuth.cos(),
            elevation.sin(),
        );
        assert!((sun.into_inner() - expected).norm() < DIRECTION_TOLERANCE);
    }

    #[test]
    fn bad_input_is_an_error() {
        let p = Point3::new(1.0, 1.0, 1.0);
        assert!(matches!(
            zenith_dir_from_vertical_edge(p, p),
            Err(IlluminationError::Coincident { .. })
        ));
        assert!(matches!(
            sun_dir_from_shadow(Point3::new(f64::NAN, 0.0, 0.0), p),
            Err(IlluminationError::NonFinite { .. })
        ));
    }
}
