//! Fisheye sky luminance map as an 8-bit sRGB image (for the studio and the documentation).
//!
//! Projection: equidistant (angular) fisheye looking up at the zenith, r = (Z / 90°)·R with R half
//! the image size; north at the top and, as seen from below, east on the left (x_px grows to the
//! west). Pixels outside the horizon circle are black.
//!
//! Tone map (documented so images are comparable): with x = L/(2·L_z), the displayed linear
//! value is Reinhard's x/(1 + x) (the zenith shows at 1/3, the bright circumsolar region
//! approaches 1), then the sRGB transfer function (IEC 61966-2-1) and rounding to 8 bits; the map
//! is grey (R = G = B).
//!
//! # Known limitations
//! Luminance only (no colour); one sample per pixel centre (no anti-aliasing at the horizon).

use super::{SkyError, SkyModel};
use image::{Rgb, RgbImage};
use nalgebra::Vector3;
use std::f64::consts::FRAC_PI_2;

/// Largest accepted map size in pixels.
pub const MAX_MAP_SIZE_PX: u32 = 8192;

/// sRGB encoding of a linear value in 0…1.
fn srgb_encode(linear: f64) -> f64 {
    let v = linear.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Display value (0…255) of a relative luminance L/L_z under the documented tone map.
#[must_use]
pub fn tone_map(relative_luminance: f64) -> u8 {
    let x = (relative_luminance / 2.0).max(0.0);
    let display = srgb_encode(x / (1.0 + x));
    // In 0…255 by the clamp in srgb_encode.
    (display * 255.0).round() as u8
}

/// Direction (unit, z up, x east, y north) seen at pixel (`x_px`, `y_px`) of a `size_px` map,
/// or `None` outside the horizon circle.
#[must_use]
pub fn direction_at_pixel(x_px: u32, y_px: u32, size_px: u32) -> Option<Vector3<f64>> {
    let half = f64::from(size_px) / 2.0;
    // Offsets from the centre, in units of the horizon radius; +u = west, +v = north.
    let u = (f64::from(x_px) + 0.5 - half) / half;
    let v = (half - (f64::from(y_px) + 0.5)) / half;
    let r = (u * u + v * v).sqrt();
    if r > 1.0 {
        return None;
    }
    let zenith = r * FRAC_PI_2;
    let (sin_z, cos_z) = zenith.sin_cos();
    if r == 0.0 {
        return Some(Vector3::z());
    }
    Some(Vector3::new(-u / r * sin_z, v / r * sin_z, cos_z))
}

/// Renders the fisheye map of `model` with the sun in `sun_dir_in_world`.
///
/// # Errors
/// [`SkyError::InvalidImageSize`] for a size of 0 or above [`MAX_MAP_SIZE_PX`].
pub fn sky_map(
    model: &SkyModel,
    sun_dir_in_world: &Vector3<f64>,
    size_px: u32,
) -> Result<RgbImage, SkyError> {
    if size_px == 0 || size_px > MAX_MAP_SIZE_PX {
        return Err(SkyError::InvalidImageSize {
            size_px,
            max_px: MAX_MAP_SIZE_PX,
        });
    }
    Ok(RgbImage::from_fn(size_px, size_px, |x, y| {
        let value = direction_at_pixel(x, y, size_px).map_or(0, |dir| {
            tone_map(model.relative_luminance(&dir, sun_dir_in_world))
        });
        Rgb([value, value, value])
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::direction_from_elevation_azimuth;

    #[test]
    fn geometry_and_tone_map() {
        // Centre pixel of an odd-sized map looks at the zenith.
        let d = direction_at_pixel(50, 50, 101).expect("inside");
        assert!((d.z - 1.0).abs() < 1e-12);
        // Top-centre pixel looks north near the horizon, left-middle east.
        let north = direction_at_pixel(50, 0, 101).expect("inside");
        assert!(north.y > 0.99 && north.z < 0.02);
        let east = direction_at_pixel(0, 50, 101).expect("inside");
        assert!(east.x > 0.99);
        assert!(direction_at_pixel(0, 0, 101).is_none());
        // Zenith luminance shows at linear 1/3: sRGB(1/3) = 1.055·(1/3)^(1/2.4) − 0.055 = 0.6127,
        // × 255 = 156.2 → 156.
        assert_eq!(tone_map(1.0), 156);
        assert_eq!(tone_map(0.0), 0);
    }

    #[test]
    fn map_of_clear_sky_is_brightest_towards_the_sun() {
        let sun = direction_from_elevation_azimuth(30_f64.to_radians(), 90_f64.to_radians());
        let model = SkyModel::cie_general(12).expect("valid");
        let img = sky_map(&model, &sun, 64).expect("valid size");
        // Sun in the east is on the left half of the image.
        let left: u64 = (0..32)
            .flat_map(|x| (0..64).map(move |y| (x, y)))
            .map(|(x, y)| u64::from(img.get_pixel(x, y)[0]))
            .sum();
        let right: u64 = (32..64)
            .flat_map(|x| (0..64).map(move |y| (x, y)))
            .map(|(x, y)| u64::from(img.get_pixel(x, y)[0]))
            .sum();
        assert!(left > right);
        assert!(sky_map(&model, &sun, 0).is_err());
    }
}
