//! Durisch's illumination model for an opaque, diffusely reflecting surface under natural
//! daylight and artificial point lights, and its second inversion (Durisch 1992 §3.3 eqs. 3–5,
//! §3.4 eq. 6, §4.3 eq. 10).
//!
//! `L = ρ_d/π · (E_s + E_u + E_h [+ E_artificial])`                                     (eq. 6)
//!
//! - sun (eq. 3): `E_s = E_sun · max(0, n·d_s) · δ_s`, with `E_sun = k_s L̂ Ω_s` the irradiance at
//!   normal incidence and δ_s the visibility of the sun (an any-hit shadow ray, decided by the
//!   caller);
//! - ambient (eq. 4): `E_u = π · k_u L̂`, never occluded;
//! - sky (eq. 5): `E_h = Σ_i δ_i · (L_i Δω_i) · max(0, n·l_i)` over the facets of a
//!   [`crate::sky_dome::SkyDome`] (per-facet visibility δ_i by the caller).
//!
//! Durisch writes eq. 6 as `k_d ρ_dλ (…)` with ρ_dλ in sr⁻¹; here `diffuse_reflectance` is the
//! dimensionless directional-hemispherical reflectance (albedo) and the 1/π is explicit, so
//! `k_d ρ_dλ ≡ diffuse_reflectance / π`. The second inversion (eq. 10) is then
//! `ρ_d = π · L₀ / (E_s + E_u + E_h)`.
//!
//! Colours are linear RGB triples (`[f64; 3]`) in the photo's units; the light strengths share
//! those units (they come from the first inversion, §4.3, so only ratios matter).
//!
//! # Known limitations
//! Diffuse reflection only here: the specular term of Hall & Greenberg's full model is the GGX
//! lobe of [`super::specular`], mirrors and glass are recursion in [`super::differential`] and
//! [`super::glass`]. Artificial lights are points: isotropic ([`PointLight`]) or with a
//! luminaire's photometric web ([`super::luminaire_light`]), both through
//! [`inverse_square_cosine_rgb`].
//! The inversion is undefined where the natural irradiance is zero (fully shadowed with no
//! ambient term): [`diffuse_reflectance_from_true_colour`] returns `None` there.

use nalgebra::{Point3, Vector3};

/// Linear RGB.
pub type Rgb = [f64; 3];

/// A distant light: the sun or one sky facet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistantLight {
    /// Unit vector from the scene towards the light, world frame.
    pub dir_in_world: Vector3<f64>,
    /// Irradiance on a surface facing the light (`k_s L̂ Ω_s` for the sun, `L_i Δω_i` for a sky
    /// facet), per channel.
    pub normal_irradiance_rgb: Rgb,
}

impl DistantLight {
    /// Irradiance on a surface with unit normal `normal_in_world` (zero from behind).
    #[must_use]
    pub fn irradiance_rgb(&self, normal_in_world: &Vector3<f64>) -> Rgb {
        let cos = self.dir_in_world.dot(normal_in_world).max(0.0);
        self.normal_irradiance_rgb.map(|e| e * cos)
    }
}

/// An isotropic point light of the planned project (an artificial light source, case D1/C).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLight {
    /// Position, world frame, metres.
    pub position_in_world_m: Point3<f64>,
    /// Radiant (or luminous) intensity per channel, in the photo's units × m².
    pub intensity_rgb: Rgb,
}

impl PointLight {
    /// Irradiance at `point` with unit normal `normal` (inverse square and cosine law), or zero
    /// from behind.
    #[must_use]
    pub fn irradiance_rgb(&self, point_in_world_m: &Point3<f64>, normal: &Vector3<f64>) -> Rgb {
        inverse_square_cosine_rgb(
            &self.position_in_world_m,
            |_| self.intensity_rgb,
            point_in_world_m,
            normal,
        )
    }
}

/// Irradiance at `point_in_world_m` (unit `normal`) from a point source at `light_in_world_m`
/// whose intensity towards a unit direction (from the light) is `intensity_toward_rgb`:
/// `E = I(dir)·cos θ / d²`, zero from behind or at the source itself.
#[must_use]
pub fn inverse_square_cosine_rgb(
    light_in_world_m: &Point3<f64>,
    intensity_toward_rgb: impl Fn(&Vector3<f64>) -> Rgb,
    point_in_world_m: &Point3<f64>,
    normal: &Vector3<f64>,
) -> Rgb {
    let to_light = light_in_world_m - point_in_world_m;
    let r2 = to_light.norm_squared();
    if r2 <= 0.0 {
        return [0.0; 3];
    }
    let r = r2.sqrt();
    let cos = (to_light.dot(normal) / r).max(0.0);
    if cos <= 0.0 {
        return [0.0; 3];
    }
    intensity_toward_rgb(&(-to_light / r)).map(|i| i * cos / r2)
}

/// Natural daylight: sun, ambient and sky facets (Durisch §3.3).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Daylight {
    /// Direct sunlight, if the sun is up.
    pub sun: Option<DistantLight>,
    /// Ambient radiance `k_u L̂` per channel (eq. 4): irradiance π·k_u on any surface.
    pub ambient_radiance_rgb: Rgb,
    /// Sky facets as distant lights (eq. 5).
    pub sky: Vec<DistantLight>,
}

impl Daylight {
    /// The ambient irradiance `E_u = π k_u L̂` (eq. 4).
    #[must_use]
    pub fn ambient_irradiance_rgb(&self) -> Rgb {
        self.ambient_radiance_rgb.map(|k| std::f64::consts::PI * k)
    }

    /// Sky facets of a uniform sky of radiance `radiance_rgb` on the facets of `dome`.
    #[must_use]
    pub fn uniform_sky_lights(
        dome: &crate::sky_dome::SkyDome,
        radiance_rgb: Rgb,
    ) -> Vec<DistantLight> {
        dome.facets
            .iter()
            .map(|f| DistantLight {
                dir_in_world: f.centre_dir_in_world,
                normal_irradiance_rgb: radiance_rgb.map(|l| l * f.solid_angle_sr),
            })
            .collect()
    }

    /// Sky facets from [`crate::sky_dome::SkySource`]s (photometric, achromatic) tinted by
    /// `colour_rgb`.
    #[must_use]
    pub fn sky_lights_from_sources(
        sources: &[crate::sky_dome::SkySource],
        colour_rgb: Rgb,
    ) -> Vec<DistantLight> {
        sources
            .iter()
            .map(|s| DistantLight {
                dir_in_world: s.dir_in_world,
                normal_irradiance_rgb: colour_rgb.map(|c| c * s.integrated_luminance),
            })
            .collect()
    }
}

/// Adds `b` to `a` channel-wise.
#[must_use]
pub fn add(a: Rgb, b: Rgb) -> Rgb {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Scales `a` by `s`.
#[must_use]
pub fn scale(a: Rgb, s: f64) -> Rgb {
    a.map(|x| x * s)
}

/// Channel-wise product.
#[must_use]
pub fn mul(a: Rgb, b: Rgb) -> Rgb {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

/// Total natural irradiance at a point with unit normal `normal_in_world`: ambient, plus the
/// sun when `sun_visible`, plus each sky facet `i` for which `sky_visible(i)` (eqs. 3–5).
#[must_use]
pub fn natural_irradiance_rgb(
    daylight: &Daylight,
    normal_in_world: &Vector3<f64>,
    sun_visible: bool,
    mut sky_visible: impl FnMut(usize) -> bool,
) -> Rgb {
    let weight = |visible: bool| if visible { [1.0; 3] } else { [0.0; 3] };
    natural_irradiance_weighted_rgb(daylight, normal_in_world, weight(sun_visible), |i| {
        weight(sky_visible(i))
    })
}

/// [`natural_irradiance_rgb`] with a fraction per channel of each light reaching the point
/// (0 blocked, 1 unobstructed, between when it passes glass panes): the sun's `sun_rgb`, sky
/// facet `i`'s `sky_rgb(i)` (asked only for facets above the surface). Lights with a zero
/// fraction are skipped and a fraction of 1 multiplies exactly, so with 0/1 fractions the sum
/// is bit for bit the unweighted one.
#[must_use]
pub fn natural_irradiance_weighted_rgb(
    daylight: &Daylight,
    normal_in_world: &Vector3<f64>,
    sun_rgb: Rgb,
    mut sky_rgb: impl FnMut(usize) -> Rgb,
) -> Rgb {
    let reaches = |w: &Rgb| w.iter().any(|&x| x > 0.0);
    let mut e = daylight.ambient_irradiance_rgb();
    if let Some(sun) = &daylight.sun
        && reaches(&sun_rgb)
    {
        e = add(e, mul(sun.irradiance_rgb(normal_in_world), sun_rgb));
    }
    for (i, facet) in daylight.sky.iter().enumerate() {
        if facet.dir_in_world.dot(normal_in_world) > 0.0 {
            let w = sky_rgb(i);
            if reaches(&w) {
                e = add(e, mul(facet.irradiance_rgb(normal_in_world), w));
            }
        }
    }
    e
}

/// Eq. 6: reflected radiance `ρ_d/π · E` of a diffuse surface (ρ_d the albedo per channel).
/// A negative `irradiance_rgb` (case D3) gives a negative radiance change.
#[must_use]
pub fn diffuse_radiance_rgb(diffuse_reflectance: Rgb, irradiance_rgb: Rgb) -> Rgb {
    let k = std::f64::consts::FRAC_1_PI;
    [
        diffuse_reflectance[0] * k * irradiance_rgb[0],
        diffuse_reflectance[1] * k * irradiance_rgb[1],
        diffuse_reflectance[2] * k * irradiance_rgb[2],
    ]
}

/// Eq. 10, the second inversion: the albedo `ρ_d = π·L₀/E` per channel from the true colour `L₀`
/// and the natural irradiance `E` at the point. `None` when a channel of `E` is not positive
/// (nothing to divide by: the point receives no natural light in that channel).
#[must_use]
pub fn diffuse_reflectance_from_true_colour(
    true_colour_rgb: Rgb,
    irradiance_rgb: Rgb,
) -> Option<Rgb> {
    if irradiance_rgb.iter().any(|&e| !(e > 0.0 && e.is_finite())) {
        return None;
    }
    Some([0, 1, 2].map(|k| std::f64::consts::PI * true_colour_rgb[k] / irradiance_rgb[k]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky_dome::durisch_facets::durisch_dome;

    /// Pure floating-point round-off of a handful of products and sums.
    const ROUND_OFF_TOL: f64 = 1e-12;
    /// The facet sum of eq. 5 for m_h = 16 against the exact π·L of a uniform sky on a horizontal
    /// plane: the midpoint rule's error on cos θ over 16 polar bands is ~ (Δθ)²/24 ≈ 4e-4.
    const FACET_SUM_TOL: f64 = 1e-3;

    #[test]
    fn sun_only_is_rho_over_pi_e_cos() {
        let theta = 0.6_f64;
        let daylight = Daylight {
            sun: Some(DistantLight {
                dir_in_world: Vector3::new(theta.sin(), 0.0, theta.cos()),
                normal_irradiance_rgb: [3.0, 2.85, 2.6],
            }),
            ..Daylight::default()
        };
        let rho = [0.2, 0.5, 0.8];
        let e = natural_irradiance_rgb(&daylight, &Vector3::z(), true, |_| true);
        let l = diffuse_radiance_rgb(rho, e);
        for k in 0..3 {
            let expected = rho[k] / std::f64::consts::PI * [3.0, 2.85, 2.6][k] * theta.cos();
            assert!((l[k] - expected).abs() < ROUND_OFF_TOL);
        }
        let shadowed = natural_irradiance_rgb(&daylight, &Vector3::z(), false, |_| true);
        assert_eq!(shadowed.map(f64::to_bits), [0.0_f64.to_bits(); 3]);
    }

    #[test]
    fn ambient_only_is_rho_k_u() {
        let daylight = Daylight {
            ambient_radiance_rgb: [0.14, 0.13, 0.53],
            ..Daylight::default()
        };
        let rho = [0.3, 0.6, 0.9];
        let l = diffuse_radiance_rgb(
            rho,
            natural_irradiance_rgb(&daylight, &Vector3::x(), true, |_| true),
        );
        for k in 0..3 {
            assert!((l[k] - rho[k] * daylight.ambient_radiance_rgb[k]).abs() < ROUND_OFF_TOL);
        }
    }

    #[test]
    fn uniform_sky_facets_integrate_to_pi_l() {
        let dome = durisch_dome(16).unwrap();
        let sky = Daylight {
            sky: Daylight::uniform_sky_lights(&dome, [0.25, 0.32, 0.45]),
            ..Daylight::default()
        };
        let e = natural_irradiance_rgb(&sky, &Vector3::z(), false, |_| true);
        for (k, l) in [0.25, 0.32, 0.45].iter().enumerate() {
            let exact = std::f64::consts::PI * l;
            assert!((e[k] - exact).abs() / exact < FACET_SUM_TOL, "{e:?}");
        }
    }

    #[test]
    fn second_inversion_recovers_the_albedo() {
        let e = [1.7, 2.1, 0.9];
        let rho = [0.25, 0.5, 0.75];
        let l0 = diffuse_radiance_rgb(rho, e);
        let back = diffuse_reflectance_from_true_colour(l0, e).unwrap();
        for k in 0..3 {
            assert!((back[k] - rho[k]).abs() < ROUND_OFF_TOL);
        }
        assert!(diffuse_reflectance_from_true_colour(l0, [1.0, 0.0, 1.0]).is_none());
    }

    #[test]
    fn point_light_follows_inverse_square_and_cosine() {
        let light = PointLight {
            position_in_world_m: Point3::new(0.0, 3.0, 4.0),
            intensity_rgb: [25.0, 50.0, 0.0],
        };
        let e = light.irradiance_rgb(&Point3::origin(), &Vector3::z());
        // r = 5, cos θ = 4/5.
        assert!((e[0] - 25.0 * 0.8 / 25.0).abs() < ROUND_OFF_TOL);
        assert!((e[1] - 50.0 * 0.8 / 25.0).abs() < ROUND_OFF_TOL);
        assert_eq!(
            light
                .irradiance_rgb(&Point3::origin(), &-Vector3::z())
                .map(f64::to_bits),
            [0.0_f64.to_bits(); 3]
        );
    }
}
