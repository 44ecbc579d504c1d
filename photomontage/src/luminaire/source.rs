//! A luminaire as a light source: a photometric web placed at a point in the world and aimed
//! by a rotation, with optional LM-63 tilt multipliers; intensity toward world directions and
//! direct illuminance by the inverse-square cosine law (Durisch 1992 §3.2: light sources of the
//! montage; IES LM-63-2002 for the tilt table).
//!
//! # Known limitations
//! A point source: near-field effects of the luminous opening are ignored (use it at distances
//! above ~5× the opening size). No occlusion: visibility is the renderer's job. The tilt angle is
//! the angle between the luminaire's nadir axis and the world's downward vertical for all three
//! lamp-to-luminaire geometries.

use super::distribution::{PhotometricWeb, TiltTable};
use nalgebra::{Point3, Rotation3, Vector3};

/// A luminaire as a light source: a photometric web placed at a point and aimed by a rotation.
#[derive(Debug, Clone, PartialEq)]
pub struct Luminaire {
    /// The intensity distribution in the luminaire frame.
    pub distribution: PhotometricWeb,
    /// Optional tilt multipliers (LM-63 TILT=INCLUDE).
    pub tilt: Option<TiltTable>,
    /// Photometric centre in world coordinates (m).
    pub position_in_world: Point3<f64>,
    /// Rotation taking luminaire-frame directions to world directions (identity: nadir down).
    pub world_from_luminaire: Rotation3<f64>,
}

impl Luminaire {
    /// A luminaire hanging in its photometric position (nadir = world −z) at `position_in_world`.
    #[must_use]
    pub fn new(distribution: PhotometricWeb, position_in_world: Point3<f64>) -> Self {
        Self {
            distribution,
            tilt: None,
            position_in_world,
            world_from_luminaire: Rotation3::identity(),
        }
    }

    /// The angle (degrees) between the luminaire's nadir axis and the world's downward vertical.
    #[must_use]
    pub fn tilt_deg(&self) -> f64 {
        let nadir = self.world_from_luminaire * Vector3::new(0.0, 0.0, -1.0);
        (-nadir.z).clamp(-1.0, 1.0).acos().to_degrees()
    }

    /// Intensity (cd) emitted toward `dir_in_world`, tilt multiplier included.
    #[must_use]
    pub fn intensity_toward_cd(&self, dir_in_world: &Vector3<f64>) -> f64 {
        let dir_in_luminaire = self.world_from_luminaire.inverse() * dir_in_world;
        let tilt_factor = self
            .tilt
            .as_ref()
            .map_or(1.0, |t| t.multiplier_at(self.tilt_deg()));
        self.distribution.intensity_toward_cd(&dir_in_luminaire) * tilt_factor
    }

    /// Direct illuminance (lx) at `point_in_world` on a surface with normal `normal_in_world`,
    /// by the inverse-square cosine law E = I cos θ / d² (no occlusion).
    #[must_use]
    pub fn illuminance_lx(
        &self,
        point_in_world: &Point3<f64>,
        normal_in_world: &Vector3<f64>,
    ) -> f64 {
        let to_point = point_in_world - self.position_in_world;
        let d2 = to_point.norm_squared();
        let Some(n) = normal_in_world.try_normalize(1e-300) else {
            return 0.0;
        };
        if d2 <= 0.0 {
            return 0.0;
        }
        let dir = to_point / d2.sqrt();
        let cos_incidence = -dir.dot(&n);
        if cos_incidence <= 0.0 {
            return 0.0;
        }
        self.intensity_toward_cd(&dir) * cos_incidence / d2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::luminaire::{PhotometricType, Symmetry};
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    fn grid(step: f64, from: f64, to: f64) -> Vec<f64> {
        let n = ((to - from) / step).round() as usize;
        (0..=n).map(|i| from + step * i as f64).collect()
    }

    #[test]
    fn luminaire_inverse_square_and_aiming() {
        let v = grid(5.0, 0.0, 180.0);
        let web = PhotometricWeb::from_planes(
            PhotometricType::C,
            Symmetry::Axial,
            &[0.0],
            &v,
            &v.iter()
                .map(|g| if *g < 90.0 { 1000.0 } else { 0.0 })
                .collect::<Vec<_>>(),
        )
        .unwrap();
        let lum = Luminaire::new(web.clone(), Point3::new(0.0, 0.0, 5.0));
        // 1000 cd straight down onto a floor 5 m below: 40 lx.
        let e = lum.illuminance_lx(&Point3::origin(), &Vector3::z());
        assert_relative_eq!(e, 40.0, max_relative = 1e-12);
        // Aimed straight up (rotated 180° about x), the floor is dark and a ceiling is lit.
        let mut up = Luminaire::new(web, Point3::new(0.0, 0.0, 5.0));
        up.world_from_luminaire = Rotation3::from_axis_angle(&Vector3::x_axis(), PI);
        assert_relative_eq!(up.tilt_deg(), 180.0, epsilon = 1e-9);
        assert_relative_eq!(up.illuminance_lx(&Point3::origin(), &Vector3::z()), 0.0);
        let e_ceiling = up.illuminance_lx(&Point3::new(0.0, 0.0, 7.0), &-Vector3::z());
        assert_relative_eq!(e_ceiling, 250.0, max_relative = 1e-12);
    }
}
