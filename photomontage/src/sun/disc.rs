//! The solar disc: angular radius and solid angle Ω_s of the sun seen from the earth
//! (Durisch 1992 §3.3 and §4.1: "The solid angle Ω_s of incident sunlight is calculated from the
//! distance to the sun and the radius of the sun").
//!
//! A sphere of radius R seen from distance d subtends the cone of half-angle α = asin(R/d) and the
//! solid angle Ω = 2π(1 − cos α) (exact for a sphere). The solar radius is the IAU 2015 nominal
//! value (Resolution B3) and the astronomical unit the IAU 2012 value (Resolution B2).
//!
//! # Known limitations
//! The sun is treated as a uniform disc; limb darkening and the aureole are left to the sky model.

use super::SunError;

/// Nominal solar radius, IAU 2015 Resolution B3: 695 700 km.
pub const SUN_RADIUS_M: f64 = 6.957e8;

/// The astronomical unit in metres (IAU 2012 Resolution B2, exact).
#[must_use]
pub const fn astronomical_unit_m() -> f64 {
    149_597_870_700.0
}

/// Angular radius α = asin(R/d) of a sphere of radius `radius_m` at centre distance `distance_m`.
///
/// # Errors
/// [`SunError::OutOfRange`] when the radius is not positive or the distance is not larger than
/// the radius (the observer would be inside the sphere).
pub fn sun_angular_radius(distance_m: f64, radius_m: f64) -> Result<f64, SunError> {
    if !(radius_m > 0.0 && radius_m.is_finite()) {
        return Err(SunError::OutOfRange {
            name: "radius_m",
            value: radius_m,
            min: f64::MIN_POSITIVE,
            max: f64::MAX,
        });
    }
    if !(distance_m > radius_m && distance_m.is_finite()) {
        return Err(SunError::OutOfRange {
            name: "distance_m",
            value: distance_m,
            min: radius_m,
            max: f64::MAX,
        });
    }
    Ok((radius_m / distance_m).asin())
}

/// Solid angle Ω_s = 2π(1 − cos α) in steradians of a sphere of radius `radius_m` seen from
/// `distance_m` (centre to observer). For the sun use [`SUN_RADIUS_M`] and the earth–sun distance
/// from [`super::SolarPosition::earth_sun_distance_au`] × [`astronomical_unit_m`].
///
/// # Errors
/// As [`sun_angular_radius`].
pub fn sun_solid_angle_sr(distance_m: f64, radius_m: f64) -> Result<f64, SunError> {
    let alpha = sun_angular_radius(distance_m, radius_m)?;
    // 1 − cos α = 2 sin²(α/2), stable for the sun's tiny α.
    Ok(4.0 * std::f64::consts::PI * (alpha / 2.0).sin().powi(2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Closed forms evaluated in f64: only rounding separates them.
    const CLOSED_FORM_TOL: f64 = 1e-12;

    #[test]
    fn hemisphere_limit_and_45_degrees() {
        // d = R·√2 gives α = 45°, Ω = 2π(1 − √2/2).
        let omega = sun_solid_angle_sr(2.0_f64.sqrt(), 1.0).expect("valid");
        assert!((omega - 2.0 * PI * (1.0 - 0.5_f64.sqrt())).abs() < CLOSED_FORM_TOL);
        // d = 2R gives α = 30°, Ω = 2π(1 − √3/2).
        let omega = sun_solid_angle_sr(2.0, 1.0).expect("valid");
        assert!((omega - 2.0 * PI * (1.0 - 0.75_f64.sqrt())).abs() < CLOSED_FORM_TOL);
    }

    #[test]
    fn sun_at_one_au() {
        // Published mean angular semi-diameter of the sun at 1 AU: 959.63″ (Astronomical Almanac,
        // from R = 696 000 km); the IAU 2015 nominal radius 695 700 km is 0.043 % smaller, 0.41″.
        let alpha = sun_angular_radius(astronomical_unit_m(), SUN_RADIUS_M).expect("valid");
        let arcsec = alpha.to_degrees() * 3600.0;
        assert!((arcsec - (959.63 - 0.41)).abs() < 0.02, "{arcsec}");
        // Small-angle limit π(R/d)² ≈ 6.80e-5 sr.
        let omega = sun_solid_angle_sr(astronomical_unit_m(), SUN_RADIUS_M).expect("valid");
        let small = PI * (SUN_RADIUS_M / astronomical_unit_m()).powi(2);
        assert!((omega / small - 1.0).abs() < 1e-5);
        assert!((omega - 6.80e-5).abs() < 0.01e-5);
    }

    #[test]
    fn inside_the_sphere_is_an_error() {
        assert!(sun_solid_angle_sr(0.5, 1.0).is_err());
        assert!(sun_solid_angle_sr(2.0, -1.0).is_err());
        assert!(sun_solid_angle_sr(f64::NAN, 1.0).is_err());
    }
}
