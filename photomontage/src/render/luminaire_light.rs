//! Artificial lights of the project (Durisch 1992 §3.2 light sources, §6.2 cases C and D1):
//! an isotropic [`PointLight`] or a [`LuminaireLight`], a luminaire whose intensity depends on
//! the direction through its photometric web (IES LM-63 / EULUMDAT, [`crate::luminaire`]),
//! placed and aimed in the world, with a colour and scale that turn candela into the photo's
//! units. Both go through one code path: the intensity towards a direction, the inverse-square
//! cosine law ([`inverse_square_cosine_rgb`]) and an any-hit shadow ray against every object
//! (in the tracer); on artificial surfaces they light the diffuse and specular layers (case C),
//! on natural ones they add `ρ_d/π·E` (case D1).
//!
//! # Known limitations
//! Point sources: the luminous opening's size is ignored (no soft shadows, near-field error
//! within ~5 opening sizes). The colour is one RGB triple for the whole web (no angle-dependent
//! spectrum). Luminaires are not visible themselves (no geometry) and do not light the
//! photographed surroundings through the photo bounce.

use nalgebra::{Point3, Vector3};

use super::illumination::{PointLight, Rgb, inverse_square_cosine_rgb};
use crate::luminaire::Luminaire;

/// A luminaire as an artificial light: photometric web, position and aim
/// ([`Luminaire`]), and the radiant scale of one candela in the photo's units.
#[derive(Debug, Clone, PartialEq)]
pub struct LuminaireLight {
    /// The positioned, aimed luminaire (intensities in cd, tilt multipliers applied).
    pub luminaire: Luminaire,
    /// Photo units × m² per candela, per channel: the light's colour and the exposure scale
    /// (intensity in the photo's units = `I_cd · rgb_per_cd`).
    pub rgb_per_cd: Rgb,
}

impl LuminaireLight {
    /// Intensity towards `dir_from_light_in_world` (unit), photo units × m².
    #[must_use]
    pub fn intensity_toward_rgb(&self, dir_from_light_in_world: &Vector3<f64>) -> Rgb {
        let i_cd = self.luminaire.intensity_toward_cd(dir_from_light_in_world);
        self.rgb_per_cd.map(|c| c * i_cd)
    }
}

/// An artificial light of the project.
#[derive(Debug, Clone, PartialEq)]
pub enum ArtificialLight {
    /// Isotropic point light.
    Point(PointLight),
    /// Luminaire with a photometric web.
    Luminaire(Box<LuminaireLight>),
}

impl From<PointLight> for ArtificialLight {
    fn from(light: PointLight) -> Self {
        Self::Point(light)
    }
}

impl From<LuminaireLight> for ArtificialLight {
    fn from(light: LuminaireLight) -> Self {
        Self::Luminaire(Box::new(light))
    }
}

impl ArtificialLight {
    /// Position of the (photometric centre of the) light, world frame, metres.
    #[must_use]
    pub fn position_in_world_m(&self) -> Point3<f64> {
        match self {
            Self::Point(p) => p.position_in_world_m,
            Self::Luminaire(l) => l.luminaire.position_in_world,
        }
    }

    /// Intensity towards the unit direction `dir_from_light_in_world`, photo units × m².
    #[must_use]
    pub fn intensity_toward_rgb(&self, dir_from_light_in_world: &Vector3<f64>) -> Rgb {
        match self {
            Self::Point(p) => p.intensity_rgb,
            Self::Luminaire(l) => l.intensity_toward_rgb(dir_from_light_in_world),
        }
    }

    /// Irradiance at `point_in_world_m` on a surface with unit normal `normal` (inverse-square
    /// cosine law, no occlusion).
    #[must_use]
    pub fn irradiance_rgb(&self, point_in_world_m: &Point3<f64>, normal: &Vector3<f64>) -> Rgb {
        inverse_square_cosine_rgb(
            &self.position_in_world_m(),
            |d| self.intensity_toward_rgb(d),
            point_in_world_m,
            normal,
        )
    }

    /// Irradiance at `point_in_world_m` on a surface facing the light, `I(dir)/d²`.
    #[must_use]
    pub fn normal_irradiance_rgb(&self, point_in_world_m: &Point3<f64>) -> Rgb {
        let from_light = point_in_world_m - self.position_in_world_m();
        let d2 = from_light.norm_squared();
        if d2 <= 0.0 {
            return [0.0; 3];
        }
        self.intensity_toward_rgb(&(from_light / d2.sqrt()))
            .map(|i| i / d2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::luminaire::IesFile;

    /// A few products and one square root.
    const ROUND_OFF_TOL: f64 = 1e-12;

    /// A hand-written LM-63-2002 file: type C, axially symmetric, tabulated at 0/30/60/90°.
    pub(crate) const DOWNLIGHT_IES: &str = "IESNA:LM-63-2002\n\
        [TEST] photomontage render fixture\n\
        [LUMINAIRE] hand-written downlight\n\
        TILT=NONE\n\
        1 -1 1 7 1 1 2 0.2 0.2 0.1\n\
        1.0 1.0 20\n\
        0 30 60 90 120 150 180\n\
        0\n\
        1000 800 400 0 0 0 0\n";

    pub(crate) fn downlight(position: Point3<f64>) -> Luminaire {
        let web = IesFile::parse(DOWNLIGHT_IES.as_bytes())
            .unwrap()
            .distribution()
            .unwrap();
        Luminaire::new(web, position)
    }

    #[test]
    fn luminaire_light_follows_the_web_and_the_inverse_square_cosine_law() {
        let light = ArtificialLight::from(LuminaireLight {
            luminaire: downlight(Point3::new(0.0, 0.0, 5.0)),
            rgb_per_cd: [1e-3, 2e-3, 0.5e-3],
        });
        // Straight below, d = 5: E = 1000 cd / 25 m².
        let e = light.irradiance_rgb(&Point3::origin(), &Vector3::z());
        for (k, s) in [1e-3, 2e-3, 0.5e-3].iter().enumerate() {
            assert!((e[k] - s * 1000.0 / 25.0).abs() < ROUND_OFF_TOL);
        }
        // γ = 60° on the floor: d = 10, cos = 0.5, I = 400 cd (tabulated) → E = 2 lx × scale.
        let p = Point3::new(5.0 * 3f64.sqrt(), 0.0, 0.0);
        let e = light.irradiance_rgb(&p, &Vector3::z());
        assert!(
            (e[0] - 1e-3 * 400.0 * 0.5 / 100.0).abs() < ROUND_OFF_TOL,
            "{e:?}"
        );
        // Above the luminaire (γ > 90°): dark.
        let e = light.irradiance_rgb(&Point3::new(0.0, 0.0, 8.0), &-Vector3::z());
        assert!(e.iter().all(|v| v.abs() < ROUND_OFF_TOL));
    }

    #[test]
    fn a_point_light_is_the_isotropic_special_case() {
        let p = PointLight {
            position_in_world_m: Point3::new(1.0, 2.0, 3.0),
            intensity_rgb: [7.0, 8.0, 9.0],
        };
        let q = Point3::new(-2.0, 0.5, 0.0);
        let n = Vector3::new(0.2, 0.1, 1.0).normalize();
        let a = ArtificialLight::from(p);
        assert_eq!(
            a.irradiance_rgb(&q, &n).map(f64::to_bits),
            p.irradiance_rgb(&q, &n).map(f64::to_bits)
        );
        // Facing the light, E = I / d².
        let d2 = (p.position_in_world_m - q).norm_squared();
        let e = a.normal_irradiance_rgb(&q);
        assert!((e[1] - 8.0 / d2).abs() < ROUND_OFF_TOL);
    }
}
