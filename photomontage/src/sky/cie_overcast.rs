//! The traditional CIE overcast sky (Moon & Spencer 1942; CIE 1955):
//! L(Z) = L_z·(1 + 2 cos Z)/3, hence E_h = (7π/9)·L_z and, for an unobstructed vertical plane,
//! E_v = (π/6 + 4/9)·L_z (`reference/lighting.md` §1.2, §1.4). Radiance `gensky -c` implements
//! the same (`skybright.cal`, `cloudysky`).
//!
//! # Known limitations
//! Azimuthally uniform by definition; zero below the horizon (Radiance blends to the ground
//! near the horizon, which moves its E_h 0.15 % below the closed form).

/// L/L_z of the traditional overcast sky at cos Z = `cos_zenith`; 0 below the horizon.
#[must_use]
pub fn relative_luminance(cos_zenith: f64) -> f64 {
    if cos_zenith > 0.0 {
        (1.0 + 2.0 * cos_zenith) / 3.0
    } else {
        0.0
    }
}

/// Closed-form E_h/L_z = 7π/9.
#[must_use]
pub fn horizontal_illuminance_over_zenith_luminance() -> f64 {
    7.0 * std::f64::consts::PI / 9.0
}

/// Closed-form E_v/L_z = π/6 + 4/9 for a vertical plane (sky only, no ground).
#[must_use]
pub fn vertical_illuminance_over_zenith_luminance() -> f64 {
    std::f64::consts::PI / 6.0 + 4.0 / 9.0
}
