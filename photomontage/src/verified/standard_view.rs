//! One entry point for the views a verified-view package shows — the photo itself, a planar view
//! at a standard focal length, a cylindrical panorama — with or without the proposal at an AVR
//! level, and each view's geometry report ([`super::reprojected_geometry`]). Used by the
//! `view` and `sheet` commands and the studio, so all three show the same image.
//!
//! How the proposal enters each view:
//! - **photo**: AVR0/AVR1 drawn over the photo ([`super::avr`]), AVR2/AVR3 rendered into it;
//! - **planar**: AVR2/AVR3 rendered into the view as into a photo
//!   ([`super::planar_view::planar_view_job`]); AVR0/AVR1 drawn over the photo and re-projected
//!   (both cameras share their centre, so the drawing lands where the view's pinhole puts it);
//! - **cylindrical**: each photo's AVR image (drawn or rendered into the photo) composed on the
//!   cylinder exactly as the photos are ([`super::cylindrical_view`]).
//!
//! # Known limitations
//! A cylindrical montage renders every photo whole, also the parts the panorama's overlap
//! replaces; a planar AVR0/AVR1 drawing is resampled bilinearly (lines soften by up to a pixel).

use std::sync::atomic::AtomicBool;

use image::Rgb32FImage;

use super::avr::{AvrError, AvrLevel, apply_massing, avr_overlay};
use super::cylindrical_view::{
    CylindricalError, CylindricalOptions, PanoramaPhoto, common_centre, cylindrical_view,
};
use super::geometry::{ViewGeometry, ViewGeometryError, ViewGeometryOptions, view_geometry};
use super::planar_view::{PlanarViewError, planar_view, planar_view_job, reproject, solved_photo};
use super::reprojected_geometry::{cylindrical_view_geometry, planar_view_geometry};
use crate::render::{DifferentialTracer, RenderError, RenderedImage, TileProgress, render_view};
use crate::site::SiteDocument;
use crate::site::render::{SiteRenderError, prepare_view};

/// Which view.
#[derive(Debug, Clone, PartialEq)]
pub enum StandardView {
    /// The photo as taken.
    Photo { photo: String },
    /// A planar view of a photo at a 35 mm-equivalent focal length, `size_px` (default: the
    /// photo's size).
    Planar {
        photo: String,
        focal_equiv_mm: f64,
        size_px: Option<[u32; 2]>,
    },
    /// A cylindrical panorama of photos taken from one point.
    Cylindrical {
        photos: Vec<String>,
        options: CylindricalOptions,
    },
}

impl StandardView {
    /// The photos the view is made from.
    #[must_use]
    pub fn photos(&self) -> Vec<&str> {
        match self {
            Self::Photo { photo } | Self::Planar { photo, .. } => vec![photo.as_str()],
            Self::Cylindrical { photos, .. } => photos.iter().map(String::as_str).collect(),
        }
    }
}

/// What can go wrong making a view.
#[derive(Debug, thiserror::Error)]
pub enum StandardViewError {
    #[error(transparent)]
    Planar(#[from] PlanarViewError),
    #[error(transparent)]
    Cylindrical(#[from] CylindricalError),
    #[error(transparent)]
    Geometry(#[from] ViewGeometryError),
    #[error(transparent)]
    Avr(#[from] AvrError),
    #[error(transparent)]
    Site(#[from] SiteRenderError),
    #[error("photo {photo}: {message}")]
    Render { photo: String, message: String },
}

/// A view made: its image (linear RGBA), its geometry, its projection as JSON (the virtual
/// camera or the cylinder) and any render warnings.
#[derive(Debug, Clone)]
pub struct MadeView {
    pub image: RenderedImage,
    pub geometry: ViewGeometry,
    /// `("camera.json", …)` or `("cylinder.json", …)`; `None` for the photo itself.
    pub projection_json: Option<(&'static str, String)>,
    /// Share of pixels the photos cover (1 for the photo itself).
    pub coverage: f64,
    pub warnings: Vec<String>,
}

fn render_error(photo: &str, e: &dyn std::fmt::Display) -> StandardViewError {
    StandardViewError::Render {
        photo: photo.to_owned(),
        message: e.to_string(),
    }
}

fn rgb32f(image: &RenderedImage) -> Rgb32FImage {
    let [w, h] = image.size_px;
    Rgb32FImage::from_fn(w, h, |x, y| {
        let p = image.rgba[(y * w + x) as usize];
        image::Rgb([p[0], p[1], p[2]])
    })
}

/// Renders job `job` (AVR2 with the massing material), reporting tiles to `on_tile`.
fn render_job(
    mut job: crate::site::render::ViewJob,
    avr: AvrLevel,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
    warnings: &mut Vec<String>,
) -> Result<RenderedImage, StandardViewError> {
    let photo = job.photo_id.clone();
    warnings.extend(job.warnings.iter().map(ToString::to_string));
    if avr == AvrLevel::Avr2 {
        apply_massing(&mut job.scene.scene).map_err(AvrError::from)?;
    }
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &job.photo_linear,
        job.settings.max_depth,
    )
    .map_err(|e| render_error(&photo, &e))?;
    render_view(&tracer, &job.settings, on_tile, cancel)
        .map_err(|e: RenderError| render_error(&photo, &e))
}

/// The AVR image of a photo: drawn (AVR0/AVR1) or rendered (AVR2/AVR3).
///
/// # Errors
/// [`AvrError`] (no proposal, unsolved photo), the render's errors.
pub fn photo_avr_image(
    doc: &SiteDocument,
    photo_id: &str,
    avr: AvrLevel,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
    warnings: &mut Vec<String>,
) -> Result<RenderedImage, StandardViewError> {
    if matches!(avr, AvrLevel::Avr0 | AvrLevel::Avr1) {
        return Ok(avr_overlay(doc, photo_id, avr)?.image);
    }
    let job = prepare_view(doc, photo_id)?;
    render_job(job, avr, on_tile, cancel, warnings)
}

#[allow(clippy::cast_precision_loss)]
fn coverage(image: &RenderedImage) -> f64 {
    let covered = image.rgba.iter().filter(|p| p[3] > 0.0).count();
    covered as f64 / image.rgba.len().max(1) as f64
}

/// Makes `view` with the proposal at `avr` (`None`: the photos alone) and its geometry for
/// `options`' paper.
///
/// # Errors
/// [`StandardViewError`], each naming the photo concerned: an unsolved photo, no proposal, a
/// panorama whose photos were not taken from one point, a focal length that cannot be
/// converted, a render failure or cancellation.
pub fn make_view(
    doc: &SiteDocument,
    view: &StandardView,
    avr: Option<AvrLevel>,
    options: &ViewGeometryOptions,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<MadeView, StandardViewError> {
    let mut warnings = Vec::new();
    match view {
        StandardView::Photo { photo } => {
            let geometry = view_geometry(doc, photo, options)?;
            let image = match avr {
                Some(level) => photo_avr_image(doc, photo, level, on_tile, cancel, &mut warnings)?,
                None => {
                    let (_, linear) = solved_photo(doc, photo)?;
                    let [w, h] = [linear.width(), linear.height()];
                    RenderedImage {
                        size_px: [w, h],
                        rgba: linear.pixels().map(|p| [p[0], p[1], p[2], 1.0]).collect(),
                        changed_pixels: 0,
                        primary_rays: 0,
                    }
                }
            };
            Ok(MadeView {
                image,
                geometry,
                projection_json: None,
                coverage: 1.0,
                warnings,
            })
        }
        StandardView::Planar {
            photo,
            focal_equiv_mm,
            size_px,
        } => {
            let (planar, image) = match avr {
                Some(level @ (AvrLevel::Avr2 | AvrLevel::Avr3)) => {
                    let (planar, job) = planar_view_job(doc, photo, *focal_equiv_mm, *size_px)?;
                    let image = render_job(job, level, on_tile, cancel, &mut warnings)?;
                    (planar, image)
                }
                Some(level) => {
                    let planar = planar_view(doc, photo, *focal_equiv_mm, *size_px)?;
                    let drawn = avr_overlay(doc, photo, level)?.image;
                    let (source, _) = solved_photo(doc, photo)?;
                    let image = reproject(&source, &rgb32f(&drawn), &planar.camera);
                    (planar, image)
                }
                None => {
                    let planar = planar_view(doc, photo, *focal_equiv_mm, *size_px)?;
                    let image = planar.image.clone();
                    (planar, image)
                }
            };
            let geometry = planar_view_geometry(doc, photo, &planar.camera, options)?;
            let camera_json = serde_json::to_string_pretty(&planar.camera)
                .map_err(|e| render_error(photo, &e))?;
            Ok(MadeView {
                image,
                geometry,
                projection_json: Some(("camera.json", camera_json)),
                coverage: planar.coverage,
                warnings,
            })
        }
        StandardView::Cylindrical {
            photos,
            options: cyl,
        } => {
            let ids: Vec<&str> = photos.iter().map(String::as_str).collect();
            let mut loaded = ids
                .iter()
                .map(|id| solved_photo(doc, id))
                .collect::<Result<Vec<_>, _>>()?;
            // One point first: refuse before rendering anything.
            let as_taken: Vec<PanoramaPhoto<'_>> = ids
                .iter()
                .zip(&loaded)
                .map(|(id, (camera, image))| PanoramaPhoto { id, camera, image })
                .collect();
            common_centre(&as_taken, cyl.max_centre_spread_m)?;
            if let Some(level) = avr {
                for (id, (_, image)) in ids.iter().zip(loaded.iter_mut()) {
                    *image = rgb32f(&photo_avr_image(
                        doc,
                        id,
                        level,
                        on_tile,
                        cancel,
                        &mut warnings,
                    )?);
                }
            }
            let panorama_photos: Vec<PanoramaPhoto<'_>> = ids
                .iter()
                .zip(&loaded)
                .map(|(id, (camera, image))| PanoramaPhoto { id, camera, image })
                .collect();
            let made = cylindrical_view(&panorama_photos, cyl)?;
            let geometry = cylindrical_view_geometry(doc, &ids, &made.cylinder, options)?;
            let cylinder_json = serde_json::to_string_pretty(&made.cylinder)
                .map_err(|e| render_error(&ids.join("+"), &e))?;
            let coverage = coverage(&made.image);
            Ok(MadeView {
                image: made.image,
                geometry,
                projection_json: Some(("cylinder.json", cylinder_json)),
                coverage,
                warnings,
            })
        }
    }
}
