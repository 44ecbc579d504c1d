//! Undistorting a whole photo (Durisch 1992 §4.1, "geometrical correction"): resample it so that
//! it obeys the pinhole model with the same focal length and principal point and no distortion.
//! Each output pixel maps through the forward distortion to a source position, which is sampled
//! bilinearly; rows are processed in parallel (rayon).
//!
//! # Known limitations
//! Bilinear resampling slightly softens the image; output pixels whose source lies outside the
//! photo are black.

use super::Intrinsics;
use image::{Rgb, Rgb32FImage};
use nalgebra::Point2;
use rayon::prelude::*;

/// Bilinear sample at a pixel position (pixel-centre convention); `None` outside the image.
#[must_use]
pub fn sample_bilinear(image: &Rgb32FImage, pixel: Point2<f64>) -> Option<[f32; 3]> {
    let (w, h) = (f64::from(image.width()), f64::from(image.height()));
    if !(pixel.x >= -0.5 && pixel.y >= -0.5 && pixel.x <= w - 0.5 && pixel.y <= h - 0.5) {
        return None;
    }
    let x = pixel.x.clamp(0.0, w - 1.0);
    let y = pixel.y.clamp(0.0, h - 1.0);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
    let (x0, y0) = (x0 as u32, y0 as u32);
    let x1 = (x0 + 1).min(image.width() - 1);
    let y1 = (y0 + 1).min(image.height() - 1);
    let p = |xx: u32, yy: u32| image.get_pixel(xx, yy).0;
    let (a, b, c, d) = (p(x0, y0), p(x1, y0), p(x0, y1), p(x1, y1));
    let mut out = [0.0f32; 3];
    for i in 0..3 {
        let top = a[i] + (b[i] - a[i]) * fx;
        let bottom = c[i] + (d[i] - c[i]) * fx;
        out[i] = top + (bottom - top) * fy;
    }
    Some(out)
}

/// Resamples `image` (taken with `intrinsics`) to the same camera without lens distortion.
#[must_use]
pub fn undistort_image(image: &Rgb32FImage, intrinsics: &Intrinsics) -> Rgb32FImage {
    let (w, h) = (image.width(), image.height());
    let ideal = Intrinsics {
        distortion: super::BrownConrady::default(),
        ..*intrinsics
    };
    let mut out = Rgb32FImage::new(w, h);
    out.par_chunks_mut(3 * w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for x in 0..w as usize {
                let normalised = ideal.normalised_from_pixel(Point2::new(x as f64, y as f64));
                let source = intrinsics.pixel_from_normalised(normalised);
                let value = sample_bilinear(image, source).unwrap_or([0.0; 3]);
                row[3 * x..3 * x + 3].copy_from_slice(&value);
            }
        });
    out
}

/// The same for a single pixel position: where a distorted pixel lands in the undistorted photo.
#[must_use]
pub fn undistorted_pixel(intrinsics: &Intrinsics, distorted_px: Point2<f64>) -> Point2<f64> {
    let n = intrinsics.normalised_from_pixel(distorted_px);
    Point2::new(
        intrinsics.focal_px * n.x + intrinsics.principal_point_px[0],
        intrinsics.focal_px * n.y + intrinsics.principal_point_px[1],
    )
}

/// An image of one colour, for tests and placeholders of the right size.
#[must_use]
pub fn filled(w: u32, h: u32, colour: [f32; 3]) -> Rgb32FImage {
    Rgb32FImage::from_pixel(w, h, Rgb(colour))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::BrownConrady;

    /// A bright dot drawn at a distorted position must appear, after undistortion, at the ideal
    /// position of the same ray. The centroid of a 3×3 dot resampled bilinearly is exact to well
    /// under 0.1 px.
    const CENTROID_TOLERANCE_PX: f64 = 0.1;

    #[test]
    fn dot_moves_to_its_ideal_position() {
        let intrinsics = Intrinsics {
            focal_px: 300.0,
            principal_point_px: [159.5, 119.5],
            distortion: BrownConrady {
                k1: -0.25,
                k2: 0.05,
                p1: 0.001,
                ..BrownConrady::default()
            },
            image_size_px: [320, 240],
        };
        // Ideal (undistorted) pixel position of a ray, and where the lens put it.
        let ideal = Point2::new(260.0, 200.0);
        let n = Point2::new((ideal.x - 159.5) / 300.0, (ideal.y - 119.5) / 300.0);
        let distorted = intrinsics.pixel_from_normalised(n);
        let mut img = filled(320, 240, [0.0; 3]);
        let (cx, cy) = (distorted.x.round() as i64, distorted.y.round() as i64);
        for dy in -1..=1 {
            for dx in -1..=1 {
                img.put_pixel((cx + dx) as u32, (cy + dy) as u32, Rgb([1.0; 3]));
            }
        }
        let out = undistort_image(&img, &intrinsics);
        let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
        for (x, y, p) in out.enumerate_pixels() {
            let v = f64::from(p[0]);
            sx += v * f64::from(x);
            sy += v * f64::from(y);
            sw += v;
        }
        let centroid = Point2::new(sx / sw, sy / sw);
        // The dot was drawn at the rounded distorted position: map that back.
        let expected = undistorted_pixel(&intrinsics, Point2::new(cx as f64, cy as f64));
        assert!(
            (centroid - expected).norm() < CENTROID_TOLERANCE_PX,
            "centroid {centroid} expected {expected}"
        );
        assert!((expected - ideal).norm() < 1.0);
    }

    #[test]
    fn zero_distortion_is_identity() {
        let intrinsics = Intrinsics::centred(100.0, [16, 8]);
        let img = Rgb32FImage::from_fn(16, 8, |x, y| Rgb([x as f32, y as f32, 1.0]));
        assert_eq!(undistort_image(&img, &intrinsics), img);
    }
}
