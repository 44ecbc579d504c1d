//! The unfolded elevation of one CAD model of a site ([`crate::design::unfolded`]): the site's
//! scene from [`super::site_scene::site_scene`] (so `[[materials]]` colours show), and for the
//! irradiance view a radiosity transfer lit by
//! [`super::radiosity_lighting::site_transfer_lighting`].

use std::sync::atomic::AtomicBool;

use super::SiteDocument;
use super::radiosity_lighting::{site_ground_below_horizon, site_transfer_lighting};
use super::render_error::SiteRenderError;
use super::site_scene::{ObjectSource, site_scene};
use crate::design::unfolded::{
    Shading, UnfoldError, UnfoldParams, UnfoldedImage, UnfoldedLayout, draw, unfold,
};
use crate::radiosity::{RadiosityError, Transfer, TransferParams};
use crate::scene::ObjectId;

/// Errors of the site elevation.
#[derive(Debug, thiserror::Error)]
pub enum ElevationError {
    /// No visible model of that id.
    #[error("no visible model `{model}` in the site; models: {}", valid.join(", "))]
    UnknownModel {
        /// The id given.
        model: String,
        /// The visible models.
        valid: Vec<String>,
    },
    /// The scene or lighting could not be built.
    #[error(transparent)]
    Site(#[from] SiteRenderError),
    /// Layout error.
    #[error(transparent)]
    Unfold(#[from] UnfoldError),
    /// The radiosity solve failed (or was cancelled).
    #[error("radiosity: {0}")]
    Radiosity(#[from] RadiosityError),
}

/// How to light the irradiance view.
pub struct ElevationLighting<'a> {
    /// Transfer (mesh, solver) parameters; `solve.ground` is set from the site.
    pub params: TransferParams,
    /// The photo whose capture time places the sun.
    pub view: String,
    /// Raised to cancel the solve.
    pub cancel: &'a AtomicBool,
}

/// One façade's summary: its layout and the irradiance at the centre of its panel.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FacadeSummary {
    /// Azimuth of the outward normal, degrees from north.
    pub azimuth_deg: f64,
    /// Width, metres.
    pub width_m: f64,
    /// Left edge and width of the panel, pixels.
    pub x0_px: u32,
    /// Panel width, pixels.
    pub width_px: u32,
    /// The pixel at the panel's centre.
    pub centre_px: [u32; 2],
    /// Irradiance (luminance Y, site units) at the world point behind the centre pixel, from
    /// `Solution::irradiance_at`; `None` without a solve or where no element is.
    pub centre_irradiance_y: Option<f64>,
}

/// A drawn elevation with its summaries and the build's warnings.
pub struct SiteElevation {
    /// The layout.
    pub layout: UnfoldedLayout,
    /// The picture.
    pub image: UnfoldedImage,
    /// Per façade, left to right.
    pub facades: Vec<FacadeSummary>,
    /// Warnings (scene and lighting notes) as text.
    pub warnings: Vec<String>,
}

impl SiteElevation {
    /// The picture as PNG bytes: what `photomontage elevation --out` writes and the studio's
    /// export writes (one encoder, so the same pixels).
    ///
    /// # Errors
    /// The PNG encoder's error (not expected for an in-memory RGB image).
    pub fn png_bytes(&self) -> Result<Vec<u8>, image::ImageError> {
        let mut bytes = Vec::new();
        self.image.image.write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )?;
        Ok(bytes)
    }
}

/// Draws the unfolded elevation of model `model` of the site: colours, or irradiance when
/// `lighting` is given.
///
/// # Errors
/// [`ElevationError`].
pub fn site_elevation(
    doc: &SiteDocument,
    model: &str,
    params: &UnfoldParams,
    lighting: Option<ElevationLighting<'_>>,
) -> Result<SiteElevation, ElevationError> {
    let site = site_scene(doc)?;
    let mut warnings: Vec<String> = site.warnings.iter().map(ToString::to_string).collect();
    let index = site
        .object_sources
        .iter()
        .position(|s| *s == ObjectSource::Model(model.to_owned()))
        .ok_or_else(|| ElevationError::UnknownModel {
            model: model.to_owned(),
            valid: doc
                .site
                .models
                .iter()
                .filter(|m| m.visible)
                .map(|m| m.id.clone())
                .collect(),
        })?;
    let object = ObjectId(u32::try_from(index).unwrap_or(u32::MAX));
    let layout = unfold(&site.scene, object, params)?;
    let transfer = match lighting {
        None => None,
        Some(l) => {
            let (lights, notes) = site_transfer_lighting(doc, &site.scene, &l.view)?;
            warnings.extend(notes);
            let mut p = l.params;
            p.solve.ground = site_ground_below_horizon(doc, &site.scene)?;
            let (mesh, notes) = p.solve.mesh.sized_for(&site.scene);
            p.solve.mesh = mesh;
            warnings.extend(notes);
            let t = Transfer::build(&site.scene, &lights, &p, l.cancel, &|_| {})?;
            warnings.extend(t.solution().warnings.iter().map(ToString::to_string));
            Some(t)
        }
    };
    let shading = match &transfer {
        Some(t) => Shading::Irradiance(t.solution()),
        None => Shading::Colour,
    };
    let image = draw(&site.scene, &layout, shading);
    let space = crate::colour::rgb::RgbColourSpace::srgb();
    let facades = layout
        .panels
        .iter()
        .map(|panel| {
            let centre_px = [
                panel.x0_px + panel.width_px / 2,
                layout.y0_px + layout.height_px / 2,
            ];
            let centre_irradiance_y = transfer.as_ref().and_then(|t| {
                let (p, _) = crate::design::unfolded::point_at_pixel(
                    &site.scene,
                    &layout,
                    panel,
                    centre_px[0],
                    centre_px[1],
                )?;
                t.solution()
                    .irradiance_at(&p, &panel.normal_in_world)
                    .map(|s| space.luminance(s.total_rgb))
            });
            FacadeSummary {
                azimuth_deg: panel.azimuth_deg,
                width_m: panel.width_m(),
                x0_px: panel.x0_px,
                width_px: panel.width_px,
                centre_px,
                centre_irradiance_y,
            }
        })
        .collect();
    Ok(SiteElevation {
        layout,
        image,
        facades,
        warnings,
    })
}
