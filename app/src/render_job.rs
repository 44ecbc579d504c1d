//! The render jobs of the studio's Render panel, through the entry point `photomontage render`
//! uses (`photomontage::site::render_photo::RenderPlan`: the panel's quality as the request,
//! checked as the CLI checks it; the view prepared once and traced per pass), and the AVR0/AVR1
//! overlays of `photomontage::verified` (LVMF Appendix C). Public so that tests compare the
//! panel's render with the library's.
//!
//! # Known limitations
//! The auxiliary EXR layers are not offered (use the CLI); spectral mode follows the site's
//! `render.spectral`, as the CLI's does without `--spectral`.

use photomontage::colour::ToneMap;
use photomontage::colour::tonemap::ToneCurve;
use photomontage::render::{RenderError, RenderSettings, RenderedImage, TileProgress};
use photomontage::site::SiteDocument;
use photomontage::site::render::{KeptPhoto, SiteRenderError};
use photomontage::site::render_photo::{PreparedView, RenderPlan, RenderRequest, SPP_RANGE};
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
    /// Rays per pixel not a multiple of 4 in 4–64 (the CLI's range) or min above max.
    #[error(
        "rays per pixel {spp_min}–{spp_max}: both must be multiples of 4 from 4 to 64, min ≤ max"
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
/// `on_tile` per finished tile. Public so that tests can compare.
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
    let spp = (quality.spp_min, quality.spp_max);
    trace_photo(&job, spp, on_tile, cancel)
}

/// A render of the panel: the library's plan (`photomontage::site::render_photo::RenderPlan`,
/// the CLI's `render` entry point) with the panel's quality as its request, and the view it
/// prepared.
#[derive(Debug)]
pub struct PhotoJob {
    /// The checked request.
    pub plan: RenderPlan,
    /// The loaded view (its lighting takes the kept transfers' light in the radiosity mode).
    pub prepared: PreparedView,
}

/// Prepares the render of `photo_id` as the panel does: the panel's quality as a
/// [`RenderRequest`] checked by [`RenderPlan::new`] (the CLI's checks), the view loaded by
/// [`RenderPlan::prepare`], with the AVR2 massing material as its edit.
///
/// # Errors
/// [`RenderPanelError`] variants `NotSolved`, `BadQuality`, `Prepare`.
pub fn prepare_photo(
    doc: &SiteDocument,
    photo_id: &str,
    quality: Quality,
) -> Result<PhotoJob, RenderPanelError> {
    prepare_photo_kept(doc, photo_id, quality, None)
}

/// [`prepare_photo`], taking the decoded photo from `kept` where it holds the view's file
/// unchanged and keeping the one it loads there otherwise (the live preview's renders: an edit
/// does not decode the photo again).
///
/// # Errors
/// As [`prepare_photo`].
pub fn prepare_photo_kept(
    doc: &SiteDocument,
    photo_id: &str,
    quality: Quality,
    kept: Option<&mut Option<KeptPhoto>>,
) -> Result<PhotoJob, RenderPanelError> {
    let photo = photo_id.to_owned();
    let Quality {
        spp_min,
        spp_max,
        seed,
        avr,
    } = quality;
    let in_range = |n: u32| SPP_RANGE.contains(&n) && n.is_multiple_of(4);
    if !in_range(spp_min) || !in_range(spp_max) || spp_min > spp_max {
        return Err(RenderPanelError::BadQuality { spp_min, spp_max });
    }
    if !doc
        .site
        .photos
        .iter()
        .any(|p| p.id == photo_id && p.exterior.is_some())
    {
        return Err(RenderPanelError::NotSolved { photo });
    }
    let prepare_error = |e: &dyn std::fmt::Display| RenderPanelError::Prepare {
        photo: photo.clone(),
        message: e.to_string(),
    };
    let request = RenderRequest {
        spp_min: Some(spp_min),
        spp_max: Some(spp_max),
        seed: Some(seed),
        ..RenderRequest::view(photo_id)
    };
    let plan = RenderPlan::new(doc, &request).map_err(|e| prepare_error(&e))?;
    let massing = avr == AvrLevel::Avr2;
    let prepared = plan
        .prepare_kept(
            doc,
            &|scene| {
                if massing {
                    apply_massing(scene)?;
                }
                Ok(())
            },
            kept,
        )
        .map_err(|e| prepare_error(&e))?;
    Ok(PhotoJob { plan, prepared })
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

/// Traces a prepared job with `spp` = (min, max) rays per pixel ([`RenderPlan::trace`]), calling
/// `on_tile` per finished tile.
///
/// # Errors
/// [`RenderPanelError`] variants `Prepare`, `Render`, `Cancelled`.
pub fn trace_photo(
    job: &PhotoJob,
    (spp_min, spp_max): (u32, u32),
    on_tile: &(dyn Fn(TileProgress) + Sync),
    cancel: &AtomicBool,
) -> Result<RenderedImage, RenderPanelError> {
    let photo = job.plan.request.view.clone();
    let settings = RenderSettings {
        min_rays_per_pixel: spp_min,
        max_rays_per_pixel: spp_max,
        ..job.plan.settings
    };
    job.plan
        .trace(&job.prepared, &settings, on_tile, cancel)
        .map(|rendered| rendered.image)
        .map_err(|e| match e {
            SiteRenderError::Render(RenderError::Cancelled) => {
                RenderPanelError::Cancelled { photo }
            }
            SiteRenderError::Render(other) => RenderPanelError::Render {
                photo,
                message: other.to_string(),
            },
            other => RenderPanelError::Prepare {
                photo,
                message: other.to_string(),
            },
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The panel's quality is checked as the CLI checks rays per pixel (multiples of 4 from 4
    /// to 64, min ≤ max) before anything is loaded; a good quality on an unsolved photo is
    /// `NotSolved`.
    #[test]
    fn quality_is_checked_as_the_cli_checks_it() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../sample_sites/courtyard/site.toml");
        let doc = SiteDocument::load(&path).expect("sample site");
        let id = doc.site.photos[0].id.clone();
        let with = |spp_min, spp_max| Quality {
            spp_min,
            spp_max,
            ..Quality::default()
        };
        for (lo, hi) in [(4, 128), (0, 16), (6, 16), (16, 8)] {
            let e = prepare_photo(&doc, &id, with(lo, hi)).unwrap_err();
            assert!(
                matches!(e, RenderPanelError::BadQuality { spp_min, spp_max } if (spp_min, spp_max) == (lo, hi)),
                "{lo}–{hi}: {e}"
            );
        }
        assert!(matches!(
            prepare_photo(&doc, &id, with(4, 64)).unwrap_err(),
            RenderPanelError::NotSolved { .. }
        ));
    }
}
