//! Light arriving at a hit point and the atmosphere between it and the eye, for the cases of
//! Durisch 1992 §6.2: the sun's and the artificial lights' visibility (shadow rays through
//! glass panes, [`super::glass`]), the cosine law and inverse-square irradiance of the
//! artificial lights, and the Schachter atmosphere forward (eq. 2) and inverted (eq. 8).
//!
//! # Known limitations
//! Artificial lights are points (their photometric web gives the intensity, not an extent), so
//! their shadows are hard.

use nalgebra::{Point3, Vector3};

use super::{DifferentialTracer, Lighting, SURFACE_OFFSET_M};
use crate::colour::Colour;
use crate::render::illumination::{Rgb, add, mul, scale};
use crate::scene::Material;

impl DifferentialTracer<'_> {
    /// Fraction of the sun reaching the offset point `origin` of a surface with geometric
    /// `normal` (zero from behind or without a sun); see [`Self::light_transmittance`].
    pub(super) fn sun_transmittance(&self, origin: &Point3<f64>, normal: &Vector3<f64>) -> Rgb {
        self.lighting
            .daylight
            .sun
            .as_ref()
            .filter(|s| s.dir_in_world.dot(normal) > 0.0)
            .map_or([0.0; 3], |s| {
                self.light_transmittance(origin, &s.dir_in_world, f64::INFINITY)
            })
    }

    /// The artificial lights that reach the surface point `point` (in front of the geometric
    /// `normal`; shadow ray from the offset point `origin` by any-hit against everything): unit
    /// direction towards each and its irradiance at `point` on a surface facing it, `I(−dir)/d²`
    /// (inverse-square law).
    pub(super) fn visible_artificial_lights(
        &self,
        point: &Point3<f64>,
        origin: &Point3<f64>,
        normal: &Vector3<f64>,
    ) -> Vec<(Vector3<f64>, Rgb)> {
        let mut out = Vec::new();
        for light in &self.lighting.artificial_lights {
            let to_light = light.position_in_world_m() - origin;
            let dist = to_light.norm();
            if dist <= SURFACE_OFFSET_M || to_light.dot(normal) <= 0.0 {
                continue;
            }
            let dir = to_light / dist;
            let passed = self.light_transmittance(origin, &dir, dist - SURFACE_OFFSET_M);
            if passed.iter().any(|&x| x > 0.0) {
                let to_light_from_point = light.position_in_world_m() - point;
                let dir_from_point = to_light_from_point.try_normalize(0.0).unwrap_or(dir);
                out.push((
                    dir_from_point,
                    mul(light.normal_irradiance_rgb(point), passed),
                ));
            }
        }
        out
    }

    /// Irradiance from the artificial lights `visible` on a surface of unit (shading) normal
    /// `normal` (cosine law); also says whether any light reaches the point.
    pub(super) fn artificial_light_irradiance(
        visible: &[(Vector3<f64>, Rgb)],
        normal: &Vector3<f64>,
    ) -> (Rgb, bool) {
        let mut e = [0.0; 3];
        for (dir, e_normal) in visible {
            e = add(e, scale(*e_normal, dir.dot(normal).max(0.0)));
        }
        (e, !visible.is_empty())
    }

    pub(super) fn transmission(&self, distance_m: f64) -> Rgb {
        self.shade().transmission(distance_m)
    }

    /// Eq. 2 forward: apparent colour of a true colour seen over `distance_m`.
    pub(super) fn apparent(&self, true_rgb: Rgb, distance_m: f64) -> Rgb {
        self.shade().apparent(true_rgb, distance_m)
    }

    /// Eq. 8: true colour from an apparent colour seen over `distance_m` (unchanged when there
    /// is no atmosphere or the inversion is refused).
    pub(super) fn true_colour(&self, apparent_rgb: Rgb, distance_m: f64) -> Rgb {
        true_colour_rgb(self.lighting, apparent_rgb, distance_m)
    }

    /// The light and materials this tracer shades with ([`Shade`]).
    pub(super) fn shade(&self) -> Shade<'_> {
        Shade {
            lighting: self.lighting,
            materials: self.materials,
        }
    }
}

/// The light and materials a sample is shaded under: a tracer's own ([`DifferentialTracer`]
/// shades with them), or those of a studio edit for a replay ([`super::replay`]). Needs no geometry.
#[derive(Debug, Clone, Copy)]
pub struct Shade<'a> {
    /// Lights, atmosphere and radiosity solutions.
    pub lighting: &'a Lighting,
    /// The materials, indexed by material id.
    pub materials: &'a [Material],
}

impl Shade<'_> {
    /// τ(d) of the atmosphere per channel (1 without one).
    pub(super) fn transmission(&self, distance_m: f64) -> Rgb {
        self.lighting.atmosphere.as_ref().map_or([1.0; 3], |a| {
            let t = a.transmission(distance_m);
            [0, 1, 2].map(|k| f64::from(t.channels[k]))
        })
    }

    /// Eq. 2 forward: apparent colour of a true colour seen over `distance_m`.
    pub(super) fn apparent(&self, true_rgb: Rgb, distance_m: f64) -> Rgb {
        let t = self.transmission(distance_m);
        let horizon = self.lighting.atmosphere.as_ref().map_or([0.0; 3], |a| {
            [0, 1, 2].map(|k| f64::from(a.horizon().channels[k]))
        });
        [0, 1, 2].map(|k| true_rgb[k] * t[k] + horizon[k] * (1.0 - t[k]))
    }

    /// The apparent colour after adding `delta` to the true colour `l0`: along the photo's own
    /// line of sight `L_photo + τ(d)·ΔL₀` (eq. 2 is affine), otherwise eq. 2 at `distance_m`.
    pub(super) fn changed_apparent(
        &self,
        photo_rgb: Rgb,
        l0: Rgb,
        delta: Rgb,
        photo_distance_m: f64,
        distance_m: f64,
    ) -> (Rgb, bool) {
        if photo_distance_m.to_bits() == distance_m.to_bits() {
            let t = self.transmission(distance_m);
            (add(photo_rgb, mul(t, delta)), true)
        } else {
            (self.apparent(add(l0, delta), distance_m), true)
        }
    }
}

/// Eq. 8 with the atmosphere of `lighting`: the true colour of an apparent colour seen over
/// `distance_m` (unchanged when there is no atmosphere or the inversion is refused). The
/// renderer's case D and the site's photo reflectances (`site::photo_reflectance`) use it.
#[must_use]
pub fn true_colour_rgb(lighting: &super::Lighting, apparent_rgb: Rgb, distance_m: f64) -> Rgb {
    let Some(a) = &lighting.atmosphere else {
        return apparent_rgb;
    };
    #[allow(clippy::cast_possible_truncation)]
    let c = Colour::from_slice(&apparent_rgb.map(|x| x as f32));
    a.true_colour(&c, distance_m).map_or(apparent_rgb, |t| {
        [0, 1, 2].map(|k| f64::from(t.channels[k]))
    })
}
