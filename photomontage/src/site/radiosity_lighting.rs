//! A site's lighting as radiosity light groups: the sun (SPA or `sun_manual`, weighted by
//! `sun_weight`), the sky model scaled to `sky_weight` horizontal irradiance, each enabled
//! `[[luminaires]]` entry, the emitting materials, and the ground below the horizon where the
//! site does not model it (`[lighting] ground_modelled`, `ground_albedo`; docs/methodology.md).
//!
//! # Known limitations
//! `ambient_weight` is the renderer's term and has no radiosity counterpart (a note says so).

use nalgebra::Vector3;

use super::SiteDocument;
use super::luminaires::site_luminaire_lights;
use super::render::{site_sky_model, site_sun_dir};
use super::render_error::SiteRenderError;
use crate::radiosity::{
    GroundBelowHorizon, LightGroup, LightWarning, NamedLuminaire, PointSource, Sky, Sun,
    TransferLighting,
};
use crate::render::luminaire_light::ArtificialLight;
use crate::scene::{ObjectKind, Scene};
use crate::sky_dome::icosahedral::{IcosahedralDome, IcosahedralParams};

/// A natural polygon whose normal is within 30° of the zenith is ground (cos 30°).
pub const GROUND_NORMAL_MIN_Z: f64 = 0.866;

/// Default albedo of an unmodelled ground (mixed urban ground).
pub const DEFAULT_GROUND_ALBEDO: f64 = 0.2;

/// Whether `scene` has ground: a natural triangle facing up within 30° of the zenith.
#[must_use]
pub fn scene_has_ground(scene: &Scene) -> bool {
    scene.triangles().iter().any(|t| {
        let natural = scene
            .objects()
            .get(t.object.0 as usize)
            .is_some_and(|o| o.kind == ObjectKind::Natural);
        let v = t.vertices_in_world_m;
        let n = (v[1] - v[0]).cross(&(v[2] - v[0]));
        natural && n.norm() > 0.0 && n.z / n.norm() >= GROUND_NORMAL_MIN_Z
    })
}

/// The ground below the horizon for the site's radiosity: `None` where the ground is modelled
/// (`ground_modelled = true`, or absent and [`scene_has_ground`]).
///
/// # Errors
/// [`SiteRenderError::Request`] for an albedo outside [0, 1].
pub fn site_ground_below_horizon(
    doc: &SiteDocument,
    scene: &Scene,
) -> Result<Option<GroundBelowHorizon>, SiteRenderError> {
    let l = &doc.site.lighting;
    let modelled = l.ground_modelled.unwrap_or_else(|| scene_has_ground(scene));
    if modelled {
        return Ok(None);
    }
    let albedo_rgb = l.ground_albedo.unwrap_or([DEFAULT_GROUND_ALBEDO; 3]);
    if albedo_rgb.iter().any(|a| !(0.0..=1.0).contains(a)) {
        return Err(SiteRenderError::Request {
            field: "[lighting] ground_albedo",
            reason: format!("{albedo_rgb:?}: each channel must be in [0, 1]"),
        });
    }
    Ok(Some(GroundBelowHorizon {
        albedo_rgb,
        ..GroundBelowHorizon::default()
    }))
}

/// The site's lighting for a radiosity transfer, the sun placed for photo `view` (or
/// `sun_manual`), with notes for the user (ambient weight ignored).
///
/// # Errors
/// Sky model, sun position and luminaire errors.
pub fn site_transfer_lighting(
    doc: &SiteDocument,
    scene: &Scene,
    view: &str,
) -> Result<(TransferLighting, Vec<String>), SiteRenderError> {
    let l = &doc.site.lighting;
    let sun_weighted = l.sun_weight.iter().any(|&k| k != 0.0);
    let sky_weighted = l.sky_weight.iter().any(|&k| k != 0.0);
    let needs_sun = sun_weighted || (sky_weighted && l.sky_model.needs_sun());
    let sun_dir: Option<Vector3<f64>> = if needs_sun {
        Some(site_sun_dir(doc, view)?)
    } else {
        None
    };
    let sun = sun_dir.map(|d| Sun {
        dir_in_world: d,
        normal_irradiance_rgb: if sun_weighted { l.sun_weight } else { [0.0; 3] },
    });
    let sky = if sky_weighted {
        let model = site_sky_model(doc, view, &sun_dir.unwrap_or_else(Vector3::z))?;
        Some(Sky {
            model,
            horizontal_irradiance_rgb: l.sky_weight,
        })
    } else {
        None
    };
    let lights = site_luminaire_lights(doc)?;
    let names = doc
        .site
        .luminaires
        .iter()
        .filter(|l| l.enabled)
        .map(|l| l.id.clone());
    let luminaires = names
        .zip(lights)
        .map(|(name, light)| NamedLuminaire {
            name: format!("luminaire:{name}"),
            source: match light {
                ArtificialLight::Point(p) => PointSource {
                    position_in_world_m: p.position_in_world_m,
                    luminaire: None,
                    intensity_rgb: p.intensity_rgb,
                },
                ArtificialLight::Luminaire(l) => PointSource {
                    position_in_world_m: l.luminaire.position_in_world,
                    luminaire: Some(l.luminaire.clone()),
                    intensity_rgb: l.rgb_per_cd,
                },
            },
            dimming: 1.0,
        })
        .collect();
    let emitters = scene.materials().iter().any(|m| {
        m.emission_rgb_w_m2_sr
            .is_some_and(|e| e.iter().any(|&v| v > 0.0))
    });
    let mut notes = Vec::new();
    if l.ambient_weight.iter().any(|&k| k != 0.0) {
        notes.push("ambient_weight is the renderer's term; the radiosity solve ignores it".into());
    }
    Ok((
        TransferLighting {
            sun,
            sky,
            luminaires,
            emitters,
        },
        notes,
    ))
}

/// A site's radiosity light groups, as [`site_light_groups`] builds them.
#[derive(Debug, Clone)]
pub struct SiteLightGroups {
    /// The lighting (sun, sky, luminaires, emitters) a transfer is built for.
    pub lighting: TransferLighting,
    /// The groups that carry light, in transfer order (sun, sky, each luminaire, emitters).
    pub groups: Vec<LightGroup>,
    /// Notes for the user (terms the radiosity ignores).
    pub notes: Vec<String>,
    /// Warnings about the sources (the sun below the horizon).
    pub warnings: Vec<LightWarning>,
}

/// The one builder of a site's radiosity light groups: [`site_transfer_lighting`]'s lighting
/// (sun placed for photo `view`) listed as [`TransferLighting::light_groups`] lists it on the
/// Tonn & Donath dome clustered to `sky_tolerance`, without the groups that carry no light (a
/// zero `sun_weight` or `sky_weight`, a sun at or below the horizon).
///
/// # Errors
/// Sky model, sun position and luminaire errors; invalid sources or a sky that cannot be
/// clustered ([`SiteRenderError::Sky`]).
pub fn site_light_groups(
    doc: &SiteDocument,
    scene: &Scene,
    view: &str,
    sky_tolerance: f64,
) -> Result<SiteLightGroups, SiteRenderError> {
    let (lighting, notes) = site_transfer_lighting(doc, scene, view)?;
    let dome = IcosahedralDome::new(&IcosahedralParams::tonn_donath())?;
    let (groups, warnings) =
        lighting
            .light_groups(&dome, sky_tolerance)
            .map_err(|e| SiteRenderError::Sky {
                reason: e.to_string(),
            })?;
    let groups = groups.into_iter().filter(carries_light).collect();
    Ok(SiteLightGroups {
        lighting,
        groups,
        notes,
        warnings,
    })
}

/// Whether a group has a source with light or takes the materials' emission.
fn carries_light(group: &LightGroup) -> bool {
    group.emission
        || group
            .sources
            .iter()
            .any(|s| s.normal_irradiance_rgb.iter().any(|&v| v != 0.0))
        || group
            .points
            .iter()
            .any(|p| p.intensity_rgb.iter().any(|&v| v != 0.0))
}
