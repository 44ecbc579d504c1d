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
//! ChaCha8 stream (seed and group, stream = element index, or its twin's in the natural mesh:
//! [`super::twin`]): thread-count independent.
//!
//! A point source (a luminaire, [`PointSource`]) of intensity I(ω) gives E = I(ω)·cos θ/d² at
//! each of the element's N points, with a shadow ray to the source, averaged over the points.
//!
//! **Ground below the horizon** ([`GroundBelowHorizon`]): where the site's ground is not modelled,
//! the lower hemisphere is a uniform Lambertian ground of albedo a lit by the group's own distant
//! sources, radiance L_g = a·E_h/π with E_h the group's unobstructed horizontal irradiance
//! (Σ E_n·max(0, d_z)); it is discretised as the upper dome's uniform-radiance clusters mirrored
//! below the horizon ([`ground_sources`]), each carrying its irradiance vector exactly as
//! [`IcosahedralDome::cluster`] does, so a plane that sees the whole lower hemisphere (a vertical
//! wall sees half of it) gets L_g·π·(1 − cos tilt)/2 to the clustering tolerance. Because L_g is
//! linear in the group's sources, each group keeps its own ground term and groups still add.
//!
//! # Known limitations
//! The ground below the horizon is uniform (no shadow of the buildings on it, no view of the
//! sky's horizon brightening from below); a modelled ground is used instead where there is one. The sun is
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
pub(super) const DIRECT_RAY_LENGTH_M: f32 = 1e7;

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

/// The stratified sample points of every element for one group's direct light (module doc):
/// element e's points are `points[e·n .. (e+1)·n]`, n = `samples_per_axis`², drawn from the
/// element's own stream. A transfer keeps them, so a relight re-traces only the rays.
#[derive(Debug, Clone)]
pub struct DirectSamples {
    per_element: usize,
    points: Vec<Point3<f64>>,
}

impl DirectSamples {
    /// The points of group `group_index` on `engine`'s mesh.
    #[must_use]
    pub fn new(engine: &FormFactorEngine<'_>, group_index: u64) -> Self {
        let mesh = engine.mesh();
        let params = engine.params();
        let n = params.samples_per_axis as usize;
        #[allow(clippy::cast_precision_loss)]
        let inv_n = 1.0 / n as f64;
        let points = (0..mesh.elements.len())
            .into_par_iter()
            .flat_map_iter(|e| {
                let node = mesh.element_node(e);
                let mut rng =
                    ChaCha8Rng::seed_from_u64(params.seed ^ DIRECT_SEED_SALT ^ group_index);
                rng.set_stream(engine.direct_stream(e));
                #[allow(clippy::cast_precision_loss)]
                (0..n * n)
                    .map(|k| {
                        let u = ((k / n) as f64 + rng.random::<f64>()) * inv_n;
                        let v = ((k % n) as f64 + rng.random::<f64>()) * inv_n;
                        node.point_at(u, v)
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        Self {
            per_element: n * n,
            points,
        }
    }

    /// Whether these are the points of a mesh of `elements` elements with `per_element` points
    /// each.
    #[must_use]
    pub fn fits(&self, elements: usize, per_element: usize) -> bool {
        self.per_element == per_element && self.points.len() == elements * per_element
    }

    /// Points per element.
    #[must_use]
    pub fn per_element(&self) -> usize {
        self.per_element
    }

    /// Element `e`'s points.
    #[must_use]
    pub fn of_element(&self, e: usize) -> &[Point3<f64>] {
        &self.points[e * self.per_element..(e + 1) * self.per_element]
    }
}

/// Direct irradiance per element from `sources` (module doc). `group_index` separates the random
/// streams of different groups.
#[must_use]
pub fn direct_irradiance(
    engine: &FormFactorEngine<'_>,
    sources: &[DistantSource],
    group_index: u64,
) -> Vec<Rgb> {
    if sources.is_empty() {
        return vec![[0.0; 3]; engine.mesh().elements.len()];
    }
    direct_irradiance_at(engine, &DirectSamples::new(engine, group_index), sources)
}

/// [`direct_irradiance`] from sample points drawn before (the same points give the same values,
/// bit for bit).
///
/// # Panics
/// When `samples` were drawn for another mesh or sample count.
#[must_use]
pub fn direct_irradiance_at(
    engine: &FormFactorEngine<'_>,
    samples: &DirectSamples,
    sources: &[DistantSource],
) -> Vec<Rgb> {
    let mesh = engine.mesh();
    let tracer = engine.tracer();
    let params = engine.params();
    let points = samples.per_element;
    assert!(
        samples.fits(mesh.elements.len(), points)
            && points == (params.samples_per_axis as usize).pow(2),
        "direct-light samples drawn for another mesh"
    );
    (0..mesh.elements.len())
        .into_par_iter()
        .map(|e| {
            let node = mesh.element_node(e);
            let samples = &samples.points[e * points..(e + 1) * points];
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
    let (flux, horizontal) = sky_leaf_flux(model, sun_dir_in_world, dome)?;
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

/// Each leaf's ∫L dω of the sky `model` (sun in `sun_dir_in_world`) in relative units, and the
/// unobstructed horizontal irradiance Σ Φ_i·max(0, d_z) they give.
///
/// # Errors
/// [`RadiosityError::InvalidSource`] when the model gives no light above the horizon.
pub fn sky_leaf_flux(
    model: &SkyModel,
    sun_dir_in_world: &Vector3<f64>,
    dome: &IcosahedralDome,
) -> Result<(Vec<f64>, f64), RadiosityError> {
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
        return Err(RadiosityError::InvalidSource {
            group: "sky".into(),
            reason: format!(
                "the sky model gives horizontal irradiance {horizontal} above the horizon"
            ),
        });
    }
    Ok((flux, horizontal))
}

/// The lower hemisphere as a uniform ground of the given albedo (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundBelowHorizon {
    /// Diffuse albedo of the unmodelled ground per channel, in [0, 1] (0.2 is the usual value
    /// for mixed urban ground, CIE 171:2006 test cases use 0.2–0.3).
    pub albedo_rgb: Rgb,
    /// Clustering tolerance of the mirrored uniform dome ([`IcosahedralDome::cluster`]).
    pub cluster_tolerance: f64,
}

impl Default for GroundBelowHorizon {
    /// Albedo 0.2, clustering tolerance 0.02.
    fn default() -> Self {
        Self {
            albedo_rgb: [0.2; 3],
            cluster_tolerance: 0.02,
        }
    }
}

impl GroundBelowHorizon {
    /// Checks the albedo and tolerance.
    ///
    /// # Errors
    /// [`RadiosityError::InvalidParameter`] outside [0, 1] or for a bad tolerance.
    pub fn validate(&self) -> Result<(), RadiosityError> {
        for &a in &self.albedo_rgb {
            if !(0.0..=1.0).contains(&a) {
                return Err(RadiosityError::InvalidParameter {
                    name: "ground_albedo",
                    value: a,
                    reason: "must be in [0, 1]",
                });
            }
        }
        if !(self.cluster_tolerance.is_finite() && self.cluster_tolerance >= 0.0) {
            return Err(RadiosityError::InvalidParameter {
                name: "ground_cluster_tolerance",
                value: self.cluster_tolerance,
                reason: "must be finite and ≥ 0",
            });
        }
        Ok(())
    }

    /// Ground radiance L_g = a·E_h/π per channel for a group of distant `sources`.
    #[must_use]
    pub fn radiance_rgb(&self, sources: &[DistantSource]) -> Rgb {
        let e_h = horizontal_irradiance_rgb(sources);
        std::array::from_fn(|c| self.albedo_rgb[c] * e_h[c] / std::f64::consts::PI)
    }
}

/// Unobstructed horizontal irradiance of distant sources, Σ E_n·max(0, d_z).
#[must_use]
pub fn horizontal_irradiance_rgb(sources: &[DistantSource]) -> Rgb {
    let mut e = [0.0; 3];
    for s in sources {
        let z = s.dir_in_world.z.max(0.0);
        for c in 0..3 {
            e[c] += s.normal_irradiance_rgb[c] * z;
        }
    }
    e
}

/// The lower hemisphere as distant sources of unit radiance: the uniform-radiance clusters of
/// `dome` under `tolerance`, mirrored below the horizon; a source's normal irradiance (all
/// channels) is its cluster's |Σ Ω_i·d_i| (module doc).
///
/// # Errors
/// Dome errors for a bad tolerance.
pub fn ground_sources(
    dome: &IcosahedralDome,
    tolerance: f64,
) -> Result<Vec<DistantSource>, RadiosityError> {
    let flux: Vec<f64> = dome.leaves.iter().map(|f| f.solid_angle_sr).collect();
    let (clusters, _bound) = dome.cluster(&flux, tolerance)?;
    Ok(clusters
        .into_iter()
        .map(|c| {
            let d = c.dir_in_world;
            DistantSource {
                dir_in_world: Vector3::new(d.x, d.y, -d.z),
                normal_irradiance_rgb: [c.integrated_luminance; 3],
            }
        })
        .collect())
}

/// Per element, the irradiance from a unit-radiance ground below the horizon, Σ_c |S_c|·cos·V
/// (shadowed like any distant group; random streams apart from the light groups').
#[must_use]
pub fn ground_transfer(engine: &FormFactorEngine<'_>, ground: &[DistantSource]) -> Vec<f64> {
    direct_irradiance(engine, ground, GROUND_STREAM)
        .into_iter()
        .map(|e| e[0])
        .collect()
}

/// Group index of the ground term's random streams (far from any real group index).
const GROUND_STREAM: u64 = 0xFFFF_0000;

/// A light that does not do what it seems to (warnings, naming the light and the object).
#[derive(Debug, Clone, PartialEq)]
pub enum LightWarning {
    /// More than [`INSIDE_PROBE_FRACTION`] of the probe rays from a point source meet the back of
    /// a surface: it sits inside a closed object, and its light never reaches a front face.
    LuminaireInsideObject {
        /// Light group name.
        group: String,
        /// The object around it (the nearest back face's).
        object: String,
    },
    /// A point source lies within [`LUMINAIRE_WALL_EPS_M`] behind a surface (it faces away from
    /// the source): half of its light is lost in the wall.
    LuminaireBehindSurface {
        /// Light group name.
        group: String,
        /// The object whose surface faces away.
        object: String,
        /// Distance to that surface, metres.
        distance_m: f64,
    },
    /// The sun is at or below the horizon: the sun group gives no light.
    SunBelowHorizon {
        /// Sun elevation, degrees.
        elevation_deg: f64,
    },
}

impl std::fmt::Display for LightWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::LuminaireInsideObject { group, object } => write!(
                f,
                "light `{group}` is inside object `{object}` (the rays from it meet the back of \
                 its surfaces); it lights nothing"
            ),
            Self::LuminaireBehindSurface {
                group,
                object,
                distance_m,
            } => write!(
                f,
                "light `{group}` is {distance_m:.4} m behind a surface of object `{object}` (the \
                 surface faces away from it); its light into that side is lost"
            ),
            Self::SunBelowHorizon { elevation_deg } => write!(
                f,
                "the sun is below the horizon (elevation {elevation_deg:.2}°): no sun light"
            ),
        }
    }
}

/// A point source this close behind a surface is reported ([`LightWarning::LuminaireBehindSurface`]),
/// metres (a luminaire's photometric centre sits in front of its mounting surface; 5 cm covers
/// modelling slop without flagging lights recessed in a ceiling).
pub const LUMINAIRE_WALL_EPS_M: f64 = 0.05;

/// A point source is inside a closed object when more than this fraction of its 26 probe rays
/// meet back faces (not all: a building standing on the ground is often open at the bottom, or
/// shares its bottom face with the ground's plane, whose front face may be hit first; a light
/// outside sees the sky or front faces in most directions).
pub const INSIDE_PROBE_FRACTION: f64 = 0.5;

/// Directions probed from a point source: the 26 neighbours of a cube cell.
fn probe_directions() -> Vec<Vector3<f64>> {
    let mut out = Vec::with_capacity(26);
    for x in -1i32..=1 {
        for y in -1i32..=1 {
            for z in -1i32..=1 {
                if (x, y, z) != (0, 0, 0) {
                    out.push(Vector3::new(f64::from(x), f64::from(y), f64::from(z)).normalize());
                }
            }
        }
    }
    out
}

/// Checks where point sources sit: inside a closed object ([`INSIDE_PROBE_FRACTION`] of 26
/// probe rays meet back faces)
/// or within [`LUMINAIRE_WALL_EPS_M`] behind a surface (a probe ray meets a back face that
/// close). `object_names` is indexed by [`crate::scene::ObjectId`].
#[must_use]
pub fn check_point_sources(
    tracer: &crate::scene::SceneTracer,
    group: &str,
    points: &[PointSource],
    object_names: &[String],
) -> Vec<LightWarning> {
    let dirs = probe_directions();
    let mut out = Vec::new();
    for p in points {
        let mut back_hits = 0;
        let mut nearest_back: Option<(f64, String)> = None;
        for d in &dirs {
            let ray = tracer.ray_from_world(&p.position_in_world_m, d, 0.0, DIRECT_RAY_LENGTH_M);
            let Some(hit) = tracer.closest_hit(&ray) else {
                continue;
            };
            let normal = Vector3::from(hit.hit.normal_geometric.map(f64::from));
            let cos = normal.dot(d);
            if cos > 0.0 {
                back_hits += 1;
                let distance = f64::from(hit.hit.t) * cos;
                if nearest_back
                    .as_ref()
                    .is_none_or(|(best, _)| distance < *best)
                {
                    let object = object_names
                        .get(hit.object.0 as usize)
                        .cloned()
                        .unwrap_or_else(|| format!("#{}", hit.object.0));
                    nearest_back = Some((distance, object));
                }
            }
        }
        if let Some((distance_m, object)) = nearest_back {
            #[allow(clippy::cast_precision_loss)]
            if back_hits as f64 > INSIDE_PROBE_FRACTION * dirs.len() as f64 {
                out.push(LightWarning::LuminaireInsideObject {
                    group: group.to_owned(),
                    object,
                });
            } else if distance_m <= LUMINAIRE_WALL_EPS_M {
                out.push(LightWarning::LuminaireBehindSurface {
                    group: group.to_owned(),
                    object,
                    distance_m,
                });
            }
        }
    }
    out
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
            rng.set_stream(engine.direct_stream(e));
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
