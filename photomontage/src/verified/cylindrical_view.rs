//! A cylindrical panorama from several photos taken from one position (Landscape Institute TGN
//! 06/19, panoramas of up to 360°; NatureScot, *Visual Representation of Wind Farms*, 2017,
//! cylindrical projection at a 50 mm equivalent): each photo solved, the panorama composed on a
//! level cylinder about the vertical through the photos' mean centre with the solved rotations,
//! seams feathered.
//!
//! **Projection.** A direction `d` (world, Z up) has azimuth `θ = atan2(d_x, d_y)` (clockwise
//! from grid north) and height `h = d_z / √(d_x² + d_y²)` (the tangent of its elevation). With the
//! cylinder's radius `f` pixels, pixel `(x, y)` shows `θ = θ_left + (x + 0.5)/f`,
//! `h = h_top − (y + 0.5)/f` (pixel centres at integers, as everywhere). The radius is the focal
//! length a planar view of the requested 35 mm equivalent has at the first photo's resolution
//! (`f = f_35 · √(W² + H²) / 43.27 mm`), so the horizon has that view's scale. The panorama
//! spans the photos' azimuths and heights (at most 360°).
//!
//! **Composition.** Every panorama pixel's direction is projected into every photo through its
//! full lens model (the photos' centres are taken as one point: the spread must be below
//! [`CylindricalOptions::max_centre_spread_m`]) and sampled bilinearly; overlapping photos are
//! blended with weights proportional to the distance from each photo's border in pixels
//! (feathering), so a seam fades over the overlap.
//!
//! # Known limitations
//! Parallax from centres that are not exactly one point is ignored (within the tolerance it is
//! below `spread / distance` radians); no exposure matching between photos (they are blended as
//! they are); the cylinder is level (a tilted panorama head is corrected by the solved rotations,
//! not by a tilted cylinder); bilinear resampling.

use image::Rgb32FImage;
use nalgebra::{Point2, Point3, Vector3};
use rayon::prelude::*;
use serde::Serialize;

use super::planar_view::{focal_px_for_equivalent, sample_bilinear};
use crate::camera::Camera;
use crate::render::RenderedImage;
use crate::site::SiteDocument;
use crate::site::render::SiteRenderError;

/// Choices of the panorama.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylindricalOptions {
    /// 35 mm-equivalent focal length setting the cylinder's radius.
    pub focal_equiv_mm: f64,
    /// Photos whose centre lies farther than this from the mean centre are refused (0.1 m:
    /// a hand-held rotation about the photographer's eye; a panoramic head gives millimetres).
    pub max_centre_spread_m: f64,
    /// Largest panorama side accepted, pixels.
    pub max_size_px: u32,
}

impl Default for CylindricalOptions {
    fn default() -> Self {
        Self {
            focal_equiv_mm: 50.0,
            max_centre_spread_m: 0.1,
            max_size_px: 40_000,
        }
    }
}

/// What can go wrong making a panorama.
#[derive(Debug, thiserror::Error)]
pub enum CylindricalError {
    #[error("a cylindrical view needs at least one photo")]
    NoPhotos,
    #[error(
        "photo {photo} was not taken from the same point: its centre is {distance_m:.3} m from \
         the photos' mean centre (tolerance {tolerance_m} m)"
    )]
    NotOnePoint {
        photo: String,
        distance_m: f64,
        tolerance_m: f64,
    },
    #[error(
        "a 35 mm-equivalent focal length of {focal_equiv_mm} mm cannot be used (give a positive, \
         finite value such as 50)"
    )]
    InvalidFocal { focal_equiv_mm: f64 },
    #[error("photo {photo}: its optical axis is vertical; a level cylinder cannot place it")]
    VerticalAxis { photo: String },
    #[error("the panorama would be {size_px:?} px, more than {max_px} px on a side")]
    TooLarge { size_px: [u32; 2], max_px: u32 },
    #[error(transparent)]
    Site(#[from] SiteRenderError),
}

/// One photo of the panorama.
#[derive(Debug, Clone, Copy)]
pub struct PanoramaPhoto<'a> {
    pub id: &'a str,
    pub camera: &'a Camera,
    /// Linear RGB, the camera's size.
    pub image: &'a Rgb32FImage,
}

/// The cylinder of a panorama (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Cylinder {
    /// Mean projection centre of the photos, world metres.
    pub centre_in_world_m: [f64; 3],
    /// Radius in pixels.
    pub focal_px: f64,
    /// Azimuth of the left image edge (x = −0.5), radians clockwise from grid north.
    pub azimuth_left: f64,
    /// Height (tangent of the elevation) of the top image edge (y = −0.5).
    pub height_top: f64,
    pub size_px: [u32; 2],
}

impl Cylinder {
    /// The world direction a panorama pixel shows.
    #[must_use]
    pub fn dir_in_world(&self, pixel: Point2<f64>) -> Vector3<f64> {
        let theta = self.azimuth_left + (pixel.x + 0.5) / self.focal_px;
        let h = self.height_top - (pixel.y + 0.5) / self.focal_px;
        Vector3::new(theta.sin(), theta.cos(), h).normalize()
    }

    /// The panorama pixel of a world point (seen from the cylinder's centre), `None` straight
    /// above or below it.
    #[must_use]
    pub fn project(&self, point_in_world: &Point3<f64>) -> Option<Point2<f64>> {
        let d = point_in_world - Point3::from(self.centre_in_world_m);
        let horizontal = d.x.hypot(d.y);
        if horizontal <= f64::EPSILON * d.norm() {
            return None;
        }
        let theta = d.x.atan2(d.y);
        let rel = (theta - self.azimuth_left).rem_euclid(std::f64::consts::TAU);
        Some(Point2::new(
            self.focal_px * rel - 0.5,
            self.focal_px * (self.height_top - d.z / horizontal) - 0.5,
        ))
    }
}

/// A composed panorama.
#[derive(Debug, Clone)]
pub struct CylindricalView {
    pub cylinder: Cylinder,
    /// Linear RGBA; alpha 1 where a photo covers the pixel.
    pub image: RenderedImage,
}

fn azimuth_height(d: &Vector3<f64>) -> Option<(f64, f64)> {
    let horizontal = d.x.hypot(d.y);
    (horizontal > 1e-9).then(|| (d.x.atan2(d.y), d.z / horizontal))
}

/// Checks that the photos share one centre and returns the mean centre.
///
/// # Errors
/// [`CylindricalError::NoPhotos`], [`CylindricalError::NotOnePoint`] naming the photo farthest
/// from the mean when it exceeds the tolerance.
pub fn common_centre(
    photos: &[PanoramaPhoto<'_>],
    tolerance_m: f64,
) -> Result<Point3<f64>, CylindricalError> {
    if photos.is_empty() {
        return Err(CylindricalError::NoPhotos);
    }
    #[allow(clippy::cast_precision_loss)]
    let mean = Point3::from(
        photos
            .iter()
            .map(|p| p.camera.pose.camera_center_in_world.coords)
            .sum::<Vector3<f64>>()
            / photos.len() as f64,
    );
    let (worst, distance) = photos
        .iter()
        .map(|p| (p, (p.camera.pose.camera_center_in_world - mean).norm()))
        .fold((&photos[0], 0.0), |a, b| if b.1 > a.1 { b } else { a });
    if distance > tolerance_m {
        return Err(CylindricalError::NotOnePoint {
            photo: worst.id.to_owned(),
            distance_m: distance,
            tolerance_m,
        });
    }
    Ok(mean)
}

/// The cylinder covering all photos (their border pixels' azimuths and heights).
///
/// # Errors
/// As [`common_centre`], [`CylindricalError::InvalidFocal`], [`CylindricalError::VerticalAxis`],
/// [`CylindricalError::TooLarge`].
pub fn cylinder_for(
    photos: &[PanoramaPhoto<'_>],
    options: &CylindricalOptions,
) -> Result<Cylinder, CylindricalError> {
    let centre = common_centre(photos, options.max_centre_spread_m)?;
    let first = photos[0].camera;
    let focal_px = focal_px_for_equivalent(options.focal_equiv_mm, first.intrinsics.image_size_px)
        .ok_or(CylindricalError::InvalidFocal {
            focal_equiv_mm: options.focal_equiv_mm,
        })?;
    // Azimuths relative to the first photo's axis, so a panorama across north stays contiguous.
    let reference = azimuth_height(&first.pose.viewing_dir_in_world())
        .ok_or_else(|| CylindricalError::VerticalAxis {
            photo: photos[0].id.to_owned(),
        })?
        .0;
    let (mut lo, mut hi, mut top, mut bottom) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
    );
    for p in photos {
        let [w, h] = p.camera.intrinsics.image_size_px.map(f64::from);
        let steps = 64;
        for i in 0..=steps {
            let s = f64::from(i) / f64::from(steps);
            for q in [
                Point2::new(-0.5 + s * w, -0.5),
                Point2::new(-0.5 + s * w, h - 0.5),
                Point2::new(-0.5, -0.5 + s * h),
                Point2::new(w - 0.5, -0.5 + s * h),
            ] {
                let Some((theta, height)) = azimuth_height(&p.camera.ray_dir_in_world(q)) else {
                    return Err(CylindricalError::VerticalAxis {
                        photo: p.id.to_owned(),
                    });
                };
                let rel = (theta - reference + std::f64::consts::PI)
                    .rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                lo = lo.min(rel);
                hi = hi.max(rel);
                top = top.max(height);
                bottom = bottom.min(height);
            }
        }
    }
    let span = (hi - lo).min(std::f64::consts::TAU);
    let size = [(focal_px * span).ceil(), (focal_px * (top - bottom)).ceil()];
    let too_large = || CylindricalError::TooLarge {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        size_px: size.map(|s| s.min(f64::from(u32::MAX)) as u32),
        max_px: options.max_size_px,
    };
    if !(size[0] >= 1.0
        && size[1] >= 1.0
        && size[0] <= f64::from(options.max_size_px)
        && size[1] <= f64::from(options.max_size_px))
    {
        return Err(too_large());
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let size_px = size.map(|s| s as u32);
    Ok(Cylinder {
        centre_in_world_m: centre.coords.into(),
        focal_px,
        azimuth_left: reference + lo,
        height_top: top,
        size_px,
    })
}

/// The feathering weight of a photo pixel: its distance from the photo's border, pixels.
fn border_weight(camera: &Camera, q: Point2<f64>) -> f64 {
    let [w, h] = camera.intrinsics.image_size_px.map(f64::from);
    (q.x + 0.5)
        .min(w - 0.5 - q.x)
        .min(q.y + 0.5)
        .min(h - 0.5 - q.y)
        .max(0.0)
}

/// The sample of one photo at a panorama direction, with its feathering weight.
#[must_use]
pub fn photo_sample(photo: &PanoramaPhoto<'_>, dir: &Vector3<f64>) -> Option<([f32; 3], f64)> {
    let cam = photo.camera;
    let q = cam.project(&(cam.pose.camera_center_in_world + dir))?;
    let c = sample_bilinear(photo.image, q)?;
    Some((c, border_weight(cam, q)))
}

/// Composes the panorama (module doc).
///
/// # Errors
/// As [`cylinder_for`].
pub fn cylindrical_view(
    photos: &[PanoramaPhoto<'_>],
    options: &CylindricalOptions,
) -> Result<CylindricalView, CylindricalError> {
    let cylinder = cylinder_for(photos, options)?;
    let [w, h] = cylinder.size_px;
    let rgba: Vec<[f32; 4]> = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| (0..w).map(move |x| Point2::new(f64::from(x), f64::from(y))))
        .map(|px| {
            let dir = cylinder.dir_in_world(px);
            let (mut sum, mut weight, mut first) = ([0.0_f64; 3], 0.0, None);
            for photo in photos {
                if let Some((c, wgt)) = photo_sample(photo, &dir) {
                    first = first.or(Some(c));
                    for k in 0..3 {
                        sum[k] += f64::from(c[k]) * wgt;
                    }
                    weight += wgt;
                }
            }
            match first {
                None => [0.0; 4],
                // On a photo's very border every weight is 0: take that photo's sample.
                Some(c) if weight <= 0.0 => [c[0], c[1], c[2], 1.0],
                #[allow(clippy::cast_possible_truncation)]
                Some(_) => [
                    (sum[0] / weight) as f32,
                    (sum[1] / weight) as f32,
                    (sum[2] / weight) as f32,
                    1.0,
                ],
            }
        })
        .collect();
    let covered = rgba.iter().filter(|p| p[3] > 0.0).count();
    Ok(CylindricalView {
        cylinder,
        image: RenderedImage {
            size_px: [w, h],
            rgba,
            changed_pixels: covered,
            primary_rays: 0,
        },
    })
}

/// The panorama of the solved photos `photo_ids` of a site.
///
/// # Errors
/// The site errors of an unknown or unsolved photo or an unreadable image, and those of
/// [`cylindrical_view`].
pub fn site_cylindrical_view(
    doc: &SiteDocument,
    photo_ids: &[&str],
    options: &CylindricalOptions,
) -> Result<CylindricalView, CylindricalError> {
    let loaded = photo_ids
        .iter()
        .map(|id| super::planar_view::solved_photo(doc, id))
        .collect::<Result<Vec<_>, _>>()?;
    let photos: Vec<PanoramaPhoto<'_>> = photo_ids
        .iter()
        .zip(&loaded)
        .map(|(id, (camera, image))| PanoramaPhoto { id, camera, image })
        .collect();
    cylindrical_view(&photos, options)
}

#[cfg(test)]
#[path = "cylindrical_view_tests.rs"]
mod tests;
