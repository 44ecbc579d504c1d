//! Polar intensity diagram (the usual luminaire data-sheet plot) rendered to an RGB image.
//!
//! Convention (as in EULUMDAT/Relux data sheets): nadir (γ = 0) points down, γ = 180° up; the
//! C0–C180 curve is red with C0 on the right half, the C90–C270 curve is blue with C90 on the
//! right. Grey circles mark 1/4, 1/2, 3/4 and 1 of the scale, which is the maximum intensity
//! rounded up to 1, 2 or 5 × 10ⁿ cd; that scale value is printed (digits only, in cd) in the
//! top-left corner with a built-in 3 × 5 pixel font. Radial lines every 30°.
//!
//! # Known limitations
//! No anti-aliasing, no axis captions other than the scale value, cd only (not cd/klm).

use super::distribution::PhotometricWeb;
use image::{Rgb, RgbImage};
use std::path::Path;
use thiserror::Error;

/// Why a plot could not be written.
#[derive(Debug, Error)]
pub enum PolarPlotError {
    /// Image size out of range.
    #[error("plot size {size_px} px is outside 64..=8192")]
    BadSize {
        /// Requested size.
        size_px: u32,
    },
    /// PNG encoding or writing failed.
    #[error("cannot write {path}: {message}")]
    Write {
        /// Output path.
        path: String,
        /// Encoder message.
        message: String,
    },
}

/// Plot settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolarPlotOptions {
    /// Width and height of the square image (px).
    pub size_px: u32,
    /// Intensity at the outer circle (cd); `None` rounds the maximum up to 1/2/5 × 10ⁿ.
    pub scale_cd: Option<f64>,
}

impl Default for PolarPlotOptions {
    fn default() -> Self {
        Self {
            size_px: 512,
            scale_cd: None,
        }
    }
}

/// Colour of the C0–C180 curve.
pub const C0_C180_COLOUR: Rgb<u8> = Rgb([200, 30, 30]);
/// Colour of the C90–C270 curve.
pub const C90_C270_COLOUR: Rgb<u8> = Rgb([30, 60, 200]);
const GRID: Rgb<u8> = Rgb([190, 190, 190]);
const TEXT: Rgb<u8> = Rgb([0, 0, 0]);

/// The smallest 1, 2 or 5 × 10ⁿ not below `value` (1 for non-positive input).
#[must_use]
pub fn nice_scale(value: f64) -> f64 {
    if value.is_nan() || value <= 0.0 || value.is_infinite() {
        return 1.0;
    }
    let decade = 10f64.powf(value.log10().floor());
    for m in [1.0, 2.0, 5.0, 10.0] {
        let scale = m * decade;
        if scale >= value * (1.0 - 1e-12) {
            // Near f64::MAX the rounded scale overflows: keep the value itself.
            return if scale.is_finite() { scale } else { value };
        }
    }
    value
}

fn put(img: &mut RgbImage, x: f64, y: f64, colour: Rgb<u8>) {
    let (w, h) = img.dimensions();
    if x >= 0.0 && y >= 0.0 && x < f64::from(w) && y < f64::from(h) {
        img.put_pixel(x as u32, y as u32, colour);
    }
}

/// The part of the segment `from`–`to` inside the box `min`–`max` (Liang–Barsky), or `None`
/// when it misses the box or is not finite.
fn clip_to_box(
    from: (f64, f64),
    to: (f64, f64),
    min: (f64, f64),
    max: (f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (to.0 - from.0, to.1 - from.1);
    if ![from.0, from.1, dx, dy].iter().all(|v| v.is_finite()) {
        return None;
    }
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (p, q) in [
        (-dx, from.0 - min.0),
        (dx, max.0 - from.0),
        (-dy, from.1 - min.1),
        (dy, max.1 - from.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else if p < 0.0 {
            t0 = t0.max(q / p);
        } else {
            t1 = t1.min(q / p);
        }
    }
    (t0 <= t1).then_some((
        (from.0 + t0 * dx, from.1 + t0 * dy),
        (from.0 + t1 * dx, from.1 + t1 * dy),
    ))
}

/// Draws a segment pixel by pixel. The segment is clipped to the image first, so the step
/// count is bounded by the image size whatever the intensities (1e308 cd once meant 10³⁰⁸
/// steps).
fn line(img: &mut RgbImage, from: (f64, f64), to: (f64, f64), colour: Rgb<u8>) {
    let (w, h) = img.dimensions();
    let Some((from, to)) = clip_to_box(
        from,
        to,
        (-1.0, -1.0),
        (f64::from(w) + 1.0, f64::from(h) + 1.0),
    ) else {
        return;
    };
    let steps = ((to.0 - from.0).abs().max((to.1 - from.1).abs()).ceil() as usize).max(1);
    for i in 0..=steps {
        let t = i as f64 / steps as f64;
        let x = from.0 + t * (to.0 - from.0);
        let y = from.1 + t * (to.1 - from.1);
        put(img, x, y, colour);
    }
}

/// 3 × 5 digit glyphs, one row per u8 (3 low bits, MSB left).
const DIGITS: [[u8; 5]; 10] = [
    [7, 5, 5, 5, 7],
    [2, 6, 2, 2, 7],
    [7, 1, 7, 4, 7],
    [7, 1, 7, 1, 7],
    [5, 5, 7, 1, 1],
    [7, 4, 7, 1, 7],
    [7, 4, 7, 5, 7],
    [7, 1, 1, 1, 1],
    [7, 5, 7, 5, 7],
    [7, 5, 7, 1, 7],
];

fn draw_number(img: &mut RgbImage, value: f64, x0: u32, y0: u32, pixel: u32) {
    let text = format!("{}", value.round() as i64);
    let mut x = x0;
    for ch in text.chars() {
        if let Some(d) = ch.to_digit(10) {
            for (row, bits) in DIGITS[d as usize].iter().enumerate() {
                for col in 0..3u32 {
                    if bits & (4 >> col) != 0 {
                        for dy in 0..pixel {
                            for dx in 0..pixel {
                                put(
                                    img,
                                    f64::from(x + col * pixel + dx),
                                    f64::from(y0 + row as u32 * pixel + dy),
                                    TEXT,
                                );
                            }
                        }
                    }
                }
            }
        }
        x += 4 * pixel;
    }
}

/// Draws the polar diagram of `web`.
///
/// # Errors
/// [`PolarPlotError::BadSize`] when the size is outside 64..=8192 px.
pub fn polar_plot(
    web: &PhotometricWeb,
    options: &PolarPlotOptions,
) -> Result<RgbImage, PolarPlotError> {
    let size = options.size_px;
    if !(64..=8192).contains(&size) {
        return Err(PolarPlotError::BadSize { size_px: size });
    }
    let mut img = RgbImage::from_pixel(size, size, Rgb([255, 255, 255]));
    let centre = f64::from(size) / 2.0;
    let radius_px = f64::from(size) * 0.45;
    let scale_cd = options
        .scale_cd
        .filter(|s| *s > 0.0 && s.is_finite())
        .unwrap_or_else(|| nice_scale(web.max_intensity_cd()));

    // Grid: circles and radial lines.
    for k in 1..=4 {
        let r = radius_px * f64::from(k) / 4.0;
        let n = (r * 8.0).ceil() as usize;
        for i in 0..n {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            put(&mut img, centre + r * a.cos(), centre + r * a.sin(), GRID);
        }
    }
    for k in 0..12 {
        let a = f64::from(k) * 30f64.to_radians();
        line(
            &mut img,
            (centre, centre),
            (centre + radius_px * a.sin(), centre + radius_px * a.cos()),
            GRID,
        );
    }

    // Curves: right half plane `c_right`, left half `c_left`, γ from nadir (down).
    let point = |c_deg: f64, gamma_deg: f64, right: bool| {
        let r = radius_px * web.intensity_c_gamma_cd(c_deg, gamma_deg) / scale_cd;
        let g = gamma_deg.to_radians();
        let side = if right { 1.0 } else { -1.0 };
        (centre + side * r * g.sin(), centre + r * g.cos())
    };
    for (c_right, c_left, colour) in [(0.0, 180.0, C0_C180_COLOUR), (90.0, 270.0, C90_C270_COLOUR)]
    {
        for (c, right) in [(c_right, true), (c_left, false)] {
            let mut prev = point(c, 0.0, right);
            for i in 1..=720 {
                let p = point(c, f64::from(i) * 0.25, right);
                line(&mut img, prev, p, colour);
                prev = p;
            }
        }
    }
    draw_number(&mut img, scale_cd, 4, 4, (size / 128).max(1));
    Ok(img)
}

/// Draws the polar diagram of `web` and writes it as a PNG.
///
/// # Errors
/// Bad size, or the PNG could not be written.
pub fn save_polar_plot_png(
    web: &PhotometricWeb,
    options: &PolarPlotOptions,
    path: &Path,
) -> Result<(), PolarPlotError> {
    let img = polar_plot(web, options)?;
    img.save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| PolarPlotError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::luminaire::{PhotometricType, Symmetry};
    use approx::assert_relative_eq;

    #[test]
    fn nice_scale_rounds_up_to_1_2_5() {
        assert_relative_eq!(nice_scale(2657.0), 5000.0);
        assert_relative_eq!(nice_scale(1500.0), 2000.0);
        assert_relative_eq!(nice_scale(1000.0), 1000.0);
        assert_relative_eq!(nice_scale(0.0), 1.0);
    }

    #[test]
    fn huge_intensities_plot_in_bounded_time() {
        // 1e308 cd with the automatic scale and with a 1 cd scale: the curve runs 10³⁰⁸ px off
        // the image; the plot must still return (it once looped for ever) and draw the part
        // inside the image.
        let g: Vec<f64> = (0..=36).map(|i| f64::from(i) * 5.0).collect();
        let web = PhotometricWeb::from_planes(
            PhotometricType::C,
            Symmetry::Axial,
            &[0.0],
            &g,
            &vec![1e308; g.len()],
        )
        .unwrap();
        for scale_cd in [None, Some(1.0)] {
            let start = std::time::Instant::now();
            let img = polar_plot(
                &web,
                &PolarPlotOptions {
                    size_px: 256,
                    scale_cd,
                },
            )
            .unwrap();
            assert!(start.elapsed().as_secs() < 10, "{:?}", start.elapsed());
            assert_eq!(img.dimensions(), (256, 256));
        }
        assert_relative_eq!(nice_scale(1.7e308), 1.7e308);
        assert!(nice_scale(f64::MAX).is_finite());
    }

    #[test]
    fn clipping_keeps_the_part_inside() {
        let clipped = clip_to_box((-10.0, 5.0), (20.0, 5.0), (0.0, 0.0), (10.0, 10.0));
        assert_eq!(clipped, Some(((0.0, 5.0), (10.0, 5.0))));
        assert_eq!(
            clip_to_box((-10.0, -5.0), (20.0, -5.0), (0.0, 0.0), (10.0, 10.0)),
            None
        );
        assert_eq!(
            clip_to_box((0.0, 0.0), (f64::INFINITY, 1.0), (0.0, 0.0), (10.0, 10.0)),
            None
        );
    }

    #[test]
    fn isotropic_source_draws_a_circle_at_its_scale_fraction() {
        // 100 cd everywhere, scale 200 cd: both curves lie on the half-radius grid circle.
        let g: Vec<f64> = (0..=36).map(|i| f64::from(i) * 5.0).collect();
        let web = PhotometricWeb::from_planes(
            PhotometricType::C,
            Symmetry::Axial,
            &[0.0],
            &g,
            &vec![100.0; g.len()],
        )
        .unwrap();
        let size = 400;
        let img = polar_plot(
            &web,
            &PolarPlotOptions {
                size_px: size,
                scale_cd: Some(200.0),
            },
        )
        .unwrap();
        let centre = f64::from(size) / 2.0;
        let r = f64::from(size) * 0.45 * 0.5;
        // Straight down (γ = 0) and straight sideways on the right (γ = 90°, C0 and C90 coincide;
        // the blue C90 curve is drawn last).
        let below = img.get_pixel(centre as u32, (centre + r) as u32);
        assert_ne!(*below, Rgb([255, 255, 255]));
        let right = img.get_pixel((centre + r) as u32, centre as u32);
        assert_eq!(*right, C90_C270_COLOUR);
        // Nothing coloured halfway between centre and the curve, off the grid lines.
        let inside = img.get_pixel((centre + 0.3 * r) as u32, (centre + 0.1 * r) as u32);
        assert_eq!(*inside, Rgb([255, 255, 255]));
        assert!(matches!(
            polar_plot(
                &web,
                &PolarPlotOptions {
                    size_px: 10,
                    scale_cd: None
                }
            ),
            Err(PolarPlotError::BadSize { size_px: 10 })
        ));
    }
}
