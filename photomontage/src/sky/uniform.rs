//! The uniform sky: constant luminance over the upper hemisphere, E_h = π·L (CIE S 011 type 5
//! has the same distribution; Radiance `gensky -u`).
//!
//! # Known limitations
//! Zero below the horizon; no ground.

/// L/L_z of the uniform sky: 1 above the horizon, 0 below.
#[must_use]
pub fn relative_luminance(cos_zenith: f64) -> f64 {
    if cos_zenith > 0.0 { 1.0 } else { 0.0 }
}
