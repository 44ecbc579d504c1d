//! The render jobs of the studio's Render panel, as `photomontage render` runs them: the site
//! prepared by the library (`photomontage::site::render::prepare_view`), the panel's quality
//! override, the differential tracer (`photomontage::render::DifferentialTracer`, Debevec 1998
//! differential rendering) driven by `photomontage::render::render_view`, and the AVR0/AVR1
//! overlays of `photomontage::verified` (LVMF Appendix C). Public so that tests compare the
//! panel's render with the library's.
//!
//! # Known limitations
//! Spectral mode and the auxiliary EXR layers are not offered (use the CLI).

use photomontage::colour::ToneMap;
use photomontage::colour::tonemap::ToneCurve;
use photomontage::render::{
    DifferentialTracer, RenderError, RenderedImage, TileProgress, render_view,
};
use photomontage::site::SiteDocument;
use photomontage::site::render::{ViewJob, prepare_view};
use photomontage::verified::{AvrLevel, apply_massing, avr_overlay};
use std::sync::atomic::AtomicBool;

/// Quality settings chosen in the panel (override the site's `[render]` table).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Quality {
    /// Rays per pixel at least (multiple of 4).
    pub spp_min: u32,
    /// Rays per pixel at most (multiple of 4, ≥ `spp_min`).
    pub spp_max: u32,
    /// Seed of the sample positions.
    pub seed: u64,
    /// Accurate Visual Representation level of the view.
    pub avr: AvrLevel,
}

impl Default for Quality {
    fn default() -> Self {
        Self {
            spp_min: 4,
            spp_max: 16,
            seed: 0,
            avr: AvrLevel::Avr3,
        }
    }
}

/// Why a render could not start or finish.
#[derive(Debug, thiserror::Error)]
pub enum RenderPanelError {
    /// The photo has no solved orientation.
    #[error("photo {photo} is not solved yet: press Solve first")]
    NotSolved { photo: String },
    /// Rays per pixel not a positive multiple of 4 or min above max.
    #[error(
        "rays per pixel {spp_min}–{spp_max}: both must be multiples of 4, 4 or more, min ≤ max"
    )]
    BadQuality { spp_min: u32, spp_max: u32 },
    /// The site could not be prepared (no models, unreadable model, …).
    #[error("cannot render {photo}: {message}")]
    Prepare { photo: String, message: String },
    /// The renderer failed.
    #[error("render of {photo} failed: {message}")]
    Render { photo: String, message: String },
    /// The user cancelled.
    #[error("render of {photo} cancelled")]
    Cancelled { photo: String },
    /// Nothing rendered for this photo yet.
    #[error("nothing to export: render the photo first")]
    NothingToExport,
    /// Writing the file failed.
    #[error(transparent)]
    Export(#[from] photomontage::render::OutputError),
    /// The verified-view sheet could not be made or written.
    #[error(transparent)]
    Sheet(#[from] Box<photomontage::verified::sheet::SheetError>),
}

/// The tone map of the site (its `render.exposure`, clamped), as the CLI uses.
#[must_use]
pub fn site_tone_map(doc: &SiteDocument) -> ToneMap {
    ToneMap {
        exposure_stops: doc.site.render.exposure.log2(),
        curve: ToneCurve::Clamp,
    }
}

/// Renders `photo_id` of `doc` as the panel does (prepare, quality override, trace), calling
/// `on_tile` per finished tile. Used by the worker; public so that tests can compare.
///
/// # Errors
/// [`RenderPanelError`] variants `NotSolved`, `BadQuality`, `Prepare`, `Render`, `Cancelled`.
pub fn render_photo(
    doc: &SiteDocument,
    photo_id: &str,
    quality: Quality,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<RenderedImage, RenderPanelError> {
    let job = prepare_photo(doc, photo_id, quality)?;
    trace_photo(&job, photo_id, on_tile, cancel)
}

/// Prepares the render of `photo_id` as the panel does (site → scene, lighting, camera,
/// linear photo; quality override).
///
/// # Errors
/// [`RenderPanelError`] variants `NotSolved`, `BadQuality`, `Prepare`.
pub fn prepare_photo(
    doc: &SiteDocument,
    photo_id: &str,
    quality: Quality,
) -> Result<ViewJob, RenderPanelError> {
    let photo = photo_id.to_owned();
    if !doc
        .site
        .photos
        .iter()
        .any(|p| p.id == photo_id && p.exterior.is_some())
    {
        return Err(RenderPanelError::NotSolved { photo });
    }
    let Quality {
        spp_min,
        spp_max,
        seed,
        avr,
    } = quality;
    if spp_min < 4 || spp_min % 4 != 0 || spp_max % 4 != 0 || spp_min > spp_max {
        return Err(RenderPanelError::BadQuality { spp_min, spp_max });
    }
    let mut job = prepare_view(doc, photo_id).map_err(|e| RenderPanelError::Prepare {
        photo: photo.clone(),
        message: e.to_string(),
    })?;
    job.settings.min_rays_per_pixel = spp_min;
    job.settings.max_rays_per_pixel = spp_max;
    job.settings.seed = seed;
    if avr == AvrLevel::Avr2 {
        apply_massing(&mut job.scene.scene).map_err(|e| RenderPanelError::Prepare {
            photo: photo.clone(),
            message: e.to_string(),
        })?;
    }
    Ok(job)
}

/// AVR0/AVR1: the silhouette or wireline of `photo_id` drawn over the photo.
///
/// # Errors
/// [`RenderPanelError::Prepare`] with the library's message (unsolved photo, no model, …).
pub fn overlay_photo(
    doc: &SiteDocument,
    photo_id: &str,
    avr: AvrLevel,
) -> Result<RenderedImage, RenderPanelError> {
    avr_overlay(doc, photo_id, avr)
        .map(|o| o.image)
        .map_err(|e| RenderPanelError::Prepare {
            photo: photo_id.to_owned(),
            message: e.to_string(),
        })
}

/// Traces a prepared job, calling `on_tile` per finished tile.
///
/// # Errors
/// [`RenderPanelError`] variants `Prepare`, `Render`, `Cancelled`.
pub fn trace_photo(
    job: &ViewJob,
    photo_id: &str,
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<RenderedImage, RenderPanelError> {
    let photo = photo_id.to_owned();
    let tracer = DifferentialTracer::new(
        &job.scene.scene,
        &job.lighting,
        &job.camera,
        &job.photo_linear,
        job.settings.max_depth,
    )
    .map_err(|e| RenderPanelError::Prepare {
        photo: photo.clone(),
        message: e.to_string(),
    })?;
    render_view(&tracer, &job.settings, on_tile, cancel).map_err(|e| match e {
        RenderError::Cancelled => RenderPanelError::Cancelled { photo },
        other => RenderPanelError::Render {
            photo,
            message: other.to_string(),
        },
    })
}
