//! The lighting fits run on a site file (Durisch 1992 §4.2–4.3 on the site's data): the natural
//! scene is built from the site's polygons, each `[[samples]]` entry is located on it (a world
//! point, or the ray through a pixel of its photo's solved camera), its colour read robustly from
//! the photo ([`super::colour`]), L∞ taken from the `[[horizon_samples]]`, then the atmosphere
//! (eq. 7, [`super::atmosphere`]) and the daylight weights (eq. 9, [`super::daylight`]) are
//! fitted and the `[[sun_shadow_pairs]]` cross-checked against the SPA ([`super::sun_check`]).
//! Daylight samples of several materials share absolute weights when the library gives every
//! material's ρ_d; with `[fit_settings] interreflection` the light their photographed
//! surroundings reflect onto them is gathered ([`super::interreflection`]) and the fit repeated
//! with the fitted weights until they settle; `[fit_settings] ambient = false` fixes k_u = 0.
//! [`apply_fit`] writes the result into `[lighting]` and the `[fit]` record; the caller saves the
//! document (atomically, [`crate::site::SiteDocument::save`]).
//!
//! The scene here holds the **natural** polygons only: the photos show the site without the
//! planned building, so its CAD models must not shadow the samples.
//!
//! Sun direction, sky model and material library as the renderer takes them
//! ([`crate::site::render`]: `lighting.sun_manual`, else the SPA for `lighting.time` or the
//! time of the first daylight sample's photo, turned into the survey frame with
//! `location.grid_convergence_deg`), so the fitted weights mean what the renderer uses.
//!
//! # Known limitations
//! A problem with one sample (no solved camera, not on any polygon, wrong material, clipped
//! window) drops that sample with a warning naming it; the fits then fail only if too few samples
//! remain. The horizon colour is the mean of the horizon rectangles' medians.

use std::collections::HashMap;
use std::sync::Arc;

use chrono::{DateTime, FixedOffset};
use nalgebra::{Point3, Vector3};

use super::FitObserver;
use super::colour::ColourReadOptions;
pub use super::report::{FitResidual, NamedSunCheck, SampleReading, SiteFitReport, apply_fit};
use super::sun_check::DEFAULT_TOLERANCE_DEG;
use crate::atmosphere::AtmosphereError;
use crate::photo::PhotoImage;
use crate::scene::SceneTracer;
use crate::site::render::site_material_library;
use crate::site::{SamplePurpose, Site, SiteDocument};
use crate::sun::SpaParams;

mod locate;
mod run;

use locate::locate_sample;
use run::{horizon, run_fits, sun_checks};

/// Reference distance dₐ of the reported transmittance: 1 km, so τₐ reads as "the fraction of
/// light left after a kilometre" (0.5–0.95 in ordinary haze).
pub const REPORT_REFERENCE_DISTANCE_M: f64 = 1000.0;

/// A world-point sample counts as on the polygon the ray meets when they are this close
/// (metres), or 0.1 % of the distance when larger: survey and intersection accuracy.
const POINT_ON_POLYGON_M: f64 = 0.05;

/// Settings of a site fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SiteFitOptions {
    /// Durisch's m_h of the sky facets used for sky visibility (4·m_h² facets).
    pub sky_m_h: u32,
    /// Tolerance of the sun cross-check, degrees.
    pub sun_tolerance_deg: f64,
    /// Pixel acceptance of the colour reads.
    pub colour: ColourReadOptions,
    /// m_h of the gather dome of the interreflection term (4·m_h² facets and their mirror
    /// images), used when `[fit_settings].interreflection` is on.
    pub interreflection_m_h: u32,
}

impl Default for SiteFitOptions {
    /// m_h = 8 (256 facets, the sky term's visibility to ≈ 1 %), 2° sun tolerance, the
    /// renderer's photo-bounce dome (m_h = 6) for the interreflection.
    fn default() -> Self {
        Self {
            sky_m_h: 8,
            sun_tolerance_deg: DEFAULT_TOLERANCE_DEG,
            colour: ColourReadOptions::default(),
            interreflection_m_h: 6,
        }
    }
}

/// Errors that stop a site fit.
#[derive(Debug, thiserror::Error)]
pub enum SiteFitError {
    /// Nothing to fit.
    #[error("the site has no enabled samples, horizon samples or sun/shadow pairs to fit")]
    NothingToFit,
    /// The scene could not be built.
    #[error("scene: {0}")]
    Scene(String),
    /// The material library could not be read.
    #[error("material library: {0}")]
    MaterialLibrary(String),
    /// Atmosphere samples are on different materials.
    #[error(
        "{fit} samples must share one material: sample `{sample}` is `{material}`, sample `{first}` is `{expected}`"
    )]
    MixedMaterials {
        /// `atmosphere` or `daylight`.
        fit: &'static str,
        /// The first sample of another material.
        sample: String,
        /// Its material.
        material: String,
        /// The first sample of the fit.
        first: String,
        /// Its material.
        expected: String,
    },
    /// The atmosphere fit failed.
    #[error("atmosphere fit (samples {samples}): {source}")]
    Atmosphere {
        /// The samples used.
        samples: String,
        /// Why.
        source: AtmosphereError,
    },
    /// The daylight fit failed.
    #[error("daylight fit (samples {samples}): {source}")]
    Daylight {
        /// The samples used.
        samples: String,
        /// Why.
        source: super::daylight::DaylightError,
    },
    /// The sun direction is unknown.
    #[error("sun direction: {0}")]
    Sun(String),
    /// Daylight samples are on several materials and one has no diffuse reflectance: the
    /// weights they share are absolute and need every material's ρ_d.
    #[error(
        "daylight samples on several materials need each material's diffuse reflectance: sample \
         `{sample}` is `{material}`, which the material library does not give one"
    )]
    NoReflectance {
        /// The sample.
        sample: String,
        /// Its material.
        material: String,
    },
    /// The interreflection gather failed.
    #[error("interreflection: {0}")]
    Interreflection(String),
    /// The observer asked to stop ([`FitObserver::cancelled`]).
    #[error("the fit was cancelled")]
    Cancelled,
}

/// [`SiteFitError::Cancelled`] when the observer asks to stop.
fn check_cancel(observer: Option<&Arc<dyn FitObserver>>) -> Result<(), SiteFitError> {
    if observer.is_some_and(|o| o.cancelled()) {
        return Err(SiteFitError::Cancelled);
    }
    Ok(())
}

/// The capture time of a photo: `taken_at`, else its EXIF time with offset.
#[must_use]
pub fn photo_time(doc: &SiteDocument, photo_id: &str) -> Option<DateTime<FixedOffset>> {
    let photo = doc.site.photos.iter().find(|p| p.id == photo_id)?;
    let text = photo.taken_at.clone().or_else(|| {
        crate::photo::read_exif(&doc.resolve(&photo.file))
            .ok()?
            .taken_at_rfc3339()
    })?;
    DateTime::parse_from_rfc3339(&text).ok()
}

fn spa_params(site: &Site) -> Option<(SpaParams, f64)> {
    let loc = site.location.as_ref()?;
    let mut p = SpaParams::at(loc.latitude_deg, loc.longitude_deg);
    p.elevation_m = loc.elevation_m;
    Some((p, loc.grid_convergence_deg))
}

struct Located {
    id: String,
    material: String,
    purpose: SamplePurpose,
    photo: String,
    point: Point3<f64>,
    normal: Vector3<f64>,
    distance_m: f64,
    apparent: [f64; 3],
    rejected_px: [usize; 2],
}

struct Photos<'a> {
    doc: &'a SiteDocument,
    cache: HashMap<String, Result<PhotoImage, String>>,
}

impl Photos<'_> {
    fn get(&mut self, id: &str) -> Result<&PhotoImage, String> {
        let doc = self.doc;
        self.cache
            .entry(id.to_owned())
            .or_insert_with(|| {
                let photo = doc
                    .site
                    .photos
                    .iter()
                    .find(|p| p.id == id)
                    .ok_or_else(|| format!("no photo `{id}`"))?;
                crate::photo::load(&doc.resolve(&photo.file)).map_err(|e| e.to_string())
            })
            .as_ref()
            .map_err(Clone::clone)
    }
}

/// Runs the fits on a loaded site; see the module doc. `observer` receives solver iterations.
///
/// # Errors
/// [`SiteFitError`] when a fit that has samples cannot be done.
pub fn fit_site(
    doc: &SiteDocument,
    options: &SiteFitOptions,
    observer: Option<Arc<dyn FitObserver>>,
) -> Result<SiteFitReport, SiteFitError> {
    let site = &doc.site;
    let enabled: Vec<&crate::site::Sample> = site.samples.iter().filter(|s| s.enabled).collect();
    let horizons: Vec<&crate::site::HorizonSample> =
        site.horizon_samples.iter().filter(|h| h.enabled).collect();
    if enabled.is_empty() && horizons.is_empty() && site.sun_shadow_pairs.is_empty() {
        return Err(SiteFitError::NothingToFit);
    }
    let mut warnings = Vec::new();
    let library =
        site_material_library(doc).map_err(|e| SiteFitError::MaterialLibrary(e.to_string()))?;
    let mut photos = Photos {
        doc,
        cache: HashMap::new(),
    };
    let mut located = Vec::new();
    if !enabled.is_empty() {
        let natural = super::natural_scene::natural_scene(site, library.as_ref())
            .map_err(|e| SiteFitError::Scene(e.to_string()))?;
        warnings.extend(natural.skipped_warnings());
        let scene = natural.scene;
        let tracer = SceneTracer::new(&scene, crate::bvh::BuildQuality::default())
            .map_err(|e| SiteFitError::Scene(e.to_string()))?;
        for s in &enabled {
            check_cancel(observer.as_ref())?;
            match locate_sample(doc, s, &scene, &tracer, &mut photos, options, &mut warnings) {
                Ok(l) => located.push(l),
                Err(e) => warnings.push(format!("sample `{}` not used: {e}", s.id)),
            }
        }
        let mut report = run_fits(
            doc,
            &scene,
            &located,
            &horizons,
            &mut photos,
            &tracer,
            options,
            observer,
            &mut warnings,
            library.as_ref(),
        )?;
        report.sun_checks = sun_checks(doc, options, &mut warnings);
        report.warnings = warnings;
        return Ok(report);
    }
    let (horizon_colour, horizon_colour_sigma) =
        horizon(site, &horizons, &mut photos, &mut warnings);
    let sun_checks = sun_checks(doc, options, &mut warnings);
    Ok(SiteFitReport {
        transmittance: None,
        transmittance_sigma: None,
        reference_distance_m: REPORT_REFERENCE_DISTANCE_M,
        horizon_colour,
        horizon_colour_sigma,
        sun_weight: None,
        sun_weight_sigma: None,
        ambient_weight: None,
        ambient_weight_sigma: None,
        sky_weight: None,
        sky_weight_sigma: None,
        weights_relative: false,
        residuals: Vec::new(),
        warnings,
        sun_checks,
        samples: Vec::new(),
        extinction_per_m: None,
    })
}

#[cfg(test)]
pub(crate) mod tests;
