//! Replaying primary samples of the radiosity mode under other light and materials without
//! tracing (issue 17: "the montage preview updates within a frame for the radiosity part and
//! refines progressively for the rest").
//!
//! In the radiosity mode ([`super::radiosity_light`]) a primary sample's radiance is a closed
//! function of what its rays found (the point's element on each radiosity mesh, the sun's and
//! the luminaires' shadow rays, the photo's colour there) and of what a studio edit changes (the
//! materials' reflectances, the sun's and sky's irradiance, the atmosphere, and the two relit
//! radiosity solutions). The tracer computes the first part into a record ([`SampleReplay`]) and
//! evaluates the second with the same functions it renders with ([`Shade::replay`]),
//! so a replay under the lights and materials of the trace returns the traced value bit for bit,
//! and one under a relit solution and changed materials returns what a new trace would.
//!
//! - **Case C** (artificial point): `L = apparent(ρ/π·(E_sun·passed + E_ambient + E_rad,with(x) +
//!   E_lights) + L_emit + mirror + specular + glass)` — ρ, L_emit and the mirror colour from the
//!   current material, E_sun and E_ambient from the current daylight on the kept shading normal
//!   and sun transmittance, E_rad,with read on the kept element.
//! - **Case D** (natural point): the eq. 10 inversion with the current daylight and E_rad,without,
//!   the change D1 − D3 + E_rad,with − E_rad,without, and the unchanged test, from the kept photo
//!   colour, D1 irradiance and D3 blocked fraction.
//!
//! # Known limitations
//! What the record keeps of rays is the state they saw: after a sun move the shadows (the sun's
//! transmittance in case C, the D3 fraction in case D) stay where they were until the samples are
//! traced again, and a mirror's incoming light, a glossy highlight and a glass pane's
//! transmitted and reflected light are kept as traced (the mirror's colour follows the
//! material). A point that lies on no element of a solution (the facet path) keeps its traced
//! irradiance (case C: ρ still follows the material) or its traced value (case D).

use nalgebra::Vector3;

use super::radiosity_light::RadiosityLight;
use super::shading::{Shade, true_colour_rgb};
use super::{DifferentialTracer, PrimaryHit};
use crate::radiosity::PointOnElement;
use crate::render::illumination::{
    Rgb, add, diffuse_radiance_rgb, diffuse_reflectance_from_true_colour, mul,
    natural_irradiance_rgb, natural_irradiance_weighted_rgb, scale,
};

/// What a case C shading depends on besides the material and the light a studio edit changes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArtificialParts {
    /// The hit's material id (its ρ, emission and mirror colour are read at evaluation).
    pub material: u32,
    /// Distance along the ray, metres.
    pub distance_m: f64,
    /// The shading normal (water waves applied).
    pub shading_normal: Vector3<f64>,
    /// Fraction of the sun reaching the point per channel (shadow ray; 0 from behind).
    pub sun_passed: Rgb,
    /// Irradiance from the artificial lights on the shading normal.
    pub e_lights_rgb: Rgb,
    /// The whole irradiance where the point lies on no element of the solution with the
    /// artificial objects (the facet path: sky facets, lights, photo bounce), else `None`.
    pub e_traced_rgb: Option<Rgb>,
    /// Light a mirror material reflects in, as traced (`None`: no mirror ray).
    pub mirror_incoming_rgb: Option<Rgb>,
    /// The glossy lobe's radiance, as traced.
    pub specular_rgb: Option<Rgb>,
    /// A glass pane's reflected and transmitted radiance, as traced.
    pub glass_rgb: Option<Rgb>,
}

/// What a case D sample in the radiosity mode depends on besides the light a studio edit
/// changes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NaturalParts {
    /// The hit's material id (ρ where no natural light reaches the point).
    pub material: u32,
    /// The photo's apparent colour of the point.
    pub photo_rgb: Rgb,
    /// The distance it was photographed from, metres.
    pub photo_distance_m: f64,
    /// Distance along the ray, metres.
    pub distance_m: f64,
    /// The geometric normal facing the ray.
    pub normal: Vector3<f64>,
    /// Whether the sun reaches the point past the natural geometry.
    pub sun_natural: bool,
    /// D3: the fraction of the sun an artificial object takes (and no natural one), per channel.
    pub sun_d3: Option<Rgb>,
    /// D1: the artificial lights' irradiance, and whether any reaches the point.
    pub e_d1_rgb: Rgb,
    /// Whether an artificial light reaches the point.
    pub lit_d1: bool,
}

/// One primary sample kept for replay.
#[derive(Debug, Clone, PartialEq)]
pub enum SampleReplay {
    /// Not a function of what an edit changes here (case A; a natural point on no element of a
    /// solution): the traced value is kept.
    Kept,
    /// Case C, with the point on the mesh with the artificial objects.
    Artificial {
        /// The shading's parts.
        parts: Box<ArtificialParts>,
        /// The point on the radiosity mesh with the artificial objects.
        at: Option<PointOnElement>,
    },
    /// Case D in the radiosity mode, with the point on both meshes.
    Natural {
        /// The inversion's parts.
        parts: Box<NaturalParts>,
        /// The point on the meshes with and without the artificial objects.
        at: [PointOnElement; 2],
    },
}

/// A primary sample as traced, with what replaying it needs.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedSample {
    /// The traced radiance, and whether it differs from the photo.
    pub radiance_rgb: Rgb,
    /// Whether it differed from the photo.
    pub changed: bool,
    /// Whether the first hit is artificial.
    pub hit_artificial: bool,
    /// The first hit.
    pub first_hit: Option<PrimaryHit>,
    /// What the replay evaluates.
    pub replay: SampleReplay,
}

impl Shade<'_> {
    /// Case C's radiance from its parts, with `e_rad` the irradiance of the solution with the
    /// artificial objects at the point (`None` on the facet path, where `parts.e_traced_rgb`
    /// holds the whole irradiance). The renderer's case C ends here, and so does its replay.
    pub(super) fn artificial_radiance(&self, parts: &ArtificialParts, e_rad: Option<Rgb>) -> Rgb {
        let material = self.materials.get(parts.material as usize);
        let rho = material.map_or([0.5; 3], crate::scene::Material::diffuse_reflectance_rgb);
        let e = match (e_rad, parts.e_traced_rgb) {
            (Some(e_rad), _) => add(
                add(
                    natural_irradiance_weighted_rgb(
                        &self.lighting.daylight,
                        &parts.shading_normal,
                        parts.sun_passed,
                        |_| [0.0; 3],
                    ),
                    e_rad,
                ),
                parts.e_lights_rgb,
            ),
            (None, Some(e)) => e,
            // Never both: a traced point has one or the other.
            (None, None) => parts.e_lights_rgb,
        };
        let mut l0 = diffuse_radiance_rgb(rho, e);
        if let Some(m) = material {
            if let Some(emission) = m.emission_rgb_w_m2_sr {
                l0 = add(l0, emission);
            }
            if let (Some(mirror), Some(incoming)) = (m.mirror_rgb, parts.mirror_incoming_rgb) {
                l0 = add(l0, mul(mirror, incoming));
            }
            if let (Some(_), Some(spec)) = (&m.specular, parts.specular_rgb) {
                l0 = add(l0, spec);
            }
            if let (Some(_), Some(glass)) = (&m.glass, parts.glass_rgb) {
                l0 = add(l0, glass);
            }
        }
        self.apparent(l0, parts.distance_m)
    }

    /// Case D's radiance in the radiosity mode from its parts and the irradiance of the two
    /// solutions at the point (`[with, without]` the artificial objects); also whether it
    /// differs from the photo.
    pub(super) fn natural_radiance(
        &self,
        parts: &NaturalParts,
        e_rad: [Rgb; 2],
        radiosity: &RadiosityLight,
    ) -> (Rgb, bool) {
        let [e_with, e_without] = e_rad;
        let daylight = &self.lighting.daylight;
        let normal = &parts.normal;
        let e_natural = add(
            natural_irradiance_rgb(daylight, normal, parts.sun_natural, |_| false),
            e_without,
        );
        let e_change = add(e_with, scale(e_without, -1.0));
        let unchanged =
            parts.sun_d3.is_none() && !parts.lit_d1 && !radiosity.is_change(&e_change, &e_natural);
        let (photo_rgb, photo_distance_m) = (parts.photo_rgb, parts.photo_distance_m);
        if unchanged {
            if photo_distance_m.to_bits() == parts.distance_m.to_bits() {
                return (photo_rgb, false);
            }
            let l0 = true_colour_rgb(self.lighting, photo_rgb, photo_distance_m);
            return (self.apparent(l0, parts.distance_m), false);
        }
        let l0 = true_colour_rgb(self.lighting, photo_rgb, photo_distance_m);
        let rho = diffuse_reflectance_from_true_colour(l0, e_natural).unwrap_or_else(|| {
            self.materials
                .get(parts.material as usize)
                .map_or([0.5; 3], crate::scene::Material::diffuse_reflectance_rgb)
        });
        let mut e_d3 = [0.0; 3];
        if let (Some(blocked), Some(s)) = (parts.sun_d3, &daylight.sun) {
            e_d3 = mul(s.irradiance_rgb(normal), blocked);
        }
        let delta =
            diffuse_radiance_rgb(rho, add(add(parts.e_d1_rgb, e_change), scale(e_d3, -1.0)));
        self.changed_apparent(photo_rgb, l0, delta, photo_distance_m, parts.distance_m)
    }

    /// The radiance and change of a recorded sample under this light and these materials, with
    /// the radiosity light `lighting` holds (a relight of the one it was traced with, the same
    /// geometry): no ray is traced. A sample whose radiosity values cannot be read here
    /// (no radiosity light, or a point on no element) keeps its traced value.
    #[must_use]
    pub fn replay(&self, sample: &RecordedSample) -> (Rgb, bool) {
        let kept = (sample.radiance_rgb, sample.changed);
        let Some(radiosity) = self.lighting.radiosity.as_deref() else {
            return kept;
        };
        match &sample.replay {
            SampleReplay::Kept => kept,
            SampleReplay::Artificial { parts, at } => {
                let e_rad = match at {
                    Some(at) => match radiosity.with_on(at) {
                        Some(e) => Some(e),
                        None => return kept,
                    },
                    None => None,
                };
                (self.artificial_radiance(parts, e_rad), true)
            }
            SampleReplay::Natural { parts, at } => {
                match (radiosity.with_on(&at[0]), radiosity.without_on(&at[1])) {
                    (Some(with), Some(without)) => {
                        self.natural_radiance(parts, [with, without], radiosity)
                    }
                    _ => kept,
                }
            }
        }
    }
}

impl DifferentialTracer<'_> {
    /// A primary ray traced as [`Self::trace_primary`] does (the same value), with what
    /// [`Shade::replay`] needs to evaluate it again under other light and materials.
    #[must_use]
    pub fn trace_primary_recorded(
        &self,
        dir_in_world: &Vector3<f64>,
        photo_pixel_rgb: Rgb,
    ) -> RecordedSample {
        let mut replay = SampleReplay::Kept;
        let sample = self.trace_primary_with(dir_in_world, photo_pixel_rgb, Some(&mut replay));
        RecordedSample {
            radiance_rgb: sample.radiance_rgb,
            changed: sample.changed,
            hit_artificial: sample.hit_artificial,
            first_hit: sample.first_hit,
            replay,
        }
    }
}
