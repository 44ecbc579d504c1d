//! A sample's colour read robustly from a photo (Durisch 1992 §4.2–4.3: "Lᵢ is derived from the
//! RGB triplet of the reconstructed image function at pᵢ′"): the per-channel median over a small
//! square window, with clipped and underexposed pixels rejected and counted, converted to linear
//! units (sRGB-encoded photos are decoded, EXR photos are linear already).
//!
//! Pixel convention of the project: (0, 0) is the centre of the top-left pixel, so the window of
//! a sample at (x, y) is centred on pixel (round x, round y).
//!
//! # Known limitations
//! The photo's tone curve is assumed to be sRGB for 8-bit files (a camera's own curve, or an
//! exposure/white-balance change between photos, is not undone). The median is per channel, so
//! the result need not be the colour of one pixel.

use crate::photo::{PhotoImage, Transfer};

/// Errors reading a sample colour.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ColourError {
    /// The window centre lies outside the photo.
    #[error("pixel ({x_px:.1}, {y_px:.1}) lies outside the {width}×{height} photo")]
    OutsideImage {
        /// Requested x.
        x_px: f64,
        /// Requested y.
        y_px: f64,
        /// Photo width.
        width: u32,
        /// Photo height.
        height: u32,
    },
    /// Too few usable pixels in the window.
    #[error(
        "only {used} of {total} pixels usable ({saturated} saturated, {underexposed} underexposed)"
    )]
    TooFewUsable {
        /// Usable pixels.
        used: usize,
        /// Pixels in the window (inside the photo).
        total: usize,
        /// Rejected as saturated.
        saturated: usize,
        /// Rejected as underexposed.
        underexposed: usize,
    },
    /// A window size of 0 or above [`MAX_WINDOW_PX`].
    #[error("window of {window_px} px is outside 1…{max}", max = MAX_WINDOW_PX)]
    InvalidWindow {
        /// Size given.
        window_px: u32,
    },
}

/// Largest window edge accepted (bounds the work per sample).
pub const MAX_WINDOW_PX: u32 = 101;

/// How pixels are accepted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColourReadOptions {
    /// Encoded value (0–1 of the full code range) at or above which a channel counts as clipped,
    /// for sRGB-encoded photos: 0.98 (≥ 250 of 255).
    pub saturated_code: f32,
    /// Encoded value at or below which a channel counts as underexposed (sRGB photos):
    /// 0.02 (≤ 5 of 255), where quantisation dominates the colour.
    pub underexposed_code: f32,
    /// Linear value at or above which a channel of a float (EXR) photo counts as clipped;
    /// `None` accepts every finite value.
    pub linear_saturation: Option<f32>,
    /// Smallest fraction of the window that must be usable.
    pub min_usable_fraction: f64,
}

impl Default for ColourReadOptions {
    fn default() -> Self {
        Self {
            saturated_code: 0.98,
            underexposed_code: 0.02,
            linear_saturation: None,
            min_usable_fraction: 0.5,
        }
    }
}

/// A colour read from a window.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ColourRead {
    /// Median colour, linear RGB.
    pub linear_rgb: [f64; 3],
    /// Pixels used.
    pub used_px: usize,
    /// Pixels rejected as saturated.
    pub saturated_px: usize,
    /// Pixels rejected as underexposed.
    pub underexposed_px: usize,
}

fn median(v: &mut [f32]) -> f64 {
    v.sort_by(f32::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        f64::from(v[n / 2])
    } else {
        0.5 * (f64::from(v[n / 2 - 1]) + f64::from(v[n / 2]))
    }
}

/// Reads the rectangle `[x0, x0 + w) × [y0, y0 + h)` (clipped to the photo), see the module doc.
///
/// # Errors
/// [`ColourError::TooFewUsable`] when less than the minimum fraction is usable (or the rectangle
/// misses the photo).
pub fn read_rect(
    photo: &PhotoImage,
    origin_px: [i64; 2],
    size_px: [u32; 2],
    options: &ColourReadOptions,
) -> Result<ColourRead, ColourError> {
    let (w, h) = (
        i64::from(photo.pixels.width()),
        i64::from(photo.pixels.height()),
    );
    let x_range = origin_px[0].max(0)..(origin_px[0] + i64::from(size_px[0])).min(w);
    let y_range = origin_px[1].max(0)..(origin_px[1] + i64::from(size_px[1])).min(h);
    let mut channels: [Vec<f32>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    let (mut total, mut saturated, mut underexposed) = (0, 0, 0);
    for y in y_range {
        for x in x_range.clone() {
            total += 1;
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let p = photo.pixels.get_pixel(x as u32, y as u32).0;
            let clipped = match photo.transfer {
                Transfer::Srgb => p.iter().any(|c| *c >= options.saturated_code),
                Transfer::Linear => {
                    p.iter().any(|c| !c.is_finite())
                        || options
                            .linear_saturation
                            .is_some_and(|s| p.iter().any(|c| *c >= s))
                }
            };
            if clipped {
                saturated += 1;
                continue;
            }
            if photo.transfer == Transfer::Srgb && p.iter().any(|c| *c <= options.underexposed_code)
            {
                underexposed += 1;
                continue;
            }
            for k in 0..3 {
                channels[k].push(p[k]);
            }
        }
    }
    let used = channels[0].len();
    #[allow(clippy::cast_precision_loss)]
    if used == 0 || (used as f64) < options.min_usable_fraction * total as f64 {
        return Err(ColourError::TooFewUsable {
            used,
            total,
            saturated,
            underexposed,
        });
    }
    let encoded = channels.map(|mut c| median(&mut c));
    let linear_rgb = match photo.transfer {
        Transfer::Srgb => encoded.map(crate::colour::rgb::srgb_decode),
        Transfer::Linear => encoded,
    };
    Ok(ColourRead {
        linear_rgb,
        used_px: used,
        saturated_px: saturated,
        underexposed_px: underexposed,
    })
}

/// Reads the `window_px` × `window_px` window centred on pixel `(x_px, y_px)`.
///
/// # Errors
/// [`ColourError::InvalidWindow`], [`ColourError::OutsideImage`], [`ColourError::TooFewUsable`].
pub fn read_window(
    photo: &PhotoImage,
    centre_px: [f64; 2],
    window_px: u32,
    options: &ColourReadOptions,
) -> Result<ColourRead, ColourError> {
    if window_px == 0 || window_px > MAX_WINDOW_PX {
        return Err(ColourError::InvalidWindow { window_px });
    }
    let [width, height] = photo.size_px();
    let (cx, cy) = (centre_px[0].round(), centre_px[1].round());
    if !(cx >= 0.0 && cy >= 0.0 && cx < f64::from(width) && cy < f64::from(height)) {
        return Err(ColourError::OutsideImage {
            x_px: centre_px[0],
            y_px: centre_px[1],
            width,
            height,
        });
    }
    let half = i64::from(window_px / 2);
    #[allow(clippy::cast_possible_truncation)]
    let origin = [cx as i64 - half, cy as i64 - half];
    read_rect(photo, origin, [window_px, window_px], options)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{Rgb, Rgb32FImage};

    fn photo(f: impl Fn(u32, u32) -> [f32; 3], transfer: Transfer) -> PhotoImage {
        PhotoImage {
            pixels: Rgb32FImage::from_fn(20, 10, |x, y| Rgb(f(x, y))),
            transfer,
        }
    }

    #[test]
    fn median_rejects_a_specular_glint_and_linearises() {
        // 0.5 encoded everywhere, one clipped pixel and one dark speck in the window.
        let p = photo(
            |x, y| match (x, y) {
                (5, 5) => [1.0, 1.0, 1.0],
                (6, 4) => [0.0, 0.0, 0.0],
                _ => [0.5, 0.5, 0.5],
            },
            Transfer::Srgb,
        );
        let c = read_window(&p, [5.2, 4.8], 5, &ColourReadOptions::default()).unwrap();
        assert_eq!((c.used_px, c.saturated_px, c.underexposed_px), (23, 1, 1));
        // sRGB 0.5 decodes to 0.214041 (IEC 61966-2-1).
        for v in c.linear_rgb {
            assert!((v - 0.214_041).abs() < 1e-6, "{v}");
        }
    }

    #[test]
    fn a_mostly_clipped_window_is_refused_with_counts() {
        let p = photo(
            |x, _| if x < 8 { [0.99, 0.5, 0.5] } else { [0.5; 3] },
            Transfer::Srgb,
        );
        let err = read_window(&p, [5.0, 5.0], 5, &ColourReadOptions::default()).unwrap_err();
        assert_eq!(
            err,
            ColourError::TooFewUsable {
                used: 0,
                total: 25,
                saturated: 25,
                underexposed: 0
            }
        );
        assert!(matches!(
            read_window(&p, [25.0, 5.0], 5, &ColourReadOptions::default()),
            Err(ColourError::OutsideImage { .. })
        ));
        assert!(matches!(
            read_window(&p, [5.0, 5.0], 0, &ColourReadOptions::default()),
            Err(ColourError::InvalidWindow { window_px: 0 })
        ));
    }

    #[test]
    fn linear_photos_are_not_decoded_and_use_the_float_threshold() {
        let p = photo(
            |x, _| if x == 3 { [50.0; 3] } else { [0.25, 0.5, 2.0] },
            Transfer::Linear,
        );
        let opts = ColourReadOptions {
            linear_saturation: Some(10.0),
            ..ColourReadOptions::default()
        };
        let c = read_window(&p, [3.0, 5.0], 3, &opts).unwrap();
        // Exact: the median of equal f32 values, widened to f64.
        assert_eq!(
            c.linear_rgb.map(f64::to_bits),
            [0.25_f64, 0.5, 2.0].map(f64::to_bits)
        );
        assert_eq!(c.saturated_px, 3);
    }
}
