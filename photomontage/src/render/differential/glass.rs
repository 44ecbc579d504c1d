//! Glass in the differential tracer: a thin pane (window) that reflects and transmits with
//! exact dielectric Fresnel weights and internal absorption, summed over the multiple
//! reflections inside the slab (Durisch 1992 §6.2 case C: "reflection and refraction …
//! recursively"; the slab sums are the classical thin-plate results, e.g. Born & Wolf, or
//! pbrt-v4 §9.5 for the interface, and the Fresnel equations for unpolarised light).
//!
//! For a pane of index n at incidence θ, with single-interface reflectance `R(θ)` (exact
//! Fresnel, [`crate::scene::material::Glass::fresnel_reflectance`]) and internal transmittance
//! `τ_θ = τ^(1/cos θ_t)` along the refracted path (τ the material's per-channel transmittance at
//! normal incidence, Beer–Lambert), the pane reflects and transmits
//!
//! `R_pane = R + τ_θ² R (1−R)² / (1 − τ_θ² R²)`,   `T_pane = τ_θ (1−R)² / (1 − τ_θ² R²)`.
//!
//! For a clear pane (τ = 1) `R_pane + T_pane = 1` exactly. A thin pane does not deviate the ray
//! (the parallel offset, ~ thickness, is below any pixel), so the transmitted ray continues along
//! the incident direction: on the camera's line of sight it sees what the photo shows at that
//! pixel (case A or D with the photo's own value), elsewhere it is a secondary ray (cases B, C, D
//! through [`super::DifferentialTracer::trace_secondary`]), so windows show the photographed
//! surroundings.
//!
//! **Shadow rays through panes.** A ray towards a light (sun, sky facet, luminaire) that meets
//! only panes among the artificial objects carries `Π T_pane(θ_j)` per channel, θ_j its
//! incidence on pane j: light through a window is attenuated and tinted, not blocked. So case C
//! weights each natural light by that fraction and case D3 removes `(1 − Π T_pane)·E` instead
//! of all of `E` ([`DifferentialTracer::artificial_transmittance`]); panes and the other
//! artificial triangles sit in separate BVHs so an opaque blocker is found by one any-hit.
//!
//! # Known limitations
//! Only thin panes: a solid glass body (refraction on entry and exit, total internal reflection)
//! is not modelled. Shadow rays pass panes straight (the thin pane's parallel offset is
//! ignored), so caustics are not rendered; the light a pane reflects onto its surroundings is not
//! added; more than [`MAX_SHADOW_PANES`] panes count as blocking. The one-bounce gathers see a
//! pane as the surface it is (its shading), not what lies behind it. Recursion stops at the
//! depth limit (`max_depth`): with depth 0 a pane shows only its diffuse and specular layers.

use nalgebra::{Point3, Vector3};

use super::specular::reflect_above;
use super::{DifferentialTracer, SURFACE_OFFSET_M};
use crate::render::illumination::{Rgb, add, mul};
use crate::scene::ObjectKind;
use crate::scene::material::Glass;

/// Reflectance and transmittance of a thin pane per RGB channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaneWeights {
    /// Fraction of the incident radiance reflected (both faces and inner bounces).
    pub reflectance_rgb: Rgb,
    /// Fraction transmitted straight through.
    pub transmittance_rgb: Rgb,
}

/// The reflectance and transmittance of a thin pane of `glass` at incidence cosine
/// `cos_incidence` (see the module doc for the slab sums).
#[must_use]
pub fn thin_pane(glass: &Glass, cos_incidence: f64) -> PaneWeights {
    let cos_i = cos_incidence.clamp(0.0, 1.0);
    let r = glass.fresnel_reflectance(cos_i);
    if r >= 1.0 || !r.is_finite() {
        return PaneWeights {
            reflectance_rgb: [1.0; 3],
            transmittance_rgb: [0.0; 3],
        };
    }
    let sin_t2 = (1.0 - cos_i * cos_i) / (glass.ior * glass.ior);
    let cos_t = (1.0 - sin_t2).max(0.0).sqrt();
    let mut out = PaneWeights {
        reflectance_rgb: [0.0; 3],
        transmittance_rgb: [0.0; 3],
    };
    for k in 0..3 {
        let tau = if cos_t > 0.0 {
            glass.transmittance_rgb[k].clamp(0.0, 1.0).powf(1.0 / cos_t)
        } else {
            0.0
        };
        let one_minus_r2 = (1.0 - r) * (1.0 - r);
        let denom = 1.0 - tau * tau * r * r;
        out.transmittance_rgb[k] = tau * one_minus_r2 / denom;
        out.reflectance_rgb[k] = r + tau * tau * r * one_minus_r2 / denom;
    }
    out
}

/// What a ray still on the camera's line of sight (straight through thin panes) would see
/// behind the artificial objects: the photo's value at its pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhotoBehind {
    /// The photo's value (box-reconstructed) at the pixel sample.
    pub photo_rgb: Rgb,
    /// Distance from the camera to the origin of the current ray segment, metres.
    pub camera_distance_m: f64,
}

impl PhotoBehind {
    /// At the camera (a primary ray).
    #[must_use]
    pub fn at_camera(photo_rgb: Rgb) -> Self {
        Self {
            photo_rgb,
            camera_distance_m: 0.0,
        }
    }
}

/// Most panes a shadow ray passes before it counts as blocked: a façade of double glazing seen
/// through another is 4 panes; at 16 even clear glass (T ≈ 0.92 each) has let through < 30 %
/// and such a stack is not a window but a glass block.
pub const MAX_SHADOW_PANES: usize = 16;

impl DifferentialTracer<'_> {
    /// Fraction of light per channel that passes the artificial objects along
    /// `origin + t·dir`, `t ∈ (0, t_max]`: 1 when none is in the way (bit for bit), 0 when an
    /// opaque one is, otherwise the product of the thin-pane transmittances of the panes crossed
    /// (see the module doc).
    pub(super) fn artificial_transmittance(
        &self,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
        t_max: f64,
    ) -> Rgb {
        const CLEAR: Rgb = [1.0; 3];
        const BLOCKED: Rgb = [0.0; 3];
        if !self.may_hit_artificial(origin, dir, t_max) {
            return CLEAR;
        }
        let Some(split) = &self.artificial_split else {
            return if Self::blocked_by(self.artificial_tracer(), origin, dir, t_max) {
                BLOCKED
            } else {
                CLEAR
            };
        };
        if split
            .opaque
            .as_ref()
            .is_some_and(|o| Self::blocked_by(o, origin, dir, t_max))
        {
            return BLOCKED;
        }
        let unit = dir.normalize();
        #[allow(clippy::cast_possible_truncation)]
        let t_max_f32 = t_max as f32;
        #[allow(clippy::cast_possible_truncation)]
        let step = SURFACE_OFFSET_M as f32;
        let mut passed = CLEAR;
        let mut t_min = 0.0_f32;
        for _ in 0..MAX_SHADOW_PANES {
            let ray = split.glass.ray_from_world(origin, &unit, t_min, t_max_f32);
            let Some(hit) = split.glass.closest_hit(&ray) else {
                return passed;
            };
            let Some(glass) = self.material_of(&hit).and_then(|m| m.glass.as_ref()) else {
                return BLOCKED;
            };
            let [nx, ny, nz] = hit.hit.normal_geometric.map(f64::from);
            let cos = (unit.x * nx + unit.y * ny + unit.z * nz).abs();
            passed = mul(passed, thin_pane(glass, cos).transmittance_rgb);
            if passed.iter().all(|&x| x <= 0.0) {
                return BLOCKED;
            }
            // Past this pane (its two faces are one triangle: a thin pane).
            t_min = hit.hit.t + step;
        }
        BLOCKED
    }

    /// Fraction of light per channel from a light in direction `dir` (up to `t_max`) that
    /// reaches `origin`: 0 when natural geometry blocks it, else
    /// [`Self::artificial_transmittance`]. Without panes this is one any-hit against all
    /// geometry, 0 or 1.
    pub(super) fn light_transmittance(
        &self,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
        t_max: f64,
    ) -> Rgb {
        if self.artificial_split.is_none() {
            return if Self::blocked_by(self.all_tracer(), origin, dir, t_max) {
                [0.0; 3]
            } else {
                [1.0; 3]
            };
        }
        if self.natural_blocks(origin, dir, t_max) {
            return [0.0; 3];
        }
        self.artificial_transmittance(origin, dir, t_max)
    }

    /// Radiance that a glass pane at `point` adds towards `-dir_in_world` (true colour at the
    /// pane): the Fresnel-weighted reflection and the transmitted light from behind.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn glass_radiance(
        &self,
        glass: &Glass,
        point: &Point3<f64>,
        normal: &Vector3<f64>,
        shading_normal: &Vector3<f64>,
        dir_in_world: &Vector3<f64>,
        depth: u32,
        behind: Option<PhotoBehind>,
    ) -> Rgb {
        let cos_i = -dir_in_world.dot(shading_normal);
        let w = thin_pane(glass, cos_i);
        let mut l = [0.0; 3];
        if w.reflectance_rgb.iter().any(|&r| r > 0.0) {
            let front = point + normal * SURFACE_OFFSET_M;
            let reflected = reflect_above(dir_in_world, shading_normal, normal);
            l = add(
                l,
                mul(
                    w.reflectance_rgb,
                    self.trace_secondary(&front, &reflected, depth + 1),
                ),
            );
        }
        if w.transmittance_rgb.iter().any(|&t| t > 0.0) {
            let back = point - normal * SURFACE_OFFSET_M;
            let dir = dir_in_world.normalize();
            let through = match behind {
                Some(b) => self.through_pane_on_line_of_sight(&back, &dir, b, depth + 1),
                None => self.trace_secondary(&back, &dir, depth + 1),
            };
            l = add(l, mul(w.transmittance_rgb, through));
        }
        l
    }

    /// A transmitted ray still on the camera's line of sight: a miss shows the photo's pixel
    /// (case A), a natural hit its photographed colour with the changes of case D, an artificial
    /// hit case C (with the photo still behind it).
    fn through_pane_on_line_of_sight(
        &self,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
        behind: PhotoBehind,
        depth: u32,
    ) -> Rgb {
        let Some((hit, point, t)) = self.closest_hit_from(origin, dir) else {
            return behind.photo_rgb;
        };
        match hit.kind {
            ObjectKind::Artificial => {
                self.case_c_shade(&hit, &point, dir, t, depth, Some(behind), None)
            }
            ObjectKind::Natural => {
                self.case_d_natural_hit(
                    &hit,
                    &point,
                    dir,
                    behind.photo_rgb,
                    behind.camera_distance_m + t,
                    t,
                )
                .0
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A handful of products and one division: pure round-off.
    const ROUND_OFF_TOL: f64 = 1e-14;

    fn glass(ior: f64, t: [f64; 3]) -> Glass {
        Glass {
            ior,
            transmittance_rgb: t,
        }
    }

    #[test]
    fn clear_pane_at_normal_incidence_is_the_thin_slab_closed_form() {
        // n = 1.5: R = ((n−1)/(n+1))² = 0.04; the slab transmits (1−R)²/(1−R²) = (1−R)/(1+R).
        let w = thin_pane(&glass(1.5, [1.0; 3]), 1.0);
        for k in 0..3 {
            assert!((w.transmittance_rgb[k] - 0.96 / 1.04).abs() < ROUND_OFF_TOL);
            assert!((w.reflectance_rgb[k] - 2.0 * 0.04 / 1.04).abs() < ROUND_OFF_TOL);
        }
    }

    #[test]
    fn clear_pane_conserves_energy_at_every_angle() {
        for ior in [1.0, 1.33, 1.52, 2.4] {
            for k in 0..=50 {
                let cos = f64::from(k) / 50.0;
                let w = thin_pane(&glass(ior, [1.0; 3]), cos);
                for c in 0..3 {
                    let sum = w.reflectance_rgb[c] + w.transmittance_rgb[c];
                    assert!((sum - 1.0).abs() < 1e-12, "ior {ior} cos {cos}: {sum}");
                }
            }
        }
        // Index 1 is no interface at all: everything passes.
        let w = thin_pane(&glass(1.0, [1.0; 3]), 0.3);
        assert!(w.transmittance_rgb.iter().all(|t| (t - 1.0).abs() < 1e-15));
    }

    #[test]
    fn absorbing_pane_matches_the_closed_form_and_absorbs_the_rest() {
        let tau = [0.9, 0.8, 0.5];
        let w = thin_pane(&glass(1.5, tau), 1.0);
        for k in 0..3 {
            let t = tau[k] * 0.96 * 0.96 / (1.0 - tau[k] * tau[k] * 0.0016);
            let r = 0.04 + tau[k] * tau[k] * 0.04 * 0.96 * 0.96 / (1.0 - tau[k] * tau[k] * 0.0016);
            assert!((w.transmittance_rgb[k] - t).abs() < ROUND_OFF_TOL);
            assert!((w.reflectance_rgb[k] - r).abs() < ROUND_OFF_TOL);
            assert!(w.reflectance_rgb[k] + w.transmittance_rgb[k] < 1.0);
        }
        // 60° in n = 1.5: sin θt = sin 60°/1.5, the path is 1/cos θt times longer.
        let g = glass(1.5, tau);
        let (cos_i, sin_i) = (0.5_f64, 0.75_f64.sqrt());
        let cos_t = (1.0 - (sin_i / 1.5).powi(2)).sqrt();
        let r = g.fresnel_reflectance(cos_i);
        let w = thin_pane(&g, cos_i);
        for k in 0..3 {
            let tt = tau[k].powf(1.0 / cos_t);
            let t = tt * (1.0 - r).powi(2) / (1.0 - tt * tt * r * r);
            assert!((w.transmittance_rgb[k] - t).abs() < ROUND_OFF_TOL);
        }
        // Grazing incidence reflects everything.
        let w = thin_pane(&g, 0.0);
        assert_eq!(
            w.transmittance_rgb.map(f64::to_bits),
            [0.0_f64.to_bits(); 3]
        );
    }
}
