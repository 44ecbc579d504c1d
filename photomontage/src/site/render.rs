//! From a site file to a render job: the scene (Durisch 1992 §4.1 natural polygons and §5 CAD
//! objects), the lighting of §3.3–3.4 in the site's units, the solved camera of a photo and the
//! photo itself, linearised — everything [`crate::render::render_view`] needs for one view.
//!
//! # Lighting units (the site's `[lighting]` table, per RGB channel, in the photo's linear units)
//! - `sun_weight` k_s: irradiance of the direct sun on a surface facing it (eq. 3), the sun's
//!   [`DistantLight::normal_irradiance_rgb`];
//! - `sky_weight` k_h: horizontal irradiance of the whole unobstructed sky (eq. 5): the facets of
//!   a Durisch dome carry the relative luminance of `sky_model`, scaled so that the sum over the
//!   facets of `L_i Δω_i cos Z_i` equals k_h exactly (a uniform sky of radiance L has k_h = π·L);
//! - `ambient_weight` k_u: ambient radiance (eq. 4), irradiance π·k_u on any surface.
//!
//! The sun direction is `lighting.sun_manual` if given, else the NREL SPA ([`crate::sun`]) at
//! `lighting.time`, else the photo's `taken_at`, else its EXIF capture time, at `[location]`
//! (local times without an offset are read in `location.time_zone`, see [`super::site_time`]).
//! Azimuths (manual or SPA) are from true north; they are turned into the survey frame (+Y = grid
//! north, Z up) with `location.grid_convergence_deg`. A sun at or below the horizon gives no
//! sunlight.
//!
//! # Known limitations
//! Polygons are single-sided triangles of their vertex points (no holes). CAD materials named in
//! the material library take the library's definition; the others keep their file's definition.
//! The sky is sampled on a fixed Durisch dome (its facet count is [`SiteLightingOptions`]), so a
//! CIE sky's circumsolar peak is averaged over a facet. Luminaires (`[[luminaires]]`) are
//! added by [`super::luminaires`].

use image::Rgb32FImage;
use nalgebra::Vector3;

use chrono::Datelike;

use super::{PerezForm, SiteDocument, SkyModelName};
use crate::atmosphere::schachter::SchachterAtmosphere;
use crate::camera::Camera;
use crate::colour::Colour;
use crate::render::{
    Daylight, DifferentialError, DifferentialTracer, DistantLight, Lighting, RenderSettings,
};
use crate::sky::{PerezSky, SkyModel};
use crate::sky_dome::durisch_facets::durisch_dome;

pub use super::render_error::{SiteRenderError, SiteWarning};
pub use super::site_scene::{
    DEFAULT_POLYGON_ALBEDO, ObjectSource, SCALE_WARNING_MAX_EXTENT_M, SCALE_WARNING_MIN_EXTENT_M,
    SiteScene, site_material_library, site_scene,
};

/// Quality knobs of the site lighting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SiteLightingOptions {
    /// m_h of the Durisch sky dome (4·m_h² facets).
    pub sky_dome_m_h: u32,
    /// m_h of the photo-bounce gather dome; `None` disables the bounce.
    pub photo_bounce_m_h: Option<u32>,
    /// m_h of the nested (second) bounce gather; `None` disables it.
    pub photo_bounce_nested_m_h: Option<u32>,
}

impl Default for SiteLightingOptions {
    /// The settings that meet the 3 % Mitsuba accuracy goal (`tests/tests/render_mitsuba.rs`):
    /// sky m_h = 8 (256 facets), bounce m_h = 6, nested bounce m_h = 2.
    fn default() -> Self {
        Self {
            sky_dome_m_h: 8,
            photo_bounce_m_h: Some(6),
            photo_bounce_nested_m_h: Some(2),
        }
    }
}

/// Everything needed to render one view of a site.
#[derive(Debug, Clone)]
pub struct ViewJob {
    /// The photo id.
    pub photo_id: String,
    /// The scene.
    pub scene: SiteScene,
    /// Lights and atmosphere.
    pub lighting: Lighting,
    /// The solved camera of the photo.
    pub camera: Camera,
    /// The photo, linear RGB, the camera's size (shared with a [`KeptPhoto`]: the studio's live
    /// renders do not copy it for every edit).
    pub photo_linear: std::sync::Arc<Rgb32FImage>,
    /// Render settings from the site's `[render]` table.
    pub settings: RenderSettings,
    /// The sun direction used (survey frame), `None` when none was needed or it is below the
    /// horizon.
    pub sun_dir_in_world: Option<Vector3<f64>>,
    /// Scene warnings and setting adjustments.
    pub warnings: Vec<SiteWarning>,
}

impl ViewJob {
    /// The differential tracer of this view (its scene, lighting, camera and photo, the
    /// settings' recursion depth).
    ///
    /// # Errors
    /// As [`DifferentialTracer::new`].
    pub fn tracer(&self) -> Result<DifferentialTracer<'_>, DifferentialError> {
        DifferentialTracer::new(
            &self.scene.scene,
            &self.lighting,
            &self.camera,
            &self.photo_linear,
            self.settings.max_depth,
        )
    }
}

/// The solved camera of photo `photo_id`.
///
/// # Errors
/// [`SiteRenderError::UnknownView`] listing the valid ids, [`SiteRenderError::NotSolved`],
/// [`SiteRenderError::NoInterior`].
pub fn site_camera(doc: &SiteDocument, photo_id: &str) -> Result<Camera, SiteRenderError> {
    let Some(photo) = doc.site.photos.iter().find(|p| p.id == photo_id) else {
        return Err(SiteRenderError::UnknownView {
            id: photo_id.to_owned(),
            valid: doc.site.photos.iter().map(|p| p.id.clone()).collect(),
        });
    };
    if photo.exterior.is_none() {
        return Err(SiteRenderError::NotSolved {
            photo: photo_id.to_owned(),
        });
    }
    super::stored_camera(&doc.site, photo_id).ok_or_else(|| SiteRenderError::NoInterior {
        photo: photo_id.to_owned(),
    })
}

/// The sky model of `lighting.sky_model` for a sun in `sun_dir_in_world` (survey frame): the
/// one builder of the site's sky, used by the renderer, the radiosity lighting and the fit.
/// `perez` reads `[lighting.perez]` ([`super::PerezInputs`]) and the sun's zenith angle; its
/// irradiance form takes the day of the year from the sun time of photo `photo_id`
/// ([`super::site_time::site_sun_time`]).
///
/// # Errors
/// [`SiteRenderError::Sky`] for a CIE general sky type outside 1–15 (only possible for a value
/// built in code; the site file's reader refuses it) or a Perez sky with the sun at or below the
/// horizon; [`SiteRenderError::Request`] naming the `[lighting.perez]` field that is missing or
/// out of range, or when its irradiance form has no day of the year.
pub fn site_sky_model(
    doc: &SiteDocument,
    photo_id: &str,
    sun_dir_in_world: &Vector3<f64>,
) -> Result<SkyModel, SiteRenderError> {
    let name = doc.site.lighting.sky_model;
    match name {
        SkyModelName::Uniform => Ok(SkyModel::Uniform),
        SkyModelName::CieOvercast => Ok(SkyModel::CieOvercast),
        SkyModelName::CieGeneral(n) => SkyModel::cie_general(n).map_err(|e| SiteRenderError::Sky {
            reason: format!("`{name}`: {e}"),
        }),
        SkyModelName::Perez => site_perez_sky(doc, photo_id, sun_dir_in_world).map(SkyModel::Perez),
    }
}

fn site_perez_sky(
    doc: &SiteDocument,
    photo_id: &str,
    sun_dir_in_world: &Vector3<f64>,
) -> Result<PerezSky, SiteRenderError> {
    let form = doc
        .site
        .lighting
        .perez
        .clone()
        .unwrap_or_default()
        .form()
        .map_err(|e| SiteRenderError::Request {
            field: e.field,
            reason: e.reason,
        })?;
    let cos_zenith = sun_dir_in_world.z.clamp(-1.0, 1.0);
    if cos_zenith <= 0.0 {
        return Err(SiteRenderError::Sky {
            reason: format!(
                "`perez` needs the sun above the horizon; it is at elevation {:.3}°",
                cos_zenith.asin().to_degrees()
            ),
        });
    }
    let sun_zenith = cos_zenith.acos();
    match form {
        PerezForm::Indices {
            clearness,
            brightness,
        } => Ok(PerezSky::from_indices(clearness, brightness, sun_zenith)),
        PerezForm::Irradiance {
            direct_normal_w_m2,
            diffuse_horizontal_w_m2,
        } => {
            let time = super::site_time::site_sun_time(doc, photo_id).map_err(|e| {
                SiteRenderError::Request {
                    field: "lighting.perez",
                    reason: format!(
                        "the irradiance form needs the day of the year from the sun time ({e}); \
                         or give clearness and brightness"
                    ),
                }
            })?;
            PerezSky::from_irradiance(
                direct_normal_w_m2,
                diffuse_horizontal_w_m2,
                sun_zenith,
                time.ordinal(),
            )
            .map_err(|e| SiteRenderError::Sky {
                reason: format!("`perez`: {e}"),
            })
        }
    }
}

/// Turns a true-north azimuth and an elevation into a survey-frame unit vector (+Y grid north,
/// Z up), given the grid convergence (angle from grid north to true north, clockwise).
#[must_use]
pub fn survey_dir_from_true_azimuth(
    azimuth_deg: f64,
    elevation_deg: f64,
    grid_convergence_deg: f64,
) -> Vector3<f64> {
    crate::sky::direction_from_elevation_azimuth(
        elevation_deg.to_radians(),
        (azimuth_deg + grid_convergence_deg).to_radians(),
    )
}

/// The sun direction for photo `photo_id` in the survey frame (possibly below the horizon):
/// `sun_manual`, else the SPA at `lighting.time`, the photo's `taken_at` or its EXIF time.
///
/// # Errors
/// [`SiteRenderError::NoSunDirection`] when there is no time or no location,
/// [`SiteRenderError::Sun`] from the SPA.
pub fn site_sun_dir(doc: &SiteDocument, photo_id: &str) -> Result<Vector3<f64>, SiteRenderError> {
    let site = &doc.site;
    let convergence = site
        .location
        .as_ref()
        .map_or(0.0, |l| l.grid_convergence_deg);
    let sun = super::sun_path::site_sun_angles(doc, photo_id)?;
    Ok(survey_dir_from_true_azimuth(
        sun.azimuth_deg,
        sun.elevation_deg,
        convergence,
    ))
}

/// Sky facets of `model` for a sun in `sun_dir_in_world`, scaled so that their unobstructed
/// horizontal irradiance Σ L_i Δω_i cos Z_i equals `sky_weight_rgb` in every channel.
///
/// # Errors
/// [`SiteRenderError::Sky`] when the model gives no light above the horizon.
pub fn sky_lights(
    model: &SkyModel,
    sun_dir_in_world: &Vector3<f64>,
    dome: &crate::sky_dome::SkyDome,
    sky_weight_rgb: [f64; 3],
) -> Result<Vec<DistantLight>, SiteRenderError> {
    let relative: Vec<f64> = dome
        .facets
        .iter()
        .map(|f| {
            model.relative_luminance(&f.centre_dir_in_world, sun_dir_in_world) * f.solid_angle_sr
        })
        .collect();
    let horizontal: f64 = dome
        .facets
        .iter()
        .zip(&relative)
        .map(|(f, r)| r * f.centre_dir_in_world.z.max(0.0))
        .sum();
    if !(horizontal.is_finite() && horizontal > 0.0) {
        return Err(SiteRenderError::Sky {
            reason: format!("the sky model gives horizontal irradiance {horizontal}"),
        });
    }
    Ok(dome
        .facets
        .iter()
        .zip(&relative)
        .map(|(f, r)| DistantLight {
            dir_in_world: f.centre_dir_in_world,
            normal_irradiance_rgb: sky_weight_rgb.map(|k| k * r / horizontal),
        })
        .collect())
}

fn atmosphere(a: &super::Atmosphere) -> Result<Option<SchachterAtmosphere>, SiteRenderError> {
    if a.extinction_per_m
        .iter()
        .any(|s| !(s.is_finite() && *s >= 0.0))
    {
        return Err(SiteRenderError::AtmosphereSetting {
            reason: format!(
                "extinction_per_m {:?} must be finite and ≥ 0",
                a.extinction_per_m
            ),
        });
    }
    let sigma_max = a.extinction_per_m.iter().copied().fold(0.0, f64::max);
    if sigma_max <= 0.0 {
        return Ok(None);
    }
    // Reference distance 1/σ_max keeps every channel's τ_a in [1/e, 1], well inside f32.
    let reference_m = 1.0 / sigma_max;
    #[allow(clippy::cast_possible_truncation)]
    let tau: Vec<f32> = a
        .extinction_per_m
        .iter()
        .map(|s| (-s * reference_m).exp() as f32)
        .collect();
    #[allow(clippy::cast_possible_truncation)]
    let horizon: Vec<f32> = a.horizon_colour.iter().map(|&h| h as f32).collect();
    Ok(Some(SchachterAtmosphere::new(
        Colour::from_slice(&tau),
        Colour::from_slice(&horizon),
        reference_m,
        3,
    )?))
}

/// Whether the site's light needs a sun direction (a sun weight, or a sky that follows the sun).
pub(super) fn sun_needed(doc: &SiteDocument) -> bool {
    let l = &doc.site.lighting;
    l.sun_weight.iter().any(|&k| k != 0.0) || l.sky_model.needs_sun()
}

/// The lighting of photo `photo_id`: sun (normal irradiance = `sun_weight`), sky facets
/// (horizontal irradiance = `sky_weight`), ambient radiance = `ambient_weight`, the enabled
/// `[[luminaires]]` ([`super::luminaires::site_luminaire_lights`]), the atmosphere,
/// the horizon colour and the photo-bounce domes of `options`.
///
/// # Errors
/// No sun direction where one is needed, an SPA error, a bad sky model or atmosphere, a
/// luminaire whose file is missing or invalid.
pub fn site_lighting(
    doc: &SiteDocument,
    photo_id: &str,
    options: &SiteLightingOptions,
) -> Result<(Lighting, Option<Vector3<f64>>), SiteRenderError> {
    let l = &doc.site.lighting;
    let sun_dir = if sun_needed(doc) {
        Some(site_sun_dir(doc, photo_id)?)
    } else {
        None
    };
    // Skies without sun dependence ignore the direction.
    let sky_sun_dir = sun_dir.unwrap_or_else(Vector3::z);
    let sky = if l.sky_weight.iter().any(|&k| k != 0.0) {
        sky_lights(
            &site_sky_model(doc, photo_id, &sky_sun_dir)?,
            &sky_sun_dir,
            &durisch_dome(options.sky_dome_m_h)?,
            l.sky_weight,
        )?
    } else {
        Vec::new()
    };
    let sun_up = sun_dir.filter(|d| d.z > 0.0);
    let sun = sun_up
        .filter(|_| l.sun_weight.iter().any(|&k| k != 0.0))
        .map(|d| DistantLight {
            dir_in_world: d,
            normal_irradiance_rgb: l.sun_weight,
        });
    let lighting = Lighting {
        daylight: Daylight {
            sun,
            ambient_radiance_rgb: l.ambient_weight,
            sky,
        },
        artificial_lights: super::luminaires::site_luminaire_lights(doc)?,
        atmosphere: atmosphere(&l.atmosphere)?,
        photo_bounce_dome: options.photo_bounce_m_h.map(durisch_dome).transpose()?,
        photo_bounce_nested_dome: options
            .photo_bounce_nested_m_h
            .map(durisch_dome)
            .transpose()?,
        horizon_rgb: l.atmosphere.horizon_colour,
        radiosity: None,
        radiosity_spectral: None,
    };
    Ok((lighting, sun_up))
}

/// The renderer's settings from the site's `[render]` table; ray counts are rounded up to the
/// renderer's multiples of 4 (at most 64), with a warning when that changes them.
#[must_use]
pub fn site_render_settings(r: &super::RenderSettings) -> (RenderSettings, Vec<SiteWarning>) {
    let round = |n: u32| n.clamp(4, 64).div_ceil(4) * 4;
    let (lo, hi) = (round(r.spp_min), round(r.spp_max.max(r.spp_min)));
    let mut warnings = Vec::new();
    if lo != r.spp_min || hi != r.spp_max {
        warnings.push(SiteWarning::Setting {
            message: format!(
                "render.spp_min/spp_max {}/{} rounded to {lo}/{hi} (multiples of 4, 4–64)",
                r.spp_min, r.spp_max
            ),
        });
    }
    (
        RenderSettings {
            min_rays_per_pixel: lo,
            max_rays_per_pixel: hi,
            seed: r.seed,
            max_depth: r.max_depth,
            ..RenderSettings::default()
        },
        warnings,
    )
}

/// Photo `photo_id` decoded and linearised, checked to be the size `camera` images.
///
/// # Errors
/// [`SiteRenderError::UnknownView`], the photo's decoding errors,
/// [`SiteRenderError::SizeMismatch`].
pub fn site_photo_linear(
    doc: &SiteDocument,
    photo_id: &str,
    camera: &Camera,
) -> Result<Rgb32FImage, SiteRenderError> {
    // Nothing kept: the only handle, so no copy.
    site_photo_linear_kept(doc, photo_id, camera, None).map(std::sync::Arc::unwrap_or_clone)
}

/// A photo decoded and linearised, kept to be handed out again while its file is unchanged
/// (same path, length and modification time): the studio's live renders of one view, which
/// would otherwise decode the photo again for every edit.
#[derive(Debug, Clone)]
pub struct KeptPhoto {
    file: std::path::PathBuf,
    len: u64,
    modified: Option<std::time::SystemTime>,
    photo_linear: std::sync::Arc<Rgb32FImage>,
}

impl KeptPhoto {
    /// Whether `file` is the one kept, unchanged since it was read.
    fn holds(&self, file: &std::path::Path, meta: &std::fs::Metadata) -> bool {
        self.file == file && self.len == meta.len() && self.modified == meta.modified().ok()
    }
}

/// [`site_photo_linear`], reusing the photo `kept` holds when it is this view's file unchanged
/// and keeping the one it loads there otherwise (`None`: nothing kept). The kept photo is
/// shared, not copied.
///
/// # Errors
/// As [`site_photo_linear`].
pub fn site_photo_linear_kept(
    doc: &SiteDocument,
    photo_id: &str,
    camera: &Camera,
    kept: Option<&mut Option<KeptPhoto>>,
) -> Result<std::sync::Arc<Rgb32FImage>, SiteRenderError> {
    let photo = doc
        .site
        .photos
        .iter()
        .find(|p| p.id == photo_id)
        .ok_or_else(|| SiteRenderError::UnknownView {
            id: photo_id.to_owned(),
            valid: Vec::new(),
        })?;
    let file = doc.resolve(&photo.file);
    let meta = std::fs::metadata(&file).ok();
    let reused = kept.as_deref().and_then(Option::as_ref).and_then(|k| {
        meta.as_ref()
            .filter(|m| k.holds(&file, m))
            .map(|_| k.photo_linear.clone())
    });
    let photo_linear = match reused {
        Some(photo_linear) => photo_linear,
        None => {
            let loaded = crate::photo::load(&file)?;
            let photo_linear = std::sync::Arc::new(crate::render::linear_photo(&loaded));
            if let (Some(slot), Some(meta)) = (kept, &meta) {
                *slot = Some(KeptPhoto {
                    file: file.clone(),
                    len: meta.len(),
                    modified: meta.modified().ok(),
                    photo_linear: photo_linear.clone(),
                });
            }
            photo_linear
        }
    };
    let photo_px = [photo_linear.width(), photo_linear.height()];
    if photo_px != camera.intrinsics.image_size_px {
        return Err(SiteRenderError::SizeMismatch {
            photo: photo_id.to_owned(),
            photo_px,
            camera_px: camera.intrinsics.image_size_px,
        });
    }
    Ok(photo_linear)
}

/// Everything to render photo `photo_id`: camera, scene, lighting, the photo (linearised, size
/// checked against the camera) and the settings of the site's `[render]` table.
///
/// # Errors
/// Any error of [`site_camera`], [`site_scene`], [`site_lighting`], the photo's decoding,
/// [`SiteRenderError::SizeMismatch`] and [`SiteRenderError::NoVisibleModel`].
pub fn prepare_view(doc: &SiteDocument, photo_id: &str) -> Result<ViewJob, SiteRenderError> {
    prepare_view_with(doc, photo_id, &SiteLightingOptions::default())
}

/// [`prepare_view`] with explicit lighting options.
///
/// # Errors
/// As [`prepare_view`].
pub fn prepare_view_with(
    doc: &SiteDocument,
    photo_id: &str,
    options: &SiteLightingOptions,
) -> Result<ViewJob, SiteRenderError> {
    prepare_view_kept(doc, photo_id, options, None)
}

/// [`prepare_view_with`], taking the photo from `kept` where it holds this view's file unchanged
/// ([`site_photo_linear_kept`]).
///
/// # Errors
/// As [`prepare_view`].
pub fn prepare_view_kept(
    doc: &SiteDocument,
    photo_id: &str,
    options: &SiteLightingOptions,
    kept: Option<&mut Option<KeptPhoto>>,
) -> Result<ViewJob, SiteRenderError> {
    let camera = site_camera(doc, photo_id)?;
    // A design variant may show no model (the existing situation, for comparison).
    let variant_applied = doc.site.variants.iter().any(|v| v.applied);
    if !variant_applied && !doc.site.models.iter().any(|m| m.visible) {
        return Err(SiteRenderError::NoVisibleModel);
    }
    let scene = site_scene(doc)?;
    let (lighting, sun_dir_in_world) = site_lighting(doc, photo_id, options)?;
    let photo_linear = site_photo_linear_kept(doc, photo_id, &camera, kept)?;
    let (settings, setting_warnings) = site_render_settings(&doc.site.render);
    let mut warnings = scene.warnings.clone();
    warnings.extend(setting_warnings);
    warnings.extend(super::luminaires::luminaire_warnings(&doc.site));
    Ok(ViewJob {
        photo_id: photo_id.to_owned(),
        scene,
        lighting,
        camera,
        photo_linear,
        settings,
        sun_dir_in_world,
        warnings,
    })
}

#[cfg(test)]
#[path = "perez_sky_tests.rs"]
mod perez_tests;
#[cfg(test)]
#[path = "render_tests.rs"]
pub(crate) mod tests;
