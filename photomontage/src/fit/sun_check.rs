//! Cross-check of the sun: the direction measured in the photos from an object point and the
//! point where its shadow falls (Durisch 1992 §4.1, d̂_s; [`crate::photogrammetry::
//! sun_dir_from_shadow`]) against the NREL SPA sun (Reda & Andreas 2004, [`crate::sun`]) for the
//! photo's time at the site's location, turned into the survey frame by the grid convergence
//! (survey +Y = grid north, Z up; true north lies `grid_convergence_deg` clockwise of grid north).
//!
//! A disagreement above the tolerance (default [`DEFAULT_TOLERANCE_DEG`]) is reported with the
//! camera-clock offset that would explain it, found by searching ±12 h (1-minute steps, then
//! 1-second steps around the best), when one brings the angle under the tolerance: wrong camera
//! clocks (time zone, daylight saving, never set) are the common cause.
//!
//! # Known limitations
//! The measured direction is only as good as the two intersected points (a 5 cm error on a 5 m
//! shadow is ≈ 0.6°); their σ is not propagated. A clock offset cannot explain a sun outside the
//! day's path (a wrong date, location or shadow pair): then no offset is suggested.

use chrono::{DateTime, Duration, FixedOffset};
use nalgebra::{Point3, Vector3};

use crate::photogrammetry::illumination::{IlluminationError, sun_dir_from_shadow};
use crate::sun::{SolarPosition, SpaParams, SunError, solar_position};

/// Angle between measured and computed sun above which the check warns: 2°, well above the
/// direction error of a surveyed shadow pair (≲ 1°) and below the 4 minutes of sun motion per
/// degree that a wrong clock produces in a quarter of an hour.
pub const DEFAULT_TOLERANCE_DEG: f64 = 2.0;

/// Half-width of the clock-offset search.
pub const CLOCK_SEARCH_S: i64 = 12 * 3600;

/// Errors of the sun check.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SunCheckError {
    /// The object/shadow pair defines no direction.
    #[error("object/shadow pair: {0}")]
    Geometry(#[from] IlluminationError),
    /// The SPA refused the time or location.
    #[error("sun position: {0}")]
    Sun(#[from] SunError),
}

/// Result of one cross-check.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SunCheck {
    /// Sun direction from the shadow pair, survey frame.
    pub measured_dir_in_world: [f64; 3],
    /// SPA sun direction at the stated time, survey frame.
    pub spa_dir_in_world: [f64; 3],
    /// SPA elevation, degrees (refraction included).
    pub spa_elevation_deg: f64,
    /// SPA azimuth east of true north, degrees.
    pub spa_azimuth_deg: f64,
    /// Angle between the two, degrees.
    pub angle_deg: f64,
    /// The tolerance used.
    pub tolerance_deg: f64,
    /// The clock correction (seconds to add to the stated time) that best explains the measured
    /// direction, when it brings the angle under the tolerance and the stated time does not.
    pub clock_offset_s: Option<i64>,
    /// The angle at that corrected time, degrees.
    pub angle_at_offset_deg: Option<f64>,
}

impl SunCheck {
    /// Whether the measured and computed suns agree within the tolerance.
    #[must_use]
    pub fn agrees(&self) -> bool {
        self.angle_deg <= self.tolerance_deg
    }

    /// The warning text, `None` when they agree.
    #[must_use]
    pub fn warning(&self, pair: &str) -> Option<String> {
        if self.agrees() {
            return None;
        }
        Some(match (self.clock_offset_s, self.angle_at_offset_deg) {
            (Some(off), Some(a)) => format!(
                "sun check `{pair}`: the shadow gives a sun {:.1}° from the SPA sun at the photo's \
                 time (tolerance {:.1}°); a camera clock {} by {} would explain it ({a:.2}° then)",
                self.angle_deg,
                self.tolerance_deg,
                if off > 0 { "slow" } else { "fast" },
                hms(off.unsigned_abs()),
            ),
            _ => format!(
                "sun check `{pair}`: the shadow gives a sun {:.1}° from the SPA sun at the photo's \
                 time (tolerance {:.1}°) and no clock offset within ±12 h explains it: check the \
                 object/shadow points, the date and the site location",
                self.angle_deg, self.tolerance_deg
            ),
        })
    }
}

fn hms(s: u64) -> String {
    format!("{}h{:02}m{:02}s", s / 3600, (s / 60) % 60, s % 60)
}

/// The SPA direction in the survey frame (x grid east, y grid north, z up).
fn sun_dir_in_survey(position: &SolarPosition, grid_convergence_deg: f64) -> Vector3<f64> {
    crate::site::render::survey_dir_from_true_azimuth(
        position.azimuth_deg,
        position.elevation_deg,
        grid_convergence_deg,
    )
}

fn angle_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.angle(b).to_degrees()
}

/// Compares the sun from the object/shadow pair with the SPA sun at `time`.
///
/// # Errors
/// [`SunCheckError`] for a degenerate pair or an SPA input out of range.
pub fn check_sun(
    object_point: Point3<f64>,
    shadow_point: Point3<f64>,
    time: &DateTime<FixedOffset>,
    params: &SpaParams,
    grid_convergence_deg: f64,
    tolerance_deg: f64,
) -> Result<SunCheck, SunCheckError> {
    let measured = sun_dir_from_shadow(object_point, shadow_point)?.into_inner();
    let at = |offset_s: i64| -> Result<(f64, SolarPosition), SunError> {
        let t = *time + Duration::seconds(offset_s);
        let p = solar_position(&t, params)?;
        Ok((
            angle_deg(&measured, &sun_dir_in_survey(&p, grid_convergence_deg)),
            p,
        ))
    };
    let (angle, position) = at(0)?;
    let mut check = SunCheck {
        measured_dir_in_world: measured.into(),
        spa_dir_in_world: sun_dir_in_survey(&position, grid_convergence_deg).into(),
        spa_elevation_deg: position.elevation_deg,
        spa_azimuth_deg: position.azimuth_deg,
        angle_deg: angle,
        tolerance_deg,
        clock_offset_s: None,
        angle_at_offset_deg: None,
    };
    if check.agrees() {
        return Ok(check);
    }
    // Coarse search in minutes, then seconds around the best minute.
    let mut best = (0_i64, angle);
    for m in -(CLOCK_SEARCH_S / 60)..=(CLOCK_SEARCH_S / 60) {
        let a = at(m * 60)?.0;
        if a < best.1 {
            best = (m * 60, a);
        }
    }
    let centre = best.0;
    for s in -60..=60 {
        let a = at(centre + s)?.0;
        if a < best.1 {
            best = (centre + s, a);
        }
    }
    if best.1 <= tolerance_deg {
        check.clock_offset_s = Some(best.0);
        check.angle_at_offset_deg = Some(best.1);
    }
    Ok(check)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The SPA agrees with itself; the pair is built from its direction, so the only error is
    /// the rounding of the shadow construction.
    const SAME_SUN_DEG: f64 = 1e-9;

    fn pair_for(dir: &Vector3<f64>) -> (Point3<f64>, Point3<f64>) {
        // A 6 m pole at (100, 200, 0) in survey coordinates; the shadow of its tip on the ground.
        let top = Point3::new(100.0, 200.0, 6.0);
        let shadow = top - dir * (6.0 / dir.z);
        (top, shadow)
    }

    #[test]
    fn agrees_with_the_sun_it_was_built_from_and_finds_a_wrong_clock() {
        let params = SpaParams::at(47.37, 8.54);
        let true_time = DateTime::parse_from_rfc3339("2024-06-21T15:10:00+02:00").unwrap();
        let convergence = 1.2;
        let dir = sun_dir_in_survey(&solar_position(&true_time, &params).unwrap(), convergence);
        let (top, shadow) = pair_for(&dir);
        let ok = check_sun(
            top,
            shadow,
            &true_time,
            &params,
            convergence,
            DEFAULT_TOLERANCE_DEG,
        )
        .unwrap();
        assert!(ok.angle_deg < SAME_SUN_DEG && ok.agrees() && ok.warning("p").is_none());
        // The camera clock was left on winter time: the EXIF says 14:10.
        let exif_time = DateTime::parse_from_rfc3339("2024-06-21T14:10:00+02:00").unwrap();
        let bad = check_sun(
            top,
            shadow,
            &exif_time,
            &params,
            convergence,
            DEFAULT_TOLERANCE_DEG,
        )
        .unwrap();
        assert!(!bad.agrees(), "{bad:?}");
        // The sun moves 15°/h in hour angle: the offset is found to the second.
        assert_eq!(bad.clock_offset_s, Some(3600));
        let w = bad.warning("pole").unwrap();
        assert!(
            w.contains("pole") && w.contains("slow") && w.contains("1h00m00s"),
            "{w}"
        );
        // Ignoring the grid convergence turns the sun by 1.2°: within the 2° tolerance.
        let no_conv =
            check_sun(top, shadow, &true_time, &params, 0.0, DEFAULT_TOLERANCE_DEG).unwrap();
        assert!(
            (no_conv.angle_deg - 1.2 * dir.xy().norm()).abs() < 0.01,
            "{no_conv:?}"
        );
    }

    #[test]
    fn a_sun_off_the_days_path_has_no_offset() {
        let params = SpaParams::at(47.37, 8.54);
        let time = DateTime::parse_from_rfc3339("2024-06-21T12:00:00+02:00").unwrap();
        // A shadow pointing south: a sun in the north at 40° never happens at 47° N.
        let dir = crate::sky::direction_from_elevation_azimuth(40_f64.to_radians(), 0.0);
        let (top, shadow) = pair_for(&dir);
        let c = check_sun(top, shadow, &time, &params, 0.0, DEFAULT_TOLERANCE_DEG).unwrap();
        assert!(c.clock_offset_s.is_none());
        assert!(c.warning("x").unwrap().contains("no clock offset"));
        assert!(matches!(
            check_sun(top, top, &time, &params, 0.0, 2.0),
            Err(SunCheckError::Geometry(_))
        ));
    }
}
