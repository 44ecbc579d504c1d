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
use nalgebra::{Point2, Point3, Vector3};

use super::FitObserver;
use super::atmosphere::{AtmosphereFit, fit_atmosphere_robust};
use super::colour::{ColourReadOptions, read_rect, read_window};
use super::daylight::{
    DaylightFit, DaylightFitOptions, DaylightSample, fit_daylight, irradiance_components,
    normalised_sky_facets,
};
use super::interreflection::{
    GatherPoint, INTERREFLECTION_MAX_PASSES, INTERREFLECTION_SETTLED_REL, gather_interreflection,
    scene_with_probe, weights_settled,
};
pub use super::report::{FitResidual, NamedSunCheck, SampleReading, SiteFitReport, apply_fit};
use super::sun_check::{DEFAULT_TOLERANCE_DEG, check_sun};
use crate::atmosphere::{AtmosphereError, schachter::true_radiance};
use crate::photo::PhotoImage;
use crate::scene::{Material, MaterialLibrary, Scene, SceneTracer};
use crate::site::render::{site_material_library, site_sky_model, site_sun_dir};
use crate::site::{SamplePurpose, Site, SiteDocument, stored_camera};
use crate::sky_dome::durisch_facets::durisch_dome;
use crate::sun::SpaParams;

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

/// The natural scene of a site: its polygons with their materials (library definitions where
/// the library has them). Polygons whose vertices are not yet located are skipped with a warning.
///
/// # Errors
/// A message when a polygon cannot be added (degenerate).
pub fn natural_scene(
    site: &Site,
    library: Option<&MaterialLibrary>,
) -> Result<(Scene, Vec<String>), String> {
    super::pick::natural_scene_indexed(site, library).map(|(scene, _, warnings)| (scene, warnings))
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

fn locate_sample(
    doc: &SiteDocument,
    sample: &crate::site::Sample,
    scene: &Scene,
    tracer: &SceneTracer,
    photos: &mut Photos<'_>,
    options: &SiteFitOptions,
    warnings: &mut Vec<String>,
) -> Result<Located, String> {
    let id = &sample.id;
    let camera = stored_camera(&doc.site, &sample.photo)
        .ok_or_else(|| format!("photo `{}` has no solved camera", sample.photo))?;
    let centre = camera.pose.camera_center_in_world;
    let (pixel, dir) = match (sample.point, sample.x_px, sample.y_px) {
        (Some(p), _, _) => {
            let p = Point3::from(p);
            let pixel = camera
                .project(&p)
                .ok_or_else(|| format!("point is behind the camera of photo `{}`", sample.photo))?;
            (pixel, (p - centre).normalize())
        }
        (None, Some(x), Some(y)) => {
            let pixel = Point2::new(x, y);
            (pixel, camera.ray_dir_in_world(pixel))
        }
        _ => return Err("neither `point` nor `x_px`/`y_px` given".into()),
    };
    let ray = tracer.ray_from_world(&centre, &dir, 0.0, f32::INFINITY);
    let hit = tracer.closest_hit(&ray).ok_or_else(|| {
        format!(
            "not on any polygon: the ray through ({:.1}, {:.1}) px of photo `{}` hits nothing",
            pixel.x, pixel.y, sample.photo
        )
    })?;
    let mut point = tracer.hit_point_in_world_m(&ray, hit.hit.t);
    let n = hit.hit.normal_geometric;
    let mut normal = Vector3::new(f64::from(n[0]), f64::from(n[1]), f64::from(n[2])).normalize();
    if normal.dot(&dir) > 0.0 {
        normal = -normal;
    }
    if let Some(p) = sample.point {
        let p = Point3::from(p);
        let off_plane_m = (p - point).dot(&normal);
        let limit = POINT_ON_POLYGON_M.max(1e-3 * (point - centre).norm());
        if off_plane_m.abs() > limit {
            return Err(format!(
                "the point is not on a polygon visible in photo `{}`: the line of sight meets a \
                 polygon {:.2} m from it",
                sample.photo,
                (point - p).norm()
            ));
        }
        // The given point moved along the normal onto the polygon's plane: not the f32 hit
        // (which a grazing ray moves along the surface), and not the point itself (survey noise
        // puts it up to `limit` behind the surface, where shadow and gather rays would start
        // inside the object).
        point = p - normal * off_plane_m;
    }
    let material = scene
        .materials()
        .get(hit.material.0 as usize)
        .map_or("", |m| m.name.as_str());
    if material != sample.material {
        return Err(format!(
            "lies on a polygon of material `{material}`, not `{}`",
            sample.material
        ));
    }
    let photo = photos.get(&sample.photo)?;
    let read = read_window(photo, [pixel.x, pixel.y], sample.window_px, &options.colour)
        .map_err(|e| format!("colour at ({:.1}, {:.1}) px: {e}", pixel.x, pixel.y))?;
    if read.saturated_px + read.underexposed_px > 0 {
        warnings.push(format!(
            "sample `{id}`: {} saturated and {} underexposed pixels of its window rejected",
            read.saturated_px, read.underexposed_px
        ));
    }
    Ok(Located {
        id: id.clone(),
        material: sample.material.clone(),
        purpose: sample.purpose,
        photo: sample.photo.clone(),
        point,
        normal,
        distance_m: (point - centre).norm(),
        apparent: read.linear_rgb,
        rejected_px: [read.saturated_px, read.underexposed_px],
    })
}

fn one_material(fit: &'static str, samples: &[&Located]) -> Result<(), SiteFitError> {
    if let Some(first) = samples.first()
        && let Some(other) = samples.iter().find(|s| s.material != first.material)
    {
        return Err(SiteFitError::MixedMaterials {
            fit,
            sample: other.id.clone(),
            material: other.material.clone(),
            first: first.id.clone(),
            expected: first.material.clone(),
        });
    }
    Ok(())
}

fn id_list(samples: &[&Located]) -> String {
    samples
        .iter()
        .map(|s| format!("`{}`", s.id))
        .collect::<Vec<_>>()
        .join(", ")
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
        let (scene, w) = natural_scene(site, library.as_ref()).map_err(SiteFitError::Scene)?;
        warnings.extend(w);
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

fn horizon(
    site: &Site,
    horizons: &[&crate::site::HorizonSample],
    photos: &mut Photos<'_>,
    warnings: &mut Vec<String>,
) -> ([f64; 3], Option<[f64; 3]>) {
    let mut reads = Vec::new();
    for h in horizons {
        let read = photos.get(&h.photo).and_then(|p| {
            read_rect(
                p,
                [i64::from(h.origin_px[0]), i64::from(h.origin_px[1])],
                h.size_px,
                &ColourReadOptions::default(),
            )
            .map_err(|e| e.to_string())
        });
        match read {
            Ok(r) => reads.push(r.linear_rgb),
            Err(e) => warnings.push(format!("horizon sample `{}` not used: {e}", h.id)),
        }
    }
    if reads.is_empty() {
        warnings.push(
            "no usable horizon sample: L∞ taken from [lighting.atmosphere].horizon_colour".into(),
        );
        return (site.lighting.atmosphere.horizon_colour, None);
    }
    #[allow(clippy::cast_precision_loss)]
    let n = reads.len() as f64;
    let mean = [0, 1, 2].map(|k| reads.iter().map(|r| r[k]).sum::<f64>() / n);
    let sigma = (reads.len() > 1).then(|| {
        [0, 1, 2].map(|k| {
            (reads.iter().map(|r| (r[k] - mean[k]).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
        })
    });
    (mean, sigma)
}

fn sun_checks(
    doc: &SiteDocument,
    options: &SiteFitOptions,
    warnings: &mut Vec<String>,
) -> Vec<NamedSunCheck> {
    let site = &doc.site;
    let coords = |id: &str| -> Option<Point3<f64>> {
        site.control_points
            .iter()
            .find(|c| c.id == id)
            .map(|c| c.xyz)
            .or_else(|| site.tie_points.iter().find(|t| t.id == id).map(|t| t.xyz))
            .map(Point3::from)
    };
    let mut out = Vec::new();
    for pair in &site.sun_shadow_pairs {
        let (Some(object), Some(shadow)) = (coords(&pair.object_point), coords(&pair.shadow_point))
        else {
            warnings.push(format!(
                "sun check `{}` skipped: a point has no coordinates yet (run `solve`)",
                pair.id
            ));
            continue;
        };
        let Some(time) = photo_time(doc, &pair.photo) else {
            warnings.push(format!(
                "sun check `{}` skipped: photo `{}` has no taken_at or EXIF time",
                pair.id, pair.photo
            ));
            continue;
        };
        let Some((params, convergence)) = spa_params(site) else {
            warnings.push(format!(
                "sun check `{}` skipped: the site has no [location]",
                pair.id
            ));
            continue;
        };
        match check_sun(
            object,
            shadow,
            &time,
            &params,
            convergence,
            options.sun_tolerance_deg,
        ) {
            Ok(check) => {
                warnings.extend(check.warning(&pair.id));
                out.push(NamedSunCheck {
                    pair: pair.id.clone(),
                    check,
                });
            }
            Err(e) => warnings.push(format!("sun check `{}` failed: {e}", pair.id)),
        }
    }
    out
}

#[allow(clippy::too_many_lines)]
fn run_fits(
    doc: &SiteDocument,
    scene: &Scene,
    located: &[Located],
    horizons: &[&crate::site::HorizonSample],
    photos: &mut Photos<'_>,
    tracer: &SceneTracer,
    options: &SiteFitOptions,
    observer: Option<Arc<dyn FitObserver>>,
    warnings: &mut Vec<String>,
    library: Option<&MaterialLibrary>,
) -> Result<SiteFitReport, SiteFitError> {
    let site = &doc.site;
    let (horizon_colour, horizon_colour_sigma) = horizon(site, horizons, photos, warnings);
    let atm_samples: Vec<&Located> = located
        .iter()
        .filter(|s| s.purpose == SamplePurpose::Atmosphere)
        .collect();
    let day_samples: Vec<&Located> = located
        .iter()
        .filter(|s| s.purpose == SamplePurpose::Daylight)
        .collect();
    let mut residuals = Vec::new();
    // Atmosphere (eq. 7), or the site's current one.
    let atmosphere: Option<AtmosphereFit> = if atm_samples.is_empty() {
        warnings.push(
            "no atmosphere samples: the atmosphere is kept from [lighting.atmosphere]".into(),
        );
        None
    } else {
        one_material("atmosphere", &atm_samples)?;
        let data: Vec<(f64, [f64; 3])> = atm_samples
            .iter()
            .map(|s| (s.distance_m, s.apparent))
            .collect();
        let fit = fit_atmosphere_robust(
            horizon_colour,
            &data,
            REPORT_REFERENCE_DISTANCE_M,
            site.solve.outlier_threshold_sigma,
            observer.clone(),
        )
        .map_err(|source| SiteFitError::Atmosphere {
            samples: id_list(&atm_samples),
            source,
        })?;
        for (k, clamped) in fit.clamped.iter().enumerate() {
            if *clamped {
                warnings.push(format!(
                    "atmosphere samples {} get more contrast with distance in channel {k}: τ clamped to 1 (clear air)",
                    id_list(&atm_samples)
                ));
            }
        }
        for ((s, r), flagged) in atm_samples.iter().zip(&fit.residuals).zip(&fit.flagged) {
            residuals.push(FitResidual {
                sample: s.id.clone(),
                fit: "atmosphere",
                residual_rgb: *r,
                normalised: None,
                flagged: *flagged,
            });
        }
        let dropped: Vec<&Located> = atm_samples
            .iter()
            .zip(&fit.flagged)
            .filter(|(_, f)| **f)
            .map(|(s, _)| *s)
            .collect();
        if !dropped.is_empty() {
            warnings.push(format!(
                "atmosphere samples dropped as outliers (normalised residual > {}): {}",
                site.solve.outlier_threshold_sigma,
                id_list(&dropped)
            ));
        }
        Some(fit)
    };
    let extinction_per_m = atmosphere.as_ref().map_or(
        site.lighting.atmosphere.extinction_per_m,
        AtmosphereFit::extinction_per_m,
    );
    // Daylight (eq. 9).
    let mut gathered: HashMap<String, [f64; 3]> = HashMap::new();
    let daylight: Option<DaylightFit> = if day_samples.is_empty() {
        warnings.push("no daylight samples: the weights in [lighting] are kept".into());
        None
    } else {
        let rho_of = |s: &Located| {
            library
                .and_then(|l| l.get(&s.material))
                .map(Material::diffuse_reflectance_rgb)
        };
        let several = day_samples
            .iter()
            .any(|s| s.material != day_samples[0].material);
        if several && let Some(s) = day_samples.iter().find(|s| rho_of(s).is_none()) {
            return Err(SiteFitError::NoReflectance {
                sample: s.id.clone(),
                material: s.material.clone(),
            });
        }
        let model = site_sky_model(site.lighting.sky_model)
            .map_err(|e| SiteFitError::Sun(e.to_string()))?;
        let sun_dir = site_sun_dir(doc, &day_samples[0].photo)
            .map(|d| (d.z > 0.0).then_some(d))
            .map_err(|e| SiteFitError::Sun(e.to_string()))?;
        if sun_dir.is_none() {
            warnings.push("the sun is below the horizon: only ambient and sky are fitted".into());
        }
        let dome = durisch_dome(options.sky_m_h).map_err(|e| SiteFitError::Sun(e.to_string()))?;
        let sky_sun = sun_dir.unwrap_or_else(Vector3::z);
        let sky = normalised_sky_facets(&dome, &model, &sky_sun).map_err(|source| {
            SiteFitError::Daylight {
                samples: id_list(&day_samples),
                source,
            }
        })?;
        let mut samples: Vec<DaylightSample> = day_samples
            .iter()
            .map(|s| DaylightSample {
                id: s.id.clone(),
                // Eq. 8 with d in metres and the extinction per metre (dₐ = 1 m).
                true_colour_rgb: [0, 1, 2].map(|k| {
                    true_radiance(
                        s.apparent[k],
                        horizon_colour[k],
                        (-extinction_per_m[k]).exp(),
                        s.distance_m,
                        1.0,
                    )
                }),
                components: irradiance_components(
                    tracer,
                    &s.point,
                    &s.normal,
                    sun_dir.as_ref(),
                    &sky,
                ),
                normal_in_world: s.normal,
                diffuse_reflectance_rgb: rho_of(s),
                interreflection_rgb: [0.0; 3],
            })
            .collect();
        let fit_options = DaylightFitOptions {
            outlier_threshold: site.solve.outlier_threshold_sigma,
            diffuse_reflectance_rgb: None,
            fit_ambient: site.fit_settings.ambient,
        };
        let absolute = samples.iter().all(|s| s.diffuse_reflectance_rgb.is_some());
        let gather = site.fit_settings.interreflection && absolute;
        if site.fit_settings.interreflection && !absolute {
            warnings.push(
                "interreflection is not subtracted: it needs the samples' diffuse reflectance"
                    .into(),
            );
        }
        // E_r depends on the weights only through surfaces the photos do not show (shaded by
        // their library material): refit with the fitted weights until they settle.
        let mut gather_doc = doc.clone();
        gather_doc.site.lighting.atmosphere.extinction_per_m = extinction_per_m;
        gather_doc.site.lighting.atmosphere.horizon_colour = horizon_colour;
        let probe_scene = if gather {
            Some(
                scene_with_probe(scene)
                    .map_err(|e| SiteFitError::Interreflection(e.to_string()))?,
            )
        } else {
            None
        };
        let mut previous: Option<DaylightFit> = None;
        let mut passes = 0_usize;
        let fit = loop {
            check_cancel(observer.as_ref())?;
            passes += 1;
            if let Some(probe_scene) = &probe_scene {
                let points: Vec<GatherPoint<'_>> = day_samples
                    .iter()
                    .map(|s| GatherPoint {
                        photo: &s.photo,
                        point_in_world_m: s.point,
                        normal_in_world: s.normal,
                    })
                    .collect();
                let e_r = gather_interreflection(
                    &gather_doc,
                    probe_scene,
                    &points,
                    options.sky_m_h,
                    options.interreflection_m_h,
                    |id| photos.get(id).map(crate::render::linear_photo),
                )
                .map_err(|e| SiteFitError::Interreflection(e.to_string()))?;
                for (s, e) in samples.iter_mut().zip(e_r) {
                    s.interreflection_rgb = e;
                }
            }
            let fit = fit_daylight(&samples, &fit_options, observer.clone()).map_err(|source| {
                SiteFitError::Daylight {
                    samples: id_list(&day_samples),
                    source,
                }
            })?;
            let settled = previous.as_ref().is_some_and(|p| weights_settled(p, &fit));
            if !gather || settled || passes >= INTERREFLECTION_MAX_PASSES {
                if gather && !settled {
                    warnings.push(format!(
                        "the daylight weights changed by more than {INTERREFLECTION_SETTLED_REL} \
                         between the last two interreflection passes"
                    ));
                }
                break fit;
            }
            let l = &mut gather_doc.site.lighting;
            l.sun_weight = fit.sun_weight;
            l.ambient_weight = fit.ambient_weight;
            l.sky_weight = fit.sky_weight;
            previous = Some(fit);
        };
        if gather {
            for s in &samples {
                gathered.insert(s.id.clone(), s.interreflection_rgb);
            }
        }
        if fit.relative {
            warnings.push(format!(
                "material `{}` has no diffuse reflectance in the material library: the weights \
                 are relative (ρ_d = 1 assumed, Durisch §4.3)",
                day_samples[0].material
            ));
        }
        warnings.extend(fit.warnings.iter().cloned());
        for r in &fit.residuals {
            residuals.push(FitResidual {
                sample: r.sample.clone(),
                fit: "daylight",
                residual_rgb: r.residual_rgb,
                normalised: Some(r.normalised),
                flagged: r.flagged,
            });
        }
        Some(fit)
    };
    Ok(SiteFitReport {
        transmittance: atmosphere.as_ref().map(|a| a.transmittance),
        transmittance_sigma: atmosphere.as_ref().map(|a| a.transmittance_sigma),
        reference_distance_m: REPORT_REFERENCE_DISTANCE_M,
        horizon_colour,
        horizon_colour_sigma,
        sun_weight: daylight.as_ref().map(|d| d.sun_weight),
        sun_weight_sigma: daylight.as_ref().map(|d| d.sun_weight_sigma),
        ambient_weight: daylight.as_ref().map(|d| d.ambient_weight),
        ambient_weight_sigma: daylight.as_ref().map(|d| d.ambient_weight_sigma),
        sky_weight: daylight.as_ref().map(|d| d.sky_weight),
        sky_weight_sigma: daylight.as_ref().map(|d| d.sky_weight_sigma),
        weights_relative: daylight.as_ref().is_some_and(|d| d.relative),
        residuals,
        warnings: Vec::new(),
        sun_checks: Vec::new(),
        samples: located
            .iter()
            .map(|s| SampleReading {
                id: s.id.clone(),
                point_in_world_m: s.point.into(),
                distance_m: s.distance_m,
                apparent_rgb: s.apparent,
                rejected_px: s.rejected_px,
                interreflection_rgb: gathered.get(&s.id).copied(),
            })
            .collect(),
        extinction_per_m: atmosphere.as_ref().map(AtmosphereFit::extinction_per_m),
    })
}

#[cfg(test)]
pub(crate) mod tests;
