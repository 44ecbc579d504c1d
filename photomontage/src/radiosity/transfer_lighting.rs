//! The lighting a precomputed transfer ([`super::transfer`]) is built for and relit to: the
//! sun, the sky, the luminaires with their dimming, and the change a relight applies; and how
//! that lighting becomes light groups (the sky clustered on the dome, each luminaire its own
//! group).

use nalgebra::Vector3;

use super::solve::SkyLight;
use super::sources::{self, LightWarning, PointSource};
use super::{LightGroup, RadiosityError, Rgb};
use crate::sky::SkyModel;
use crate::sky_dome::icosahedral::IcosahedralDome;

/// The sun as a distant source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sun {
    /// Unit vector towards the sun, world frame (z up).
    pub dir_in_world: Vector3<f64>,
    /// Irradiance on a plane facing the sun, per channel.
    pub normal_irradiance_rgb: Rgb,
}

/// The sky: a luminance model scaled to a horizontal irradiance.
#[derive(Debug, Clone, PartialEq)]
pub struct Sky {
    /// Any sky model of [`crate::sky`] (uniform, CIE overcast, CIE general 1–15, Perez).
    pub model: SkyModel,
    /// Unobstructed horizontal irradiance of the sky, per channel (the site's `sky_weight`).
    pub horizontal_irradiance_rgb: Rgb,
}

/// A luminaire (or isotropic point light) with its dimming factor.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedLuminaire {
    /// Group name (`luminaire:ID` in the CLI).
    pub name: String,
    /// The source at full output.
    pub source: PointSource,
    /// Output factor, ≥ 0 (1 = full).
    pub dimming: f64,
}

/// The lighting a transfer is built for and relit to.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferLighting {
    /// The sun, `None` when there is none.
    pub sun: Option<Sun>,
    /// The sky, `None` when there is none.
    pub sky: Option<Sky>,
    /// Luminaires, one light group each.
    pub luminaires: Vec<NamedLuminaire>,
    /// Whether the emitting materials form a group.
    pub emitters: bool,
}

/// What [`Transfer::relight`] changes; `None`/empty fields keep the current value.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LightingChange {
    /// A new sun (`Some(None)` switches it off).
    pub sun: Option<Option<Sun>>,
    /// A new sky (`Some(None)` switches it off).
    pub sky: Option<Option<Sky>>,
    /// New dimming factors by luminaire name.
    pub luminaire_dimming: Vec<(String, f64)>,
    /// New diffuse reflectance (RGB, each in [0, 1]) by material name.
    pub material_reflectance: Vec<(String, Rgb)>,
}

pub(super) fn check_rgb(name: &str, what: &str, rgb: Rgb, max: f64) -> Result<(), RadiosityError> {
    if rgb.iter().all(|v| v.is_finite() && *v >= 0.0 && *v <= max) {
        Ok(())
    } else {
        Err(RadiosityError::InvalidSource {
            group: name.to_owned(),
            reason: format!("{what} {rgb:?} must be finite and in [0, {max}]"),
        })
    }
}

impl TransferLighting {
    /// The light groups in transfer order: sun, sky, each luminaire, emitters (sun and sky are
    /// always present, empty when off), with the warnings of the sun's position.
    ///
    /// # Errors
    /// Invalid sources, sky models without light.
    pub fn light_groups(
        &self,
        dome: &IcosahedralDome,
        sky_tolerance: f64,
    ) -> Result<(Vec<LightGroup>, Vec<LightWarning>), RadiosityError> {
        self.light_groups_keeping_sky(dome, sky_tolerance, None)
    }

    /// [`Self::light_groups`] with the sky group `kept` instead of clustering the sky again,
    /// where the caller knows the sky's sources are unchanged (the same sky, and a sun that it
    /// does not follow, or that did not move; a relight's sun step). The kept group's sun is set
    /// to this lighting's, so that it equals what clustering would give.
    ///
    /// # Errors
    /// As [`Self::light_groups`].
    pub fn light_groups_keeping_sky(
        &self,
        dome: &IcosahedralDome,
        sky_tolerance: f64,
        kept: Option<&LightGroup>,
    ) -> Result<(Vec<LightGroup>, Vec<LightWarning>), RadiosityError> {
        let mut warnings = Vec::new();
        let sun_group = self.sun_group(&mut warnings)?;
        let sky_group = match kept {
            Some(group) => {
                let mut group = group.clone();
                if let Some(sky) = &mut group.sky {
                    sky.sun_dir_in_world = self
                        .sun
                        .as_ref()
                        .map_or_else(Vector3::z, |s| s.dir_in_world);
                }
                group
            }
            None => self.sky_group(dome, sky_tolerance)?,
        };
        let mut groups = vec![sun_group, sky_group];
        for l in &self.luminaires {
            groups.push(luminaire_group(l)?);
        }
        if self.emitters {
            groups.push(LightGroup::emitters());
        }
        Ok((groups, warnings))
    }

    fn sun_group(&self, warnings: &mut Vec<LightWarning>) -> Result<LightGroup, RadiosityError> {
        let mut group = LightGroup::sun(Vector3::z(), [0.0; 3]);
        group.sources.clear();
        if let Some(sun) = &self.sun {
            check_rgb(
                "sun",
                "normal irradiance",
                sun.normal_irradiance_rgb,
                f64::MAX,
            )?;
            let norm = sun.dir_in_world.norm();
            if !(norm.is_finite() && (norm - 1.0).abs() < 1e-6) {
                return Err(RadiosityError::InvalidSource {
                    group: "sun".into(),
                    reason: format!("direction {:?} is not a unit vector", sun.dir_in_world),
                });
            }
            if sun.dir_in_world.z <= 0.0 {
                warnings.push(LightWarning::SunBelowHorizon {
                    elevation_deg: sun.dir_in_world.z.clamp(-1.0, 1.0).asin().to_degrees(),
                });
            } else {
                group = LightGroup::sun(sun.dir_in_world, sun.normal_irradiance_rgb);
            }
        }
        Ok(group)
    }

    fn sky_group(
        &self,
        dome: &IcosahedralDome,
        tolerance: f64,
    ) -> Result<LightGroup, RadiosityError> {
        let Some(sky) = &self.sky else {
            return Ok(LightGroup::sky(Vec::new()));
        };
        check_rgb(
            "sky",
            "horizontal irradiance",
            sky.horizontal_irradiance_rgb,
            f64::MAX,
        )?;
        if sky.horizontal_irradiance_rgb.iter().all(|&v| v == 0.0) {
            return Ok(LightGroup::sky(Vec::new()));
        }
        let sun_dir = self
            .sun
            .as_ref()
            .map_or_else(Vector3::z, |s| s.dir_in_world);
        let mut group = LightGroup::sky(sources::sky_sources(
            &sky.model,
            &sun_dir,
            sky.horizontal_irradiance_rgb,
            dome,
            tolerance,
        )?);
        group.sky = Some(SkyLight {
            model: sky.model,
            sun_dir_in_world: sun_dir,
            horizontal_irradiance_rgb: sky.horizontal_irradiance_rgb,
        });
        Ok(group)
    }
}

fn luminaire_group(l: &NamedLuminaire) -> Result<LightGroup, RadiosityError> {
    if !(l.dimming.is_finite() && l.dimming >= 0.0) {
        return Err(RadiosityError::InvalidSource {
            group: l.name.clone(),
            reason: format!("dimming {} must be finite and ≥ 0", l.dimming),
        });
    }
    let mut source = l.source.clone();
    source.intensity_rgb = source.intensity_rgb.map(|v| v * l.dimming);
    Ok(LightGroup::luminaire(&l.name, source))
}
