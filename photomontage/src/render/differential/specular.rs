//! The microfacet specular lobe of artificial surfaces: GGX / Trowbridge–Reitz normal
//! distribution with the separable Smith shadowing–masking term and Schlick's Fresnel
//! (Walter, Marschner, Li & Torrance 2007, eqs. 20, 33–34; Schlick 1994), the lobe Durisch
//! 1992 §3.4 leaves as the specular term of Hall & Greenberg's model.
//!
//! `f_s(l, v) = D(h) F(v·h) G₁(v) G₁(l) / (4 (n·v)(n·l))`, α = roughness² (Burley 2012).
//!
//! In case C the lobe is lit by
//! - the **sun** and the **artificial lights** (delta lights, evaluated analytically:
//!   `L = f_s · E_normal · (n·l)`; at the mirror configuration `v = l = n` this is
//!   `F0 / (4πα²) · E`), and
//! - the **surroundings** (sky, photographed natural surfaces, other artificial objects) by
//!   importance-sampled secondary rays: half vectors drawn with density `D(h)(n·h)`, the
//!   reflected direction traced with [`DifferentialTracer::trace_secondary`] and weighted by
//!   `F G₁(v) G₁(l) (v·h) / ((n·v)(n·h))` (the BRDF·cos / pdf ratio). The sample points are a
//!   fixed 2-D Fibonacci lattice rotated (Cranley–Patterson) by a hash of the hit point, so the
//!   render stays deterministic for any thread count and successive primary rays of a pixel see
//!   different rotations.
//!
//! # Known limitations
//! The diffuse layer is not reduced by the energy the specular lobe takes (no (1 − F) coupling);
//! the Smith term is the separable, not the height-correlated form; [`GLOSSY_RAYS_PRIMARY`] rays
//! on a primary hit and one ray on deeper hits (noise is averaged by the pixel's adaptive rays);
//! the sky facets are not evaluated analytically in the lobe (the sky reaches it through the
//! secondary rays, as case B's horizon colour). The lobe does not take part in the photo bounce
//! (light the building reflects onto natural surfaces is diffuse only).

use nalgebra::{Point3, Vector3};

use super::DifferentialTracer;
use crate::render::illumination::{DistantLight, Rgb, add, scale};
use crate::scene::material::Specular;

/// Glossy secondary rays traced per primary hit of a specular surface.
pub const GLOSSY_RAYS_PRIMARY: usize = 8;

/// A point of a surface about to be shaded.
#[derive(Debug, Clone, Copy)]
pub struct SurfaceFrame<'a> {
    /// Where secondary and shadow rays start (offset off the surface), world frame.
    pub origin: &'a Point3<f64>,
    /// Geometric unit normal facing the incoming ray.
    pub normal: &'a Vector3<f64>,
    /// Shading unit normal (the geometric one, or perturbed by water waves).
    pub shading_normal: &'a Vector3<f64>,
}

/// Mirror reflection of `dir` about `shading_normal`, or about the geometric `normal` when the
/// former would point into the surface.
#[must_use]
pub fn reflect_above(
    dir: &Vector3<f64>,
    shading_normal: &Vector3<f64>,
    normal: &Vector3<f64>,
) -> Vector3<f64> {
    let r = dir - shading_normal * (2.0 * dir.dot(shading_normal));
    if r.dot(normal) > 0.0 {
        r
    } else {
        dir - normal * (2.0 * dir.dot(normal))
    }
}

/// GGX α from the material's perceptual roughness.
#[must_use]
pub fn ggx_alpha(spec: &Specular) -> f64 {
    spec.roughness * spec.roughness
}

/// Smith's masking term for GGX, `G₁ = 2 cos / (cos + √(α² + (1−α²) cos²))`; 0 from behind.
#[must_use]
pub fn smith_g1(alpha: f64, cos_theta: f64) -> f64 {
    if cos_theta <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    2.0 * cos_theta / (cos_theta + (a2 + (1.0 - a2) * cos_theta * cos_theta).sqrt())
}

/// The GGX BRDF value `D F G / (4 (n·v)(n·l))` (sr⁻¹) for unit normal `n`, view direction `v`
/// and light direction `l` (both pointing away from the surface).
#[must_use]
pub fn ggx_brdf(spec: &Specular, n: &Vector3<f64>, v: &Vector3<f64>, l: &Vector3<f64>) -> f64 {
    let (cos_v, cos_l) = (n.dot(v), n.dot(l));
    if cos_v <= 0.0 || cos_l <= 0.0 {
        return 0.0;
    }
    let Some(h) = (v + l).try_normalize(1e-12) else {
        return 0.0;
    };
    let alpha = ggx_alpha(spec);
    spec.ggx_distribution(n.dot(&h))
        * spec.fresnel_schlick(v.dot(&h))
        * smith_g1(alpha, cos_v)
        * smith_g1(alpha, cos_l)
        / (4.0 * cos_v * cos_l)
}

/// An orthonormal basis `(t, b)` completing the unit vector `n` (Duff et al. 2017).
#[must_use]
pub fn tangent_frame(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let sign = 1.0_f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vector3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vector3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// A half vector about `n` drawn with density `D(h)(n·h)` from the unit square point `u`
/// (`tan²θ_h = α² u₀/(1−u₀)`, `φ = 2π u₁`).
#[must_use]
pub fn sample_ggx_half_vector(alpha: f64, u: [f64; 2], n: &Vector3<f64>) -> Vector3<f64> {
    let u0 = u[0].clamp(0.0, 1.0 - 1e-12);
    let tan2 = alpha * alpha * u0 / (1.0 - u0);
    let cos = 1.0 / (1.0 + tan2).sqrt();
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = 2.0 * std::f64::consts::PI * u[1];
    let (t, b) = tangent_frame(n);
    (t * (sin * phi.cos()) + b * (sin * phi.sin()) + n * cos).normalize()
}

/// BRDF·cos / pdf of the reflected direction `l = 2(v·h)h − v` when `h` was drawn by
/// [`sample_ggx_half_vector`]: `F G₁(v) G₁(l) (v·h) / ((n·v)(n·h))`; 0 below the surface.
#[must_use]
pub fn sampled_reflection_weight(
    spec: &Specular,
    n: &Vector3<f64>,
    v: &Vector3<f64>,
    l: &Vector3<f64>,
    h: &Vector3<f64>,
) -> f64 {
    let (cos_v, cos_l, cos_h, v_h) = (n.dot(v), n.dot(l), n.dot(h), v.dot(h));
    if cos_v <= 0.0 || cos_l <= 0.0 || cos_h <= 0.0 || v_h <= 0.0 {
        return 0.0;
    }
    let alpha = ggx_alpha(spec);
    spec.fresnel_schlick(v_h) * smith_g1(alpha, cos_v) * smith_g1(alpha, cos_l) * v_h
        / (cos_v * cos_h)
}

/// Point `i` of `count` of the 2-D Fibonacci lattice, rotated by `shift` modulo 1.
#[must_use]
pub fn fibonacci_point(i: usize, count: usize, shift: [f64; 2]) -> [f64; 2] {
    const INV_GOLDEN: f64 = 0.618_033_988_749_894_8;
    #[allow(clippy::cast_precision_loss)]
    let (fi, fc) = (i as f64, count.max(1) as f64);
    [
        ((fi + 0.5) / fc + shift[0]).fract(),
        (fi * INV_GOLDEN + shift[1]).fract(),
    ]
}

/// Two numbers in [0, 1) from a hash (SplitMix64) of a point and a direction.
fn hash_shift(point: &Point3<f64>, dir: &Vector3<f64>) -> [f64; 2] {
    let mut x = 0x9E37_79B9_7F4A_7C15_u64;
    for v in [point.x, point.y, point.z, dir.x, dir.y, dir.z] {
        x ^= v.to_bits();
        x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
        x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        x ^= x >> 31;
    }
    #[allow(clippy::cast_precision_loss)]
    let unit = |bits: u64| (bits >> 11) as f64 / (1u64 << 53) as f64;
    [unit(x), unit(x.rotate_left(32))]
}

impl DifferentialTracer<'_> {
    /// Radiance of the specular lobe towards `-dir_in_world` at a surface point (true colour):
    /// the visible sun and artificial lights (`lights` as from `visible_artificial_lights`)
    /// analytically, the surroundings by glossy secondary rays below the depth limit.
    pub(super) fn specular_radiance(
        &self,
        spec: &Specular,
        frame: &SurfaceFrame<'_>,
        dir_in_world: &Vector3<f64>,
        sun: Option<&DistantLight>,
        lights: &[(Vector3<f64>, Rgb)],
        depth: u32,
    ) -> Rgb {
        let n = frame.shading_normal;
        let v = -dir_in_world.normalize();
        let mut l_out = [0.0; 3];
        let mut delta_light = |l: &Vector3<f64>, e_normal: Rgb| {
            let cos_l = n.dot(l);
            if cos_l > 0.0 {
                l_out = add(l_out, scale(e_normal, ggx_brdf(spec, n, &v, l) * cos_l));
            }
        };
        if let Some(s) = sun {
            delta_light(&s.dir_in_world, s.normal_irradiance_rgb);
        }
        for (l, e_normal) in lights {
            delta_light(l, *e_normal);
        }
        if depth < self.max_depth() {
            let count = if depth == 0 { GLOSSY_RAYS_PRIMARY } else { 1 };
            let shift = hash_shift(frame.origin, dir_in_world);
            let alpha = ggx_alpha(spec);
            #[allow(clippy::cast_precision_loss)]
            let per_ray = 1.0 / count as f64;
            for i in 0..count {
                let h = sample_ggx_half_vector(alpha, fibonacci_point(i, count, shift), n);
                let l = h * (2.0 * v.dot(&h)) - v;
                if l.dot(frame.normal) <= 0.0 {
                    continue;
                }
                let w = sampled_reflection_weight(spec, n, &v, &l, &h);
                if w > 0.0 {
                    let incoming = self.trace_secondary(frame.origin, &l, depth + 1);
                    l_out = add(l_out, scale(incoming, w * per_ray));
                }
            }
        }
        l_out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Pure round-off of a few products.
    const ROUND_OFF_TOL: f64 = 1e-13;
    /// 400 × 400 midpoint quadrature of a smooth lobe (roughness ≥ 0.3): error ≪ 1e-3.
    const QUADRATURE_TOL: f64 = 2e-3;
    /// 65 536 stratified (Fibonacci) samples of a bounded weight: error ≪ 1e-3.
    const SAMPLED_TOL: f64 = 2e-3;

    fn spec(roughness: f64, f0: f64) -> Specular {
        Specular { roughness, f0 }
    }

    #[test]
    fn highlight_at_the_mirror_direction_is_f0_over_4_pi_alpha2() {
        // v = l = n: h = n, D = 1/(πα²), G₁ = 1, F = F0.
        let n = Vector3::z();
        for (roughness, f0) in [(0.5, 0.04), (0.3, 0.9), (1.0, 0.5)] {
            let s = spec(roughness, f0);
            let alpha: f64 = roughness * roughness;
            let expected = f0 / (4.0 * PI * alpha * alpha);
            let got = ggx_brdf(&s, &n, &n, &n);
            assert!(
                (got - expected).abs() < ROUND_OFF_TOL * expected,
                "{got} {expected}"
            );
        }
        // Behind the surface: nothing.
        assert!(ggx_brdf(&spec(0.5, 0.04), &n, &n, &-n).abs() < 1e-300);
    }

    /// ∫ f_s cos_l dω_l by midpoint quadrature over (θ, φ).
    fn albedo_by_quadrature(s: &Specular, v: &Vector3<f64>) -> f64 {
        let (nt, np) = (400, 400);
        let mut sum = 0.0;
        for i in 0..nt {
            let theta = (f64::from(i) + 0.5) / f64::from(nt) * PI / 2.0;
            for j in 0..np {
                let phi = (f64::from(j) + 0.5) / f64::from(np) * 2.0 * PI;
                let l = Vector3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                sum += ggx_brdf(s, &Vector3::z(), v, &l) * theta.cos() * theta.sin();
            }
        }
        sum * (PI / 2.0 / f64::from(nt)) * (2.0 * PI / f64::from(np))
    }

    fn albedo_by_sampling(s: &Specular, v: &Vector3<f64>) -> f64 {
        let n = Vector3::z();
        let count = 65_536;
        let mut sum = 0.0;
        for i in 0..count {
            let h = sample_ggx_half_vector(ggx_alpha(s), fibonacci_point(i, count, [0.0; 2]), &n);
            let l = h * (2.0 * v.dot(&h)) - v;
            sum += sampled_reflection_weight(s, &n, v, &l, &h);
        }
        sum / 65_536.0
    }

    #[test]
    fn white_furnace_importance_sampling_matches_the_integral_and_loses_no_energy_when_smooth() {
        // F0 = 1 makes F ≡ 1: the directional albedo is then the energy the Smith term keeps,
        // ≤ 1, and → 1 as the surface gets smooth (a white furnace).
        let v = Vector3::new(45f64.to_radians().sin(), 0.0, 45f64.to_radians().cos());
        let mut previous = 1.0 + QUADRATURE_TOL;
        for roughness in [0.3, 0.6, 1.0] {
            let s = spec(roughness, 1.0);
            let q = albedo_by_quadrature(&s, &v);
            let m = albedo_by_sampling(&s, &v);
            assert!(
                (q - m).abs() < QUADRATURE_TOL + SAMPLED_TOL,
                "r {roughness}: {q} {m}"
            );
            // Single scattering loses more energy the rougher the surface (Kulla & Conty 2017).
            assert!(q < previous && q > 0.0, "r {roughness}: {q}");
            previous = q;
        }
        let smooth = albedo_by_sampling(&spec(0.1, 1.0), &v);
        assert!((smooth - 1.0).abs() < 5e-3, "{smooth}");
    }

    #[test]
    fn reflect_above_stays_above_the_geometric_surface() {
        let n = Vector3::z();
        let d = Vector3::new(1.0, 0.0, -1.0).normalize();
        let r = reflect_above(&d, &n, &n);
        assert!((r - Vector3::new(1.0, 0.0, 1.0).normalize()).norm() < ROUND_OFF_TOL);
        // A shading normal tilted so far that the reflection would go below: geometric mirror.
        let tilted = Vector3::new(1.0, 0.0, 0.2).normalize();
        let r = reflect_above(&d, &tilted, &n);
        assert!(r.z > 0.0);
        let (t, b) = tangent_frame(&tilted);
        assert!(t.dot(&b).abs() < ROUND_OFF_TOL && t.dot(&tilted).abs() < ROUND_OFF_TOL);
        assert!((t.norm() - 1.0).abs() < ROUND_OFF_TOL && (b.norm() - 1.0).abs() < ROUND_OFF_TOL);
    }
}
