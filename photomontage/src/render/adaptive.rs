//! Adaptive stochastic sampling of one tile, shared by the RGB and the spectral renderer.
//!
//! **Pass 1** is Durisch's rule (§7, after Cook 1986): every pixel gets 4 jittered rays (one per
//! 2×2 stratum), then 4 more at a time while [`RenderSettings::wants_more_rays`] asks for them
//! (up to `min_rays_per_pixel` always, then while the pixel changed and the standard error of
//! its mean is high).
//!
//! That rule cannot see an edge whose first rays all fell on one side: a pixel that a shadow
//! edge crosses at 30 % whose 4 rays all landed in the shadow has zero variance and stops, and
//! its coverage is quantised to quarters. Along a shadow a few pixels wide those edge rows are
//! most of the shadow (the street site's V1/V2, docs/benchmarks.md). **Pass 2** therefore looks
//! at each pixel's neighbours, as Mitchell (1987, "Generating antialiased images at low sampling
//! densities", SIGGRAPH '87) samples more densely where the contrast between neighbouring
//! samples is high: a pixel whose pass-1 estimate differs from one of its 8 neighbours (within
//! the tile) by more than [`FACTOR_CONTRAST`], [`RADIANCE_CONTRAST`] or [`COVERAGE_STEP`] (see
//! [`pixels_at_edges`]), where at least one of the two changed, is sampled on up to
//! `max_rays_per_pixel`.
//!
//! The random numbers are drawn in a fixed order (every pixel's pass 1 in row-major order, then
//! pass 2 in row-major order), so a tile's result depends on its own stream only: bit-identical
//! on any thread count and in any band of a farm render. A pixel that no ray saw change keeps the
//! photo's value bit for bit, whatever pass it was sampled in.

use image::Rgb32FImage;
use nalgebra::Point2;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::{RenderSettings, Rgb};

/// What the adaptive rule needs to know about one ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RayOutcome {
    /// The ray's radiance, linear RGB (the photo's value where it did not change).
    pub radiance_rgb: Rgb,
    /// Whether the ray saw any change.
    pub changed: bool,
    /// Whether its first hit is an artificial object.
    pub hit_artificial: bool,
}

/// One pixel's rays so far.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct PixelTally {
    /// Rays traced.
    pub n: u32,
    /// Rays whose first hit is artificial.
    pub covered: u32,
    /// Whether any ray saw a change.
    pub changed: bool,
    /// Sum of the rays' radiances.
    pub sum: Rgb,
    /// Sum of their squares.
    pub sum_sq: Rgb,
}

impl PixelTally {
    /// The pixel's linear RGBA: the mean of `sum` (the tally's sum, or a corrected one) over its
    /// rays with the coverage as alpha where it changed, else the photo's value `photo` bit for
    /// bit with alpha 0.
    pub fn rgba(&self, sum: Rgb, photo: [f32; 3]) -> [f32; 4] {
        if !self.changed {
            return [photo[0], photo[1], photo[2], 0.0];
        }
        let nf = f64::from(self.n);
        #[allow(clippy::cast_possible_truncation)]
        [
            (sum[0] / nf) as f32,
            (sum[1] / nf) as f32,
            (sum[2] / nf) as f32,
            (f64::from(self.covered) / nf) as f32,
        ]
    }

    fn add(&mut self, ray: &RayOutcome) {
        self.changed |= ray.changed;
        self.covered += u32::from(ray.hit_artificial);
        for k in 0..3 {
            self.sum[k] += ray.radiance_rgb[k];
            self.sum_sq[k] += ray.radiance_rgb[k] * ray.radiance_rgb[k];
        }
    }

    /// Fraction of rays that hit an artificial object first.
    fn coverage(&self) -> f64 {
        f64::from(self.covered) / f64::from(self.n.max(1))
    }
}

/// Two neighbours differ when their coverage fractions differ by at least this (any difference
/// of whole rays at 4–16 rays per pixel).
pub(crate) const COVERAGE_STEP: f64 = 0.05;
/// Two neighbours not fully covered differ when, in some channel, their means divided by their
/// photo values (the change factor: 1 where nothing changed, E_new/E_old in a new shadow) have
/// a contrast |a − b| / (a + b) above this: factors 1 and 0.9 (a shadow that takes 10 % of
/// the light) are 0.053 apart. Dividing by the photo keeps the photo's own texture out of it.
pub(crate) const FACTOR_CONTRAST: f64 = 0.05;
/// Two fully covered neighbours (the planned object's own image) differ when their mean
/// radiances have a contrast |a − b| / (a + b) above this in some channel (Mitchell 1987 used
/// 0.3–0.6 per channel for whole images; the object's faces are flat-shaded, so lower is cheap).
pub(crate) const RADIANCE_CONTRAST: f64 = 0.1;
/// Photo values below this (linear) count as this in the change factor.
const PHOTO_FLOOR: f64 = 1e-3;

fn contrast(a: f64, b: f64) -> f64 {
    let s = a.abs() + b.abs();
    if s > 0.0 { (a - b).abs() / s } else { 0.0 }
}

/// Whether two neighbouring pixels' pass-1 estimates differ enough to sample both further.
fn differ(a: &PixelTally, photo_a: Rgb, b: &PixelTally, photo_b: Rgb) -> bool {
    if !a.changed && !b.changed {
        return false;
    }
    let (ca, cb) = (a.coverage(), b.coverage());
    if (ca - cb).abs() >= COVERAGE_STEP {
        return true;
    }
    let mean = |t: &PixelTally, photo: Rgb, k: usize| {
        if t.changed {
            t.sum[k] / f64::from(t.n.max(1))
        } else {
            photo[k]
        }
    };
    (0..3).any(|k| {
        let (ma, mb) = (mean(a, photo_a, k), mean(b, photo_b, k));
        if ca >= 1.0 && cb >= 1.0 {
            contrast(ma, mb) > RADIANCE_CONTRAST
        } else {
            let fa = ma / photo_a[k].max(PHOTO_FLOOR);
            let fb = mb / photo_b[k].max(PHOTO_FLOOR);
            contrast(fa, fb) > FACTOR_CONTRAST
        }
    })
}

/// The pixels of a `size_px` tile (row-major `tallies` and `photo_rgb`) that differ from one of
/// their 8 neighbours inside the tile (see [`differ`]).
pub(crate) fn pixels_at_edges(
    size_px: [u32; 2],
    tallies: &[PixelTally],
    photo_rgb: &[Rgb],
) -> Vec<bool> {
    let (w, h) = (size_px[0] as usize, size_px[1] as usize);
    let mut edge = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            // Each unordered pair once: right, and the three below.
            let below = y + 1 < h;
            let pairs = [
                (x + 1 < w).then(|| i + 1),
                below.then(|| i + w),
                (below && x + 1 < w).then(|| i + w + 1),
                (below && x > 0).then(|| i + w - 1),
            ];
            for j in pairs.into_iter().flatten() {
                if differ(&tallies[i], photo_rgb[i], &tallies[j], photo_rgb[j]) {
                    edge[i] = true;
                    edge[j] = true;
                }
            }
        }
    }
    edge
}

/// The photo pixel of pixel `i` (row-major) of the tile at `origin_px` of `size_px`.
pub(crate) fn tile_pixel(origin_px: [u32; 2], size_px: [u32; 2], i: usize) -> [u32; 2] {
    #[allow(clippy::cast_possible_truncation)]
    let i = i as u32;
    [origin_px[0] + i % size_px[0], origin_px[1] + i / size_px[0]]
}

/// Samples the tile at `origin_px` of `size_px`: pass 1 and pass 2 of the module doc, with 4
/// stratified jittered positions per batch drawn from `rng`. `trace(i, [x, y], position)`
/// traces one ray of pixel `i` (row-major in the tile) at pixel `[x, y]` through `position`
/// (pixel coordinates) and reports it; the caller keeps whatever else it needs per pixel.
/// Returns the tallies, row-major.
pub(crate) fn sample_tile(
    settings: &RenderSettings,
    rng: &mut ChaCha8Rng,
    origin_px: [u32; 2],
    size_px: [u32; 2],
    photo: &Rgb32FImage,
    trace: &mut dyn FnMut(usize, [u32; 2], Point2<f64>) -> RayOutcome,
) -> Vec<PixelTally> {
    let count = (size_px[0] * size_px[1]) as usize;
    let mut tallies = vec![PixelTally::default(); count];
    let pixel_of = |i: usize| tile_pixel(origin_px, size_px, i);
    let mut batch = |tally: &mut PixelTally, i: usize, rng: &mut ChaCha8Rng| {
        let [x, y] = pixel_of(i);
        for s in 0..4 {
            let (sx, sy) = (f64::from(s % 2), f64::from(s / 2));
            let (u, v): (f64, f64) = (rng.random(), rng.random());
            let position = Point2::new(
                f64::from(x) - 0.5 + (sx + u) / 2.0,
                f64::from(y) - 0.5 + (sy + v) / 2.0,
            );
            tally.add(&trace(i, [x, y], position));
        }
        tally.n += 4;
    };
    for (i, tally) in tallies.iter_mut().enumerate() {
        loop {
            batch(tally, i, rng);
            if !settings.wants_more_rays(tally.n, tally.changed, &tally.sum, &tally.sum_sq) {
                break;
            }
        }
    }
    if settings.max_rays_per_pixel > settings.min_rays_per_pixel {
        let photo_rgb: Vec<Rgb> = (0..count)
            .map(|i| {
                let [x, y] = pixel_of(i);
                photo.get_pixel(x, y).0.map(f64::from)
            })
            .collect();
        let edge = pixels_at_edges(size_px, &tallies, &photo_rgb);
        for (i, tally) in tallies.iter_mut().enumerate() {
            if edge[i] {
                while tally.n < settings.max_rays_per_pixel {
                    batch(tally, i, rng);
                }
            }
        }
    }
    tallies
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tally(n: u32, covered: u32, changed: bool, mean: Rgb) -> PixelTally {
        let nf = f64::from(n);
        PixelTally {
            n,
            covered,
            changed,
            sum: mean.map(|m| m * nf),
            sum_sq: mean.map(|m| m * m * nf),
        }
    }

    /// A 4 × 3 tile: a shadow (factor 0.3) over the left two columns of rows 0–1 on a photo of
    /// two textures; its edge pixels, and only they, are flagged.
    #[test]
    fn a_new_shadow_flags_its_edge_pixels_not_the_photo_texture() {
        let size = [4, 3];
        // Photo texture alternating 0.2 / 0.6: no edge unless something changed.
        let photo: Vec<Rgb> = (0..12)
            .map(|i| if i % 2 == 0 { [0.2; 3] } else { [0.6; 3] })
            .collect();
        let tallies: Vec<PixelTally> = (0..12)
            .map(|i| {
                let (x, y) = (i % 4, i / 4);
                if x < 2 && y < 2 {
                    tally(4, 0, true, photo[i].map(|p| 0.3 * p))
                } else {
                    tally(4, 0, false, photo[i])
                }
            })
            .collect();
        let edge = pixels_at_edges(size, &tallies, &photo);
        #[rustfmt::skip]
        let expected = [
            false, true, true, false,
            true, true, true, false,
            true, true, true, false,
        ];
        // The shadow's corner (0, 0) has only shadow neighbours in the tile; its other pixels
        // touch lit ones, and the lit column x = 2 and row y = 2 touch it; x = 3 does not, nor
        // does any pair of lit pixels with different texture.
        assert_eq!(edge, expected);
        // Nothing changed: no edges, whatever the texture.
        let unchanged: Vec<PixelTally> = photo.iter().map(|p| tally(4, 0, false, *p)).collect();
        assert!(pixels_at_edges(size, &unchanged, &photo).iter().all(|e| !e));
    }

    #[test]
    fn uniform_changes_and_flat_faces_are_not_edges() {
        let size = [3, 3];
        let photo = vec![[0.4, 0.5, 0.6]; 9];
        // A uniform new shadow (same factor everywhere): no edge.
        let shadow: Vec<PixelTally> = photo
            .iter()
            .map(|p| tally(4, 0, true, p.map(|c| c * 0.5)))
            .collect();
        assert!(pixels_at_edges(size, &shadow, &photo).iter().all(|e| !e));
        // A fully covered face with a smooth 5 % gradient: no edge; a face break (0.2 → 0.4) is one.
        let mut face: Vec<PixelTally> = (0..9)
            .map(|i| tally(4, 4, true, [0.2 * (1.0 + 0.01 * f64::from(i)); 3]))
            .collect();
        assert!(pixels_at_edges(size, &face, &photo).iter().all(|e| !e));
        face[8] = tally(4, 4, true, [0.4; 3]);
        let edge = pixels_at_edges(size, &face, &photo);
        assert_eq!(edge.iter().filter(|e| **e).count(), 4, "{edge:?}");
        assert!(edge[8] && edge[4] && edge[5] && edge[7]);
        // Coverage 3/4 beside 4/4: an outline.
        face[8] = tally(4, 3, true, [0.2 * 1.08; 3]);
        assert!(pixels_at_edges(size, &face, &photo)[8]);
    }
}
