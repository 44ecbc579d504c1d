//! Light groups' direct irradiance: distant sources (the sun, sky clusters) with shadow rays, and
//! the sky as clusters of the hierarchical icosahedral dome (Tonn & Donath, seed 000: "coherent
//! groups of skydome light sources can be mathematically grouped into a single light source of
//! the next higher hierarchical level"; Durisch 1992 §3.3 eq. 5 for facets as distant sources).
//!
//! A distant source of normal irradiance E_n in unit direction d gives an element with normal n
//! the irradiance E_n·max(0, n·d)·V, V the fraction of the element's stratified sample points
//! from which a ray towards d escapes the scene. With S sources and N points per element, each
//! source uses the points k ≡ s (mod S) (all N points for the sun, one point per cluster for a
//! many-cluster sky), so an element costs max(N, S) rays. Each element draws from its own
//! ChaCha8 stream (seed and group, stream = element index): thread-count independent.
//!
//! A point source (a luminaire, [`PointSource`]) of intensity I(ω) gives E = I(ω)·cos θ/d² at
//! each of the element's N points, with a shadow ray to the source, averaged over the points.
//!
//! # Known limitations
//! The sky is lit from above the horizon only; where the site's ground is not modelled, nothing
//! lights from below (the "ground below the horizon" choice is not made yet). The sun is
//! a point in direction d (no penumbra from the 0.53° disc). Luminaires are point sources (the
//! opening's size is ignored, as in the renderer).

use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::form_factor::FormFactorEngine;
use super::{RadiosityError, Rgb};
use crate::luminaire::Luminaire;
use crate::sky::SkyModel;
use crate::sky_dome::icosahedral::IcosahedralDome;

/// Shadow rays toward distant sources start this far from the surface, metres (above the `f32`
/// spacing of the tracer's local frame at a few hundred metres from its origin, 3e-5 m).
pub const DIRECT_RAY_OFFSET_M: f64 = 1e-4;

/// Rays toward distant sources stop here, metres (beyond any site).
const DIRECT_RAY_LENGTH_M: f32 = 1e7;

/// Random stream family of direct lighting, kept apart from the form-factor pairs' streams.
const DIRECT_SEED_SALT: u64 = 0x5EED_D1EC_7000_0000;

/// A light at infinity: the sun or a sky cluster.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistantSource {
    /// Unit vector towards the source, world frame.
    pub dir_in_world: Vector3<f64>,
    /// Irradiance on a plane facing the source, per channel.
    pub normal_irradiance_rgb: Rgb,
}

/// Checks that every source is finite, non-negative and has a unit direction.
///
/// # Errors
/// [`RadiosityError::InvalidSource`] naming the group.
pub fn validate(group: &str, sources: &[DistantSource]) -> Result<(), RadiosityError> {
    for (k, s) in sources.iter().enumerate() {
        let norm = s.dir_in_world.norm();
        if !(norm.is_finite() && (norm - 1.0).abs() < 1e-6) {
            return Err(RadiosityError::InvalidSource {
                group: group.to_owned(),
                reason: format!(
                    "source {k}: direction {:?} is not a unit vector",
                    s.dir_in_world
                ),
            });
        }
        if s.normal_irradiance_rgb
            .iter()
            .any(|v| !(v.is_finite() && *v >= 0.0))
        {
            return Err(RadiosityError::InvalidSource {
                group: group.to_owned(),
                reason: format!(
                    "source {k}: irradiance {:?} must be finite and ≥ 0",
                    s.normal_irradiance_rgb
                ),
            });
        }
    }
    Ok(())
}

/// Direct irradiance per element from `sources` (module doc). `group_index` separates the random
/// streams of different groups.
#[must_use]
pub fn direct_irradiance(
    engine: &FormFactorEngine<'_>,
    sources: &[DistantSource],
    group_index: u64,
) -> Vec<Rgb> {
    let mesh = engine.mesh();
    let tracer = engine.tracer();
    let params = engine.params();
    let n = params.samples_per_axis as usize;
    let points = n * n;
    #[allow(clippy::cast_precision_loss)]
    let inv_n = 1.0 / n as f64;
    (0..mesh.elements.len())
        .into_par_iter()
        .map(|e| {
            let node = mesh.element_node(e);
            let mut rng = ChaCha8Rng::seed_from_u64(params.seed ^ DIRECT_SEED_SALT ^ group_index);
            rng.set_stream(e as u64);
            #[allow(clippy::cast_precision_loss)]
            let samples: Vec<_> = (0..points)
                .map(|k| {
                    let u = ((k / n) as f64 + rng.random::<f64>()) * inv_n;
                    let v = ((k % n) as f64 + rng.random::<f64>()) * inv_n;
                    node.point_at(u, v)
                })
                .collect();
            let mut e_rgb = [0.0; 3];
            for (s, source) in sources.iter().enumerate() {
                let cos = node.normal_in_world.dot(&source.dir_in_world);
                if cos <= 0.0 {
                    continue;
                }
                let mut hits = 0usize;
                let mut rays = 0usize;
                let mut k = s % points;
                loop {
                    rays += 1;
                    #[allow(clippy::cast_possible_truncation)]
                    let ray = tracer.ray_from_world(
                        &samples[k],
                        &source.dir_in_world,
                        DIRECT_RAY_OFFSET_M as f32,
                        DIRECT_RAY_LENGTH_M,
                    );
                    if !params.visibility || !tracer.any_hit(&ray) {
                        hits += 1;
                    }
                    k += sources.len();
                    if k >= points {
                        break;
                    }
                }
                #[allow(clippy::cast_precision_loss)]
                let visible = hits as f64 / rays as f64;
                for c in 0..3 {
                    e_rgb[c] += source.normal_irradiance_rgb[c] * cos * visible;
                }
            }
            e_rgb
        })
        .collect()
}

/// The sky `model` (sun in `sun_dir_in_world`) as clusters of `dome`'s leaves under the relative
/// tolerance `tolerance` ([`IcosahedralDome::cluster`]), scaled so that the unobstructed
/// horizontal irradiance is `horizontal_irradiance_rgb` (the site's `sky_weight`, as the
/// renderer's `sky_lights` scales its facets).
///
/// # Errors
/// [`RadiosityError::InvalidSource`] when the model gives no light above the horizon or a weight
/// is negative; dome errors for a bad tolerance.
pub fn sky_sources(
    model: &SkyModel,
    sun_dir_in_world: &Vector3<f64>,
    horizontal_irradiance_rgb: Rgb,
    dome: &IcosahedralDome,
    tolerance: f64,
) -> Result<Vec<DistantSource>, RadiosityError> {
    let bad = |reason: String| RadiosityError::InvalidSource {
        group: "sky".into(),
        reason,
    };
    if horizontal_irradiance_rgb
        .iter()
        .any(|v| !(v.is_finite() && *v >= 0.0))
    {
        return Err(bad(format!(
            "sky weight {horizontal_irradiance_rgb:?} must be finite and ≥ 0"
        )));
    }
    let flux: Vec<f64> = dome
        .leaves
        .iter()
        .map(|f| {
            model.relative_luminance(&f.centre_dir_in_world, sun_dir_in_world) * f.solid_angle_sr
        })
        .collect();
    let horizontal: f64 = dome
        .leaves
        .iter()
        .zip(&flux)
        .map(|(f, phi)| phi * f.centre_dir_in_world.z.max(0.0))
        .sum();
    if !(horizontal.is_finite() && horizontal > 0.0) {
        return Err(bad(format!(
            "the sky model gives horizontal irradiance {horizontal} above the horizon"
        )));
    }
    let (clusters, _bound) = dome.cluster(&flux, tolerance)?;
    Ok(clusters
        .into_iter()
        .map(|c| DistantSource {
            dir_in_world: c.dir_in_world,
            normal_irradiance_rgb: horizontal_irradiance_rgb
                .map(|k| k * c.integrated_luminance / horizontal),
        })
        .collect())
}

/// A point source: an isotropic light or a luminaire with its photometric web.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSource {
    /// Position (photometric centre), world metres.
    pub position_in_world_m: Point3<f64>,
    /// The positioned, aimed luminaire; `None` for an isotropic source.
    pub luminaire: Option<Luminaire>,
    /// Intensity per channel: the isotropic intensity, or the factor per candela of the web.
    pub intensity_rgb: Rgb,
}

impl PointSource {
    /// Intensity towards the unit direction `dir_from_light_in_world`, per channel.
    #[must_use]
    pub fn intensity_toward_rgb(&self, dir_from_light_in_world: &Vector3<f64>) -> Rgb {
        let cd = self
            .luminaire
            .as_ref()
            .map_or(1.0, |l| l.intensity_toward_cd(dir_from_light_in_world));
        self.intensity_rgb.map(|k| k * cd)
    }
}

/// Checks point sources: finite position, finite non-negative intensity.
///
/// # Errors
/// [`RadiosityError::InvalidSource`] naming the group.
pub fn validate_points(group: &str, points: &[PointSource]) -> Result<(), RadiosityError> {
    for (k, p) in points.iter().enumerate() {
        if !p.position_in_world_m.coords.iter().all(|c| c.is_finite())
            || p.intensity_rgb
                .iter()
                .any(|v| !(v.is_finite() && *v >= 0.0))
        {
            return Err(RadiosityError::InvalidSource {
                group: group.to_owned(),
                reason: format!(
                    "point source {k}: position {:?} and intensity {:?} must be finite (intensity ≥ 0)",
                    p.position_in_world_m.coords, p.intensity_rgb
                ),
            });
        }
    }
    Ok(())
}

/// Direct irradiance per element from point sources (module doc).
#[must_use]
pub fn point_irradiance(
    engine: &FormFactorEngine<'_>,
    points: &[PointSource],
    group_index: u64,
) -> Vec<Rgb> {
    let mesh = engine.mesh();
    let params = engine.params();
    let n = params.samples_per_axis as usize;
    #[allow(clippy::cast_precision_loss)]
    let inv_n = 1.0 / n as f64;
    (0..mesh.elements.len())
        .into_par_iter()
        .map(|e| {
            let node = mesh.element_node(e);
            let mut rng = ChaCha8Rng::seed_from_u64(params.seed ^ DIRECT_SEED_SALT ^ group_index);
            rng.set_stream(e as u64);
            let mut e_rgb = [0.0; 3];
            #[allow(clippy::cast_precision_loss)]
            for k in 0..n * n {
                let u = ((k / n) as f64 + rng.random::<f64>()) * inv_n;
                let v = ((k % n) as f64 + rng.random::<f64>()) * inv_n;
                let x = node.point_at(u, v);
                for p in points {
                    let to_light = p.position_in_world_m - x;
                    let d2 = to_light.norm_squared();
                    if d2 <= 0.0 {
                        continue;
                    }
                    let d = d2.sqrt();
                    let cos = node.normal_in_world.dot(&to_light) / d;
                    if cos <= 0.0 {
                        continue;
                    }
                    if params.visibility && !engine.visible(&x, &p.position_in_world_m) {
                        continue;
                    }
                    let intensity = p.intensity_toward_rgb(&(-to_light / d));
                    for c in 0..3 {
                        e_rgb[c] += intensity[c] * cos / d2;
                    }
                }
            }
            e_rgb.map(|v| v * inv_n * inv_n)
        })
        .collect()
}
