//! A photo re-projected to a standard focal length (Landscape Institute TGN 06/19, single-frame
//! planar views at a 50 mm or 75 mm equivalent; NatureScot, *Visual Representation of Wind
//! Farms*, 2017, the same practice): a virtual distortion-free pinhole camera at the photo's
//! projection centre, looking the same way (same rotation, so same bearing, pitch and roll), with
//! its principal point at the image centre and the focal length that gives the requested 35 mm
//! equivalent on the output's diagonal (`f_px = f_35 · √(W² + H²) / 43.27 mm`, the convention of
//! [`super::geometry::focal_35mm_equiv_mm`]).
//!
//! Since both cameras share their centre, every output pixel's ray meets the photo at exactly one
//! point whatever the scene's depth: the output pixel's ray is projected into the photo through
//! its full lens model (distortion included) and the photo is sampled there bilinearly (pixel
//! centres at integer coordinates). A world point therefore lands where the virtual pinhole puts
//! it.
//!
//! [`planar_view_job`] turns the site's render job for the photo into one for the view (virtual
//! camera, re-projected photo), so the montage renders into the view as into a photo.
//!
//! # Known limitations
//! Bilinear resampling: enlarging (a longer focal length than the photo's) softens, and there is no
//! prefilter when reducing. Output pixels whose ray falls outside the photo (a shorter focal length
//! than the photo's) are transparent (alpha 0) and counted in [`PlanarView::coverage`].

use image::Rgb32FImage;
use nalgebra::Point2;
use rayon::prelude::*;

use crate::camera::{Camera, Intrinsics};
use crate::photo::exif::FULL_FRAME_DIAGONAL_MM;
use crate::render::RenderedImage;
use crate::site::SiteDocument;
use crate::site::render::{SiteRenderError, ViewJob, prepare_view, site_camera, site_photo_linear};

/// What can go wrong making a planar view.
#[derive(Debug, thiserror::Error)]
pub enum PlanarViewError {
    #[error(
        "photo {photo}: a 35 mm-equivalent focal length of {focal_equiv_mm} mm cannot be used \
         (give a positive, finite value such as 50 or 75)"
    )]
    InvalidFocal { photo: String, focal_equiv_mm: f64 },
    #[error("photo {photo}: output size {size_px:?} px must be at least 1 × 1")]
    InvalidSize { photo: String, size_px: [u32; 2] },
    #[error(transparent)]
    Site(#[from] SiteRenderError),
}

/// The focal length in pixels of a `size_px` image with 35 mm-equivalent `focal_equiv_mm`
/// (diagonal convention), `None` when either is not positive and finite.
#[must_use]
pub fn focal_px_for_equivalent(focal_equiv_mm: f64, size_px: [u32; 2]) -> Option<f64> {
    let diagonal_px = f64::from(size_px[0]).hypot(f64::from(size_px[1]));
    (focal_equiv_mm.is_finite() && focal_equiv_mm > 0.0 && diagonal_px > 0.0)
        .then(|| focal_equiv_mm * diagonal_px / FULL_FRAME_DIAGONAL_MM)
}

/// The virtual camera of a planar view of `source` (module doc).
#[must_use]
pub fn planar_camera(source: &Camera, focal_px: f64, size_px: [u32; 2]) -> Camera {
    Camera {
        intrinsics: Intrinsics::centred(focal_px, size_px),
        pose: source.pose,
    }
}

/// Bilinear sample of `image` at a pixel position (pixel centres at integers), `None` outside
/// `[-0.5, W − 0.5] × [-0.5, H − 0.5]`.
#[must_use]
pub fn sample_bilinear(image: &Rgb32FImage, p: Point2<f64>) -> Option<[f32; 3]> {
    let (w, h) = (f64::from(image.width()), f64::from(image.height()));
    if !(p.x >= -0.5 && p.y >= -0.5 && p.x <= w - 0.5 && p.y <= h - 0.5) {
        return None;
    }
    let x = p.x.clamp(0.0, w - 1.0);
    let y = p.y.clamp(0.0, h - 1.0);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let (x0, y0) = (x0 as u32, y0 as u32);
    let x1 = (x0 + 1).min(image.width() - 1);
    let y1 = (y0 + 1).min(image.height() - 1);
    let px = |x, y| image.get_pixel(x, y).0.map(f64::from);
    let (a, b, c, d) = (px(x0, y0), px(x1, y0), px(x0, y1), px(x1, y1));
    #[allow(clippy::cast_possible_truncation)]
    Some(std::array::from_fn(|k| {
        let top = a[k] + (b[k] - a[k]) * fx;
        let bottom = c[k] + (d[k] - c[k]) * fx;
        (top + (bottom - top) * fy) as f32
    }))
}

/// `photo` (taken with `source`) seen by `target`, a camera with the same projection centre:
/// linear RGBA, alpha 1 where the photo covers the pixel, 0 elsewhere.
#[must_use]
pub fn reproject(source: &Camera, photo: &Rgb32FImage, target: &Camera) -> RenderedImage {
    let [w, h] = target.intrinsics.image_size_px;
    let rgba: Vec<[f32; 4]> = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| (0..w).map(move |x| Point2::new(f64::from(x), f64::from(y))))
        .map(|px| {
            let dir = target.ray_dir_in_world(px);
            let point = source.pose.camera_center_in_world + dir;
            source
                .project(&point)
                .and_then(|q| sample_bilinear(photo, q))
                .map_or([0.0; 4], |c| [c[0], c[1], c[2], 1.0])
        })
        .collect();
    let covered = rgba.iter().filter(|p| p[3] > 0.0).count();
    RenderedImage {
        size_px: [w, h],
        rgba,
        changed_pixels: covered,
        primary_rays: 0,
    }
}

/// The solved camera of photo `photo_id` and the photo itself, linear, checked to be the
/// camera's size.
///
/// # Errors
/// [`SiteRenderError`]: an unknown or unsolved view, an unreadable photo, a size mismatch.
pub fn solved_photo(
    doc: &SiteDocument,
    photo_id: &str,
) -> Result<(Camera, Rgb32FImage), SiteRenderError> {
    let camera = site_camera(doc, photo_id)?;
    let photo_linear = site_photo_linear(doc, photo_id, &camera)?;
    Ok((camera, photo_linear))
}

/// A planar view with its virtual camera.
#[derive(Debug, Clone)]
pub struct PlanarView {
    /// The virtual camera (same centre and rotation as the photo).
    pub camera: Camera,
    /// The re-projected photo, linear RGBA.
    pub image: RenderedImage,
    /// Share of output pixels the photo covers (1 when the requested focal length is not
    /// shorter than the photo's in any direction).
    pub coverage: f64,
}

/// Photo `photo_id` re-projected to a planar view of 35 mm-equivalent `focal_equiv_mm`, of
/// `size_px` (default: the photo's size).
///
/// # Errors
/// [`PlanarViewError::InvalidFocal`], [`PlanarViewError::InvalidSize`], and the site errors of
/// an unknown or unsolved view or an unreadable photo.
pub fn planar_view(
    doc: &SiteDocument,
    photo_id: &str,
    focal_equiv_mm: f64,
    size_px: Option<[u32; 2]>,
) -> Result<PlanarView, PlanarViewError> {
    let source = site_camera(doc, photo_id)?;
    let size_px = size_px.unwrap_or(source.intrinsics.image_size_px);
    if size_px.contains(&0) {
        return Err(PlanarViewError::InvalidSize {
            photo: photo_id.to_owned(),
            size_px,
        });
    }
    let focal_px = focal_px_for_equivalent(focal_equiv_mm, size_px).ok_or_else(|| {
        PlanarViewError::InvalidFocal {
            photo: photo_id.to_owned(),
            focal_equiv_mm,
        }
    })?;
    let (_, photo_linear) = solved_photo(doc, photo_id)?;
    let camera = planar_camera(&source, focal_px, size_px);
    let image = reproject(&source, &photo_linear, &camera);
    #[allow(clippy::cast_precision_loss)]
    let coverage = image.changed_pixels as f64 / image.rgba.len().max(1) as f64;
    Ok(PlanarView {
        camera,
        image,
        coverage,
    })
}

/// The render job of a planar view, so that the montage renders into the view as into a photo:
/// the site's job for `photo_id` ([`crate::site::render::prepare_view`]) with the virtual
/// camera and the re-projected photo in place of the photo's own (pixels the photo does not
/// cover are black there). Also returns the view itself.
///
/// # Errors
/// As [`planar_view`], and [`crate::site::render::prepare_view`]'s errors (no visible model,
/// lighting).
pub fn planar_view_job(
    doc: &SiteDocument,
    photo_id: &str,
    focal_equiv_mm: f64,
    size_px: Option<[u32; 2]>,
) -> Result<(PlanarView, ViewJob), PlanarViewError> {
    let view = planar_view(doc, photo_id, focal_equiv_mm, size_px)?;
    let mut job = prepare_view(doc, photo_id)?;
    let [w, h] = view.image.size_px;
    let rgba = &view.image.rgba;
    job.photo_linear = std::sync::Arc::new(Rgb32FImage::from_fn(w, h, |x, y| {
        let p = rgba[(y * w + x) as usize];
        image::Rgb([p[0], p[1], p[2]])
    }));
    job.camera = view.camera;
    Ok((view, job))
}

#[cfg(test)]
#[path = "planar_view_tests.rs"]
mod tests;
