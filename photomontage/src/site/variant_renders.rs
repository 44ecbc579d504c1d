//! Every design variant of one view rendered under the same light (issue 17 item 4), for the
//! CLI's `compare` and the studio's Variants tab: each variant's document is
//! [`super::variants::variant_document`] (the one way a variant is applied) and its render is
//! the one render entry point, [`RenderPlan`], with the same request (view, rays per pixel,
//! seed, exposure) for all. So a variant's pixels here are the pixels of
//! `photomontage render --variant NAME` with the same options, bit for bit.
//!
//! [`plan_variants`] checks every variant and every plan before anything is loaded;
//! [`VariantJob::render`] then renders one variant (loading its scene, photo and lights).
//!
//! # Known limitations
//! Variants are rendered one after the other (each uses all the worker threads); the scene is
//! built anew for each variant, also where two variants differ in a material only.

use std::sync::atomic::AtomicBool;

use image::RgbImage;

use super::SiteDocument;
use super::render::SiteRenderError;
use super::render_photo::{RenderPlan, RenderRequest, RenderedPhoto};
use super::variants::{VariantError, checked_variant_names, variant_document};
use crate::colour::encode_srgb8;
use crate::render::TileProgress;

/// Why the variants cannot be rendered.
#[derive(Debug, thiserror::Error)]
pub enum VariantRenderError {
    /// A variant is unknown, names a model the site does not have, has a bad material, …
    #[error(transparent)]
    Variant(#[from] VariantError),
    /// The render request does not fit this variant's document (unsolved view, rays per
    /// pixel, …), or the render failed.
    #[error("variant `{variant}`: {source}")]
    Render {
        variant: String,
        source: Box<SiteRenderError>,
    },
}

/// One variant, checked and planned, not rendered yet.
#[derive(Debug, Clone)]
pub struct VariantJob {
    /// The variant's name.
    pub name: String,
    /// The site document as the variant sees it ([`variant_document`]).
    pub document: SiteDocument,
    /// Its render plan; the identity carries the variant's name.
    pub plan: RenderPlan,
}

/// One variant's render.
#[derive(Debug, Clone)]
pub struct VariantRender {
    /// The variant's name.
    pub name: String,
    /// Its render plan (settings, tone map).
    pub plan: RenderPlan,
    /// The render (linear, with layers and warnings).
    pub photo: RenderedPhoto,
    /// The render as 8-bit sRGB with the plan's tone map (what the sheets show).
    pub srgb: RgbImage,
}

/// Checks the variants `requested` (all of the site's, in file order, for `None`) and plans
/// each with `request`, before any file is loaded.
///
/// # Errors
/// [`VariantRenderError::Variant`] (see [`checked_variant_names`]), and
/// [`VariantRenderError::Render`] for a request the plan refuses.
pub fn plan_variants(
    doc: &SiteDocument,
    requested: Option<&[String]>,
    request: &RenderRequest,
) -> Result<Vec<VariantJob>, VariantRenderError> {
    let names = checked_variant_names(&doc.site, requested)?;
    names
        .into_iter()
        .map(|name| {
            let document = variant_document(doc, Some(&name))?;
            let mut plan = RenderPlan::new(&document, request).map_err(|source| {
                VariantRenderError::Render {
                    variant: name.clone(),
                    source: Box::new(source),
                }
            })?;
            // Parts of two variants must not merge.
            plan.identity.insert("variant".into(), name.clone());
            Ok(VariantJob {
                name,
                document,
                plan,
            })
        })
        .collect()
}

/// The 8-bit sRGB image of a render with `plan`'s tone map.
#[must_use]
pub fn srgb_of(photo: &RenderedPhoto, plan: &RenderPlan) -> RgbImage {
    let tone_map = plan.tone_map();
    let [w, h] = photo.image.size_px;
    RgbImage::from_fn(w, h, |x, y| {
        let p = photo.image.rgba[(y * w + x) as usize];
        image::Rgb(encode_srgb8([p[0], p[1], p[2]], &tone_map))
    })
}

impl VariantJob {
    /// Renders the variant ([`RenderPlan::render`] on its document).
    ///
    /// # Errors
    /// [`VariantRenderError::Render`] naming the variant (a cancel is
    /// [`crate::render::RenderError::Cancelled`] inside it).
    pub fn render(
        &self,
        on_tile: &(dyn Fn(TileProgress) + Sync),
        cancel: &AtomicBool,
    ) -> Result<VariantRender, VariantRenderError> {
        let photo = self
            .plan
            .render(&self.document, on_tile, cancel)
            .map_err(|source| VariantRenderError::Render {
                variant: self.name.clone(),
                source: Box::new(source),
            })?;
        let srgb = srgb_of(&photo, &self.plan);
        Ok(VariantRender {
            name: self.name.clone(),
            plan: self.plan.clone(),
            photo,
            srgb,
        })
    }
}
