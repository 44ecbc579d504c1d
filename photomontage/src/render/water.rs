//! Water surfaces in the tracer: the material's [`WaterWaves`] perturb the shading normal with
//! a solid texture of gradient noise (Durisch 1992 §7 example 2, after Haruyama & Barsky 1984,
//! Perlin 1985; bump mapping after Blinn 1978). The perturbed normal drives the diffuse cosine,
//! the mirror direction and the specular lobe; shadow and secondary rays still start from the
//! geometric surface, and a reflection that the perturbation would send into the surface falls
//! back to the geometric mirror direction.
//!
//! # Known limitations
//! Isotropic noise, not a wave spectrum; no animation; the perturbed normal is not filtered
//! (waves smaller than a pixel alias, the pixel's adaptive rays average them).

use nalgebra::{Point3, Vector3};

use crate::scene::Material;
use crate::scene::material::{GradientNoise, WaterWaves};

/// The shading normal at `point`: the geometric `normal` (facing the incoming ray
/// `dir_in_world`), perturbed by the material's water waves when it has them with a positive
/// slope (`noise` built from their seed). A perturbed normal that would face away from the
/// incoming ray, or is not finite, is replaced by the geometric one.
#[must_use]
pub fn shading_normal(
    material: Option<&Material>,
    noise: Option<&GradientNoise>,
    point: &Point3<f64>,
    normal: &Vector3<f64>,
    dir_in_world: &Vector3<f64>,
) -> Vector3<f64> {
    match (material.and_then(|m| m.water), noise) {
        (Some(waves), Some(noise)) if waves.slope > 0.0 => {
            perturbed_normal(&waves, noise, point, normal, dir_in_world)
        }
        _ => *normal,
    }
}

fn perturbed_normal(
    waves: &WaterWaves,
    noise: &GradientNoise,
    point: &Point3<f64>,
    normal: &Vector3<f64>,
    dir_in_world: &Vector3<f64>,
) -> Vector3<f64> {
    let n = waves.perturb_normal(noise, *normal, point.coords);
    if n.iter().all(|c| c.is_finite()) && n.dot(dir_in_world) < 0.0 {
        n
    } else {
        *normal
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Normalisation round-off.
    const UNIT_TOL: f64 = 1e-12;

    fn lake(slope: f64, seed: u64) -> Material {
        Material {
            water: Some(WaterWaves {
                scale_m: 3.0,
                slope,
                octaves: 4,
                seed,
            }),
            mirror_rgb: Some([0.3; 3]),
            ..Material::diffuse("lake", [0.05; 3])
        }
    }

    fn points() -> impl Iterator<Item = Point3<f64>> {
        // Survey-sized coordinates, as a UTM site would have.
        (0..200).map(|k| {
            let k = f64::from(k);
            Point3::new(
                600_000.0 + 0.37 * k,
                5_200_000.0 + 0.113 * k * k % 17.0,
                401.2,
            )
        })
    }

    #[test]
    fn perturbed_normals_are_unit_facing_the_viewer_and_tilted() {
        let m = lake(0.6, 11);
        let noise = GradientNoise::new(11);
        let up = Vector3::z();
        let down = Vector3::new(0.3, 0.1, -1.0).normalize();
        let mut max_tilt: f64 = 0.0;
        for p in points() {
            let n = shading_normal(Some(&m), Some(&noise), &p, &up, &down);
            assert!((n.norm() - 1.0).abs() < UNIT_TOL, "{n}");
            assert!(n.dot(&down) < 0.0);
            max_tilt = max_tilt.max(n.z.clamp(-1.0, 1.0).acos());
        }
        assert!(
            max_tilt > 0.05,
            "the waves must tilt some normals: {max_tilt}"
        );
    }

    #[test]
    fn deterministic_for_a_seed_and_seed_dependent() {
        let up = Vector3::z();
        let down = -Vector3::z();
        let (a, b) = (GradientNoise::new(5), GradientNoise::new(5));
        let other = GradientNoise::new(6);
        let (m5, m6) = (lake(0.5, 5), lake(0.5, 6));
        let mut differs = false;
        for p in points() {
            let na = shading_normal(Some(&m5), Some(&a), &p, &up, &down);
            let nb = shading_normal(Some(&m5), Some(&b), &p, &up, &down);
            assert_eq!(na.map(f64::to_bits), nb.map(f64::to_bits));
            let nc = shading_normal(Some(&m6), Some(&other), &p, &up, &down);
            differs |= (na - nc).norm() > 1e-6;
        }
        assert!(differs, "another seed gives other waves");
    }

    #[test]
    fn zero_slope_or_no_water_is_exactly_the_flat_normal() {
        let up = Vector3::new(0.0, 0.6, 0.8);
        let down = -Vector3::z();
        let noise = GradientNoise::new(3);
        let flat = lake(0.0, 3);
        let plain = Material::diffuse("plain", [0.5; 3]);
        for p in points() {
            for m in [Some(&flat), Some(&plain), None] {
                let n = shading_normal(m, Some(&noise), &p, &up, &down);
                assert_eq!(n.map(f64::to_bits), up.map(f64::to_bits));
            }
        }
    }
}
