//! The accuracy measures of a montage of the shared Mitsuba pair (`bench/data/mitsuba/`): the box
//! rendered into the 1024-spp `without_box` photo, compared with the 1024-spp `with_box` truth
//! (`tests/render_mitsuba.rs`, `tests/render_mitsuba_radiosity.rs`).

use image::Rgb32FImage;

/// A shadow pixel: not covered by the box and at least this much darker (sum of channels) in
/// the truth than in the photo.
pub const SHADOW_DARKER_THAN: f64 = 0.8;

/// Mean relative errors of a montage against the truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairErrors {
    /// Pixels fully covered by the box (alpha 1).
    pub box_pixels: u32,
    /// Mean over box pixels of the channel-mean |ours − truth| / truth.
    pub box_mean_rel: f64,
    /// The same, signed.
    pub box_bias: f64,
    /// Pixels outside the box that the truth shows in its shadow.
    pub shadow_pixels: u32,
    /// Mean relative error over shadow pixels.
    pub shadow_mean_rel: f64,
    /// The same, signed.
    pub shadow_bias: f64,
    /// RMSE over all pixels and channels.
    pub rmse: f64,
}

/// Compares the montage `rgba` (row-major, alpha = box coverage) with `truth`, finding the
/// shadow pixels through `photo` (the scene without the box).
///
/// # Panics
/// When the images' sizes differ from `rgba`'s.
#[must_use]
pub fn pair_errors(rgba: &[[f32; 4]], truth: &Rgb32FImage, photo: &Rgb32FImage) -> PairErrors {
    let (w, h) = truth.dimensions();
    assert_eq!(photo.dimensions(), (w, h), "photo size");
    assert_eq!(rgba.len(), (w * h) as usize, "montage size");
    let (mut box_err, mut box_bias, mut box_n) = (0.0, 0.0, 0);
    let (mut shadow_err, mut shadow_bias, mut shadow_n) = (0.0, 0.0, 0);
    let mut sq = 0.0;
    let lum = |v: [f32; 3]| v.iter().map(|&c| f64::from(c)).sum::<f64>();
    for y in 0..h {
        for x in 0..w {
            let ours = rgba[(y * w + x) as usize];
            let t = truth.get_pixel(x, y).0;
            let p = photo.get_pixel(x, y).0;
            let err = |k: usize| (f64::from(ours[k]) - f64::from(t[k])) / f64::from(t[k]).max(1e-3);
            let rel = (0..3).map(|k| err(k).abs()).sum::<f64>() / 3.0;
            let signed = (0..3).map(err).sum::<f64>() / 3.0;
            sq += (0..3)
                .map(|k| (f64::from(ours[k]) - f64::from(t[k])).powi(2))
                .sum::<f64>();
            if ours[3] >= 1.0 {
                box_err += rel;
                box_bias += signed;
                box_n += 1;
            } else if ours[3] <= 0.0 && lum(t) < SHADOW_DARKER_THAN * lum(p) {
                shadow_err += rel;
                shadow_bias += signed;
                shadow_n += 1;
            }
        }
    }
    let mean = |s: f64, n: u32| if n == 0 { f64::NAN } else { s / f64::from(n) };
    PairErrors {
        box_pixels: box_n,
        box_mean_rel: mean(box_err, box_n),
        box_bias: mean(box_bias, box_n),
        shadow_pixels: shadow_n,
        shadow_mean_rel: mean(shadow_err, shadow_n),
        shadow_bias: mean(shadow_bias, shadow_n),
        rmse: (sq / f64::from(3 * w * h)).sqrt(),
    }
}
