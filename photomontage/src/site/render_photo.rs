//! The one render-photo entry point: a site, a view, the user's overrides and a [`Band`] in; the
//! montage (or one band of it) with its layers, tone map and everything a report or a partial
//! file needs out. The CLI's `render`, the render-farm jobs (`run-job`) and the tests call this,
//! so a band rendered on a farm node is the same computation as the whole-image render.
//!
//! [`RenderPlan::new`] does the cheap checks (view, rays per pixel, exposure, layers with
//! spectral mode, band count against the view's tile rows) before anything is loaded, and fixes
//! the job's **identity**: everything the pixels depend on (the site's content hash, view, mode,
//! settings, seed, exposure, layers, program version). Parts of one view carry it, and the merge
//! refuses parts whose identities differ ([`crate::render::partial`]).
//!
//! # Known limitations
//! The identity hashes the site's content as parsed, not the photos and models it refers to.

use std::collections::BTreeMap;
use std::sync::atomic::AtomicBool;

use nalgebra::Vector3;
use sha2::{Digest, Sha256};

use super::SiteDocument;
use super::render::{
    KeptPhoto, ObjectSource, SiteLightingOptions, SiteRenderError, SiteWarning, prepare_view_kept,
    site_camera,
};
use crate::colour::{SampleSet, ToneMap};
use crate::render::output::{LayerSet, OutputLayers};
use crate::render::partial::{PART_FORMAT, PartInfo, to_hex};
use crate::render::{
    Band, DifferentialTracer, RenderSettings, RenderedImage, TileProgress, render_band_spectral,
    render_band_with_layers,
};
use crate::scene::{Scene, SceneError};

/// Rays per pixel the renderer accepts: multiples of 4 in this range.
pub const SPP_RANGE: std::ops::RangeInclusive<u32> = 4..=64;

/// What the user asks of a render; `None` takes the site's `[render]` value.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderRequest {
    /// The photo id to render into.
    pub view: String,
    /// Fewest rays per pixel.
    pub spp_min: Option<u32>,
    /// Most rays per pixel.
    pub spp_max: Option<u32>,
    /// Seed of the sample positions.
    pub seed: Option<u64>,
    /// Spectral mode (Durisch's 9 samples); `false` takes the site's `render.spectral`.
    pub spectral: bool,
    /// Radiosity lighting mode; `false` takes the site's `render.radiosity`.
    pub radiosity: bool,
    /// Auxiliary EXR layers (RGB mode only).
    pub layers: LayerSet,
    /// Exposure multiplier for 8-bit output.
    pub exposure: Option<f64>,
    /// The band to render ([`Band::WHOLE`] for the whole image).
    pub band: Band,
}

impl RenderRequest {
    /// The whole view with the site's settings.
    #[must_use]
    pub fn view(view: &str) -> Self {
        Self {
            view: view.to_owned(),
            spp_min: None,
            spp_max: None,
            seed: None,
            spectral: false,
            radiosity: false,
            layers: LayerSet::default(),
            exposure: None,
            band: Band::WHOLE,
        }
    }
}

/// A checked request with its settings resolved against the site.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderPlan {
    /// The request as given.
    pub request: RenderRequest,
    /// Spectral mode on (by the request or the site).
    pub spectral: bool,
    /// Radiosity lighting mode on (by the request or the site).
    pub radiosity: bool,
    /// Exposure multiplier for 8-bit output.
    pub exposure: f64,
    /// Whole image size, pixels.
    pub full_size_px: [u32; 2],
    /// The band's pixel rows.
    pub rows_px: [u32; 2],
    /// Everything the pixels depend on (see the module documentation).
    pub identity: BTreeMap<String, String>,
    /// Renderer settings with the overrides applied.
    pub settings: RenderSettings,
    /// Adjustments of the site's settings worth telling.
    pub warnings: Vec<SiteWarning>,
}

fn request_error(field: &'static str, reason: String) -> SiteRenderError {
    SiteRenderError::Request { field, reason }
}

fn check_spp(field: &'static str, n: u32) -> Result<u32, SiteRenderError> {
    if !SPP_RANGE.contains(&n) || !n.is_multiple_of(4) {
        return Err(request_error(
            field,
            format!("{n}: rays per pixel must be a multiple of 4 between 4 and 64"),
        ));
    }
    Ok(n)
}

/// SHA-256 of the site's content (its schema serialised as TOML), lower-case hex.
///
/// # Errors
/// [`SiteRenderError::Request`] if the site cannot be serialised.
pub fn site_content_sha256(doc: &SiteDocument) -> Result<String, SiteRenderError> {
    let text = toml::to_string(&doc.site)
        .map_err(|e| request_error("site", format!("cannot serialise the site: {e}")))?;
    Ok(to_hex(&Sha256::digest(text.as_bytes())))
}

impl RenderPlan {
    /// Checks `request` against `doc` without loading photos or models.
    ///
    /// # Errors
    /// [`SiteRenderError::UnknownView`], [`SiteRenderError::NotSolved`] and the other camera
    /// errors, [`SiteRenderError::Request`] for rays per pixel, exposure, layers in spectral mode
    /// and a band the view cannot be cut into.
    pub fn new(doc: &SiteDocument, request: &RenderRequest) -> Result<Self, SiteRenderError> {
        let camera = site_camera(doc, &request.view)?;
        let (mut settings, warnings) = super::render::site_render_settings(&doc.site.render);
        if let Some(n) = request.spp_min {
            settings.min_rays_per_pixel = check_spp("spp_min", n)?;
        }
        if let Some(n) = request.spp_max {
            settings.max_rays_per_pixel = check_spp("spp_max", n)?;
        }
        if settings.min_rays_per_pixel > settings.max_rays_per_pixel {
            return Err(request_error(
                "spp_min",
                format!(
                    "{} is above spp_max {}",
                    settings.min_rays_per_pixel, settings.max_rays_per_pixel
                ),
            ));
        }
        if settings.max_depth > crate::render::MAX_DEPTH_LIMIT {
            return Err(request_error(
                "max_depth",
                format!(
                    "{} is above the limit {}",
                    settings.max_depth,
                    crate::render::MAX_DEPTH_LIMIT
                ),
            ));
        }
        if let Some(seed) = request.seed {
            settings.seed = seed;
        }
        let spectral = request.spectral || doc.site.render.spectral;
        if spectral && !request.layers.is_empty() {
            return Err(request_error(
                "layers",
                format!(
                    "{} are computed in RGB mode only; render without spectral mode (and with \
                     render.spectral = false) to get them",
                    request.layers.names()
                ),
            ));
        }
        let radiosity = request.radiosity || doc.site.render.radiosity;
        let exposure = request.exposure.unwrap_or(doc.site.render.exposure);
        if !(exposure.is_finite() && exposure > 0.0) {
            return Err(request_error(
                "exposure",
                format!("{exposure} must be a finite positive multiplier"),
            ));
        }
        let full_size_px = camera.intrinsics.image_size_px;
        let rows = request
            .band
            .pixel_rows(full_size_px[1], settings.tile_size_px)
            .map_err(|e| request_error("tile", format!("view {}: {e}", request.view)))?;
        let mode = if spectral { "spectral Durisch9" } else { "rgb" };
        let mut identity: BTreeMap<String, String> = [
            ("site_sha256", site_content_sha256(doc)?),
            ("view", request.view.clone()),
            ("mode", mode.to_owned()),
            (
                "rays_per_pixel",
                format!(
                    "{}-{}",
                    settings.min_rays_per_pixel, settings.max_rays_per_pixel
                ),
            ),
            ("seed", settings.seed.to_string()),
            ("max_depth", settings.max_depth.to_string()),
            (
                "max_standard_error",
                settings.max_standard_error.to_string(),
            ),
            ("tile_px", settings.tile_size_px.to_string()),
            ("layers", request.layers.names()),
            ("exposure", exposure.to_string()),
            ("version", env!("CARGO_PKG_VERSION").to_owned()),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect();
        if radiosity {
            identity.insert("lighting".to_owned(), "radiosity".to_owned());
        }
        Ok(Self {
            request: request.clone(),
            spectral,
            radiosity,
            exposure,
            full_size_px,
            rows_px: [rows.start, rows.end],
            identity,
            settings,
            warnings,
        })
    }

    /// Render tiles in the band (for a progress bar).
    #[must_use]
    pub fn tile_count(&self) -> u64 {
        let ts = self.settings.tile_size_px.max(1);
        let rows = (self.rows_px[1] - self.rows_px[0]).div_ceil(ts);
        u64::from(self.full_size_px[0].div_ceil(ts) * rows)
    }

    /// The tone map of 8-bit output: the exposure, clamped.
    #[must_use]
    pub fn tone_map(&self) -> ToneMap {
        ToneMap::clamp_with_exposure(self.exposure)
    }

    /// Loads the view (scene, lights, photo) and renders the band. `on_tile` reports each
    /// finished tile; raising `cancel` stops at the next tile.
    ///
    /// # Errors
    /// Any error of [`prepare_view`], [`SiteRenderError::Render`].
    pub fn render(
        &self,
        doc: &SiteDocument,
        on_tile: &(dyn Fn(TileProgress) + Sync),
        cancel: &AtomicBool,
    ) -> Result<RenderedPhoto, SiteRenderError> {
        self.render_edited(doc, &|_| Ok(()), on_tile, cancel)
    }

    /// The band of the photo itself, unchanged (alpha 0: no artificial coverage).
    fn photo_band(&self, job: &super::render::ViewJob) -> RenderedPhoto {
        let [w, _] = self.full_size_px;
        let [y0, y1] = self.rows_px;
        let rgba = (y0..y1)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                let p = job.photo_linear.get_pixel(x, y).0;
                [p[0], p[1], p[2], 0.0]
            })
            .collect();
        RenderedPhoto {
            image: RenderedImage {
                size_px: [w, y1 - y0],
                rgba,
                changed_pixels: 0,
                primary_rays: 0,
            },
            layers: OutputLayers::default(),
            object_names: Vec::new(),
            sun_dir_in_world: job.sun_dir_in_world,
            warnings: job.warnings.clone(),
            // Nothing is added, so nothing is solved.
            radiosity: None,
        }
    }

    /// [`RenderPlan::render`] with `edit` applied to the scene before tracing (e.g. the AVR2
    /// massing material). Record the edit in [`RenderPlan::identity`] when parts are written.
    ///
    /// # Errors
    /// As [`RenderPlan::render`], and the edit's [`SceneError`].
    pub fn render_edited(
        &self,
        doc: &SiteDocument,
        edit: &dyn Fn(&mut Scene) -> Result<(), SceneError>,
        on_tile: &(dyn Fn(TileProgress) + Sync),
        cancel: &AtomicBool,
    ) -> Result<RenderedPhoto, SiteRenderError> {
        let mut prepared = self.prepare(doc, edit)?;
        let radiosity = self.solve_radiosity(doc, &mut prepared, cancel)?;
        let mut rendered = self.trace(&prepared, &self.settings, on_tile, cancel)?;
        rendered.radiosity = radiosity;
        Ok(rendered)
    }

    /// The first step of [`RenderPlan::render_edited`]: the view loaded (scene, lights, camera,
    /// photo) and `edit` applied to its scene. The studio prepares once and traces its passes
    /// (a coarse one, then the full one) from the same preparation.
    ///
    /// # Errors
    /// Any error of [`prepare_view`], and the edit's [`SceneError`].
    pub fn prepare(
        &self,
        doc: &SiteDocument,
        edit: &dyn Fn(&mut Scene) -> Result<(), SceneError>,
    ) -> Result<PreparedView, SiteRenderError> {
        self.prepare_kept(doc, edit, None)
    }

    /// [`Self::prepare`], taking the photo from `kept` where it holds the view's file unchanged
    /// and keeping the one it loads there otherwise
    /// ([`super::render::site_photo_linear_kept`]: the studio's live renders).
    ///
    /// # Errors
    /// As [`Self::prepare`].
    pub fn prepare_kept(
        &self,
        doc: &SiteDocument,
        edit: &dyn Fn(&mut Scene) -> Result<(), SceneError>,
        kept: Option<&mut Option<KeptPhoto>>,
    ) -> Result<PreparedView, SiteRenderError> {
        let mut job = prepare_view_kept(
            doc,
            &self.request.view,
            &SiteLightingOptions::default(),
            kept,
        )?;
        edit(&mut job.scene.scene)?;
        // Only a design variant gets here without a model (prepare_view refuses the site
        // itself): nothing is added, the band is the photo.
        let photo_only = job
            .scene
            .object_sources
            .iter()
            .all(|s| !matches!(s, ObjectSource::Model(_)))
            && self.request.layers.is_empty();
        Ok(PreparedView { job, photo_only })
    }

    /// In the radiosity mode, solves the site's radiosity for the prepared scene and hands it
    /// to its lighting ([`super::render_radiosity::site_radiosity_arc`]); the report, or `None`
    /// when the mode is off or nothing is added. The studio hands its kept transfers' light
    /// instead ([`super::live_relight`]).
    ///
    /// # Errors
    /// A solve error as [`SiteRenderError::Request`], [`SiteRenderError::Render`] when cancelled.
    pub fn solve_radiosity(
        &self,
        doc: &SiteDocument,
        prepared: &mut PreparedView,
        cancel: &AtomicBool,
    ) -> Result<Option<super::render_radiosity::RadiosityReport>, SiteRenderError> {
        if !self.radiosity || prepared.photo_only {
            return Ok(None);
        }
        let job = &prepared.job;
        let photo = super::photo_reflectance::PhotoView {
            camera: &job.camera,
            photo_linear: &job.photo_linear,
            lighting: &job.lighting,
        };
        let photo = doc.site.render.photo_reflectance.then_some(&photo);
        if self.spectral {
            // One solve per spectral pass ([`super::spectral_radiosity`]).
            let (light, report) = super::spectral_radiosity::site_spectral_radiosity(
                doc,
                &job.scene.scene,
                &self.request.view,
                photo,
                SampleSet::Durisch9,
                cancel,
            )?;
            prepared.job.lighting.radiosity_spectral = Some(std::sync::Arc::new(light));
            return Ok(Some(report));
        }
        let (light, report) = super::render_radiosity::site_radiosity_arc(
            doc,
            &job.scene.scene,
            &self.request.view,
            photo,
            cancel,
        )?;
        prepared.job.lighting.radiosity = Some(light);
        Ok(Some(report))
    }

    /// Traces the plan's band of a prepared view with `settings` (the plan's, or the same with
    /// other rays per pixel for a coarse pass; the seed and tiles are the caller's to keep).
    ///
    /// # Errors
    /// [`SiteRenderError::Render`] (a cancelled render included), a tracer error.
    pub fn trace(
        &self,
        prepared: &PreparedView,
        settings: &RenderSettings,
        on_tile: &(dyn Fn(TileProgress) + Sync),
        cancel: &AtomicBool,
    ) -> Result<RenderedPhoto, SiteRenderError> {
        let job = &prepared.job;
        if prepared.photo_only {
            return Ok(self.photo_band(job));
        }
        let tracer = DifferentialTracer::new(
            &job.scene.scene,
            &job.lighting,
            &job.camera,
            &job.photo_linear,
            settings.max_depth,
        )?;
        let band = self.request.band;
        let (image, layers) = if self.spectral {
            let image = render_band_spectral(
                &tracer,
                settings,
                SampleSet::Durisch9,
                band,
                on_tile,
                cancel,
            )?;
            (image, OutputLayers::default())
        } else {
            render_band_with_layers(
                &tracer,
                settings,
                self.request.layers,
                band,
                on_tile,
                cancel,
            )?
        };
        let mut warnings = job.warnings.clone();
        warnings.extend(self.warnings.iter().cloned());
        warnings.dedup();
        Ok(RenderedPhoto {
            image,
            layers,
            object_names: job
                .scene
                .object_sources
                .iter()
                .map(ObjectSource::label)
                .collect(),
            sun_dir_in_world: job.sun_dir_in_world,
            warnings,
            radiosity: None,
        })
    }

    /// What a part of this plan says of itself, given its render.
    #[must_use]
    pub fn part_info(&self, rendered: &RenderedPhoto) -> PartInfo {
        PartInfo {
            format: PART_FORMAT.to_owned(),
            tile: self.request.band.to_string(),
            full_size_px: self.full_size_px,
            rows_px: self.rows_px,
            identity: self.identity.clone(),
            exposure: self.exposure,
            object_names: self
                .request
                .layers
                .object_id
                .then(|| rendered.object_names.clone()),
            changed_pixels: rendered.image.changed_pixels,
            primary_rays: rendered.image.primary_rays,
            view_json: None,
        }
    }
}

/// A view loaded for a plan ([`RenderPlan::prepare`]): the scene with the plan's edit applied,
/// lights, camera and photo.
#[derive(Debug)]
pub struct PreparedView {
    /// The loaded view; its lighting takes the radiosity light in the radiosity mode.
    pub job: super::render::ViewJob,
    /// Nothing is added (a design variant without models): the band is the photo.
    pub photo_only: bool,
}

/// A rendered view or band.
#[derive(Debug, Clone)]
pub struct RenderedPhoto {
    /// The band's pixels (the whole image for [`Band::WHOLE`]).
    pub image: RenderedImage,
    /// The band's layers.
    pub layers: OutputLayers,
    /// Scene object names by object id.
    pub object_names: Vec<String>,
    /// The sun direction used (survey frame), if any.
    pub sun_dir_in_world: Option<Vector3<f64>>,
    /// Scene warnings and setting adjustments.
    pub warnings: Vec<SiteWarning>,
    /// The radiosity precompute, in the radiosity lighting mode.
    pub radiosity: Option<super::render_radiosity::RadiosityReport>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn street() -> SiteDocument {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../sample_sites/street/site.toml");
        SiteDocument::load(&path).unwrap()
    }

    #[test]
    fn bad_requests_are_refused_before_anything_loads() {
        let doc = street();
        // The street sample is unsolved as shipped: the camera error comes first.
        let err = RenderPlan::new(&doc, &RenderRequest::view("V1")).unwrap_err();
        assert!(matches!(err, SiteRenderError::NotSolved { .. }), "{err}");
        let err = RenderPlan::new(&doc, &RenderRequest::view("nope")).unwrap_err();
        assert!(err.to_string().contains("nope"), "{err}");
    }

    #[test]
    fn radiosity_mode_is_in_the_identity_with_or_without_spectral_mode() {
        let mut doc = street();
        let solution = crate::site::solve_site(&doc);
        crate::site::apply_solution(&mut doc.site, &solution);
        let plain = RenderPlan::new(&doc, &RenderRequest::view("V1")).unwrap();
        assert!(!plain.radiosity && !plain.identity.contains_key("lighting"));
        let request = RenderRequest {
            radiosity: true,
            ..RenderRequest::view("V1")
        };
        let plan = RenderPlan::new(&doc, &request).unwrap();
        assert!(plan.radiosity);
        assert_eq!(plan.identity["lighting"], "radiosity");
        // The site's setting turns it on as the request does.
        let mut on = doc.clone();
        on.site.render.radiosity = true;
        assert!(
            RenderPlan::new(&on, &RenderRequest::view("V1"))
                .unwrap()
                .radiosity
        );
        // With spectral mode: both, and both in the identity (a part of one is not a part of
        // the other).
        let both = RenderPlan::new(
            &doc,
            &RenderRequest {
                spectral: true,
                ..request
            },
        )
        .unwrap();
        assert!(both.radiosity && both.spectral);
        assert_eq!(both.identity["lighting"], "radiosity");
        assert_eq!(both.identity["mode"], "spectral Durisch9");
    }

    #[test]
    fn the_content_hash_follows_the_content_not_the_path() {
        let doc = street();
        let mut moved = doc.clone();
        moved.path = "/elsewhere/site.toml".into();
        assert_eq!(
            site_content_sha256(&doc).unwrap(),
            site_content_sha256(&moved).unwrap()
        );
        let mut changed = doc.clone();
        changed.site.render.seed += 1;
        assert_ne!(
            site_content_sha256(&doc).unwrap(),
            site_content_sha256(&changed).unwrap()
        );
        assert_eq!(site_content_sha256(&doc).unwrap().len(), 64);
    }
}
