//! Sky luminance models: uniform, traditional CIE overcast (Moon & Spencer), the 15 CIE standard
//! general skies (CIE S 011/E:2003) and the Perez all-weather sky (Perez, Seals & Michalsky 1993);
//! normalisation to a zenith luminance or a horizontal illuminance; numerical illuminance
//! integrals; a fisheye luminance map ([`map`]). Formulas and reference values:
//! `reference/lighting.md` §1; Durisch 1992 §3.3 for the role of the sky as a light source.
//!
//! Directions are unit vectors in the world frame with z up (the project's convention; for
//! azimuths x is east and y north). `sun_dir_in_world` points from the site towards the sun.
//!
//! # Known limitations
//! - Skies are zero below the horizon; the ground is not part of these models.
//! - Illuminance integrals are midpoint quadratures over (cos Z, azimuth); their accuracy at the
//!   default resolution is about 1e-5 relative (tested against closed forms), far below the
//!   0.1 % the CIE table is quoted to.

pub mod cie_general;
pub mod cie_overcast;
pub mod map;
pub mod perez;
pub mod uniform;

pub use cie_general::{CieSkyParameters, CieSkyType};
pub use perez::PerezSky;

use nalgebra::Vector3;
use std::f64::consts::PI;

/// Errors of the sky models.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SkyError {
    /// CIE standard sky types are numbered 1…15.
    #[error("CIE standard sky type {number} is outside 1…15")]
    CieTypeOutOfRange {
        /// Number given.
        number: u8,
    },
    /// Irradiance inputs of the Perez model must be finite, diffuse > 0, direct ≥ 0.
    #[error(
        "invalid irradiance: direct normal {direct_normal_w_m2} W/m², diffuse horizontal {diffuse_horizontal_w_m2} W/m²"
    )]
    InvalidIrradiance {
        /// Direct normal irradiance given.
        direct_normal_w_m2: f64,
        /// Diffuse horizontal irradiance given.
        diffuse_horizontal_w_m2: f64,
    },
    /// The model needs the sun above the horizon.
    #[error("sun elevation {elevation_deg}° is not above the horizon")]
    SunBelowHorizon {
        /// Elevation given.
        elevation_deg: f64,
    },
    /// A normalisation target must be finite and positive.
    #[error("normalisation value {value} must be finite and positive")]
    InvalidNormalisation {
        /// Value given.
        value: f64,
    },
    /// A direction or angle that is not usable (zero vector, NaN, out of range).
    #[error("invalid direction or angle: {reason}")]
    InvalidDirection {
        /// What was wrong.
        reason: &'static str,
    },
    /// A map size of zero or above the limit.
    #[error("image size {size_px} px is outside 1…{max_px}")]
    InvalidImageSize {
        /// Size given.
        size_px: u32,
        /// Largest accepted size.
        max_px: u32,
    },
}

/// A sky luminance distribution (relative to its zenith luminance).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum SkyModel {
    /// Constant luminance.
    Uniform,
    /// Traditional CIE overcast sky, L ∝ (1 + 2 cos Z)/3.
    CieOvercast,
    /// One of the 15 CIE standard general skies.
    CieGeneral(CieSkyType),
    /// Perez all-weather sky.
    Perez(PerezSky),
}

/// Unit vector from elevation and azimuth (east of north), both radians: x east, y north, z up.
#[must_use]
pub fn direction_from_elevation_azimuth(elevation: f64, azimuth: f64) -> Vector3<f64> {
    Vector3::new(
        azimuth.sin() * elevation.cos(),
        azimuth.cos() * elevation.cos(),
        elevation.sin(),
    )
}

impl SkyModel {
    /// The CIE standard general sky of type `number` (1…15).
    ///
    /// # Errors
    /// [`SkyError::CieTypeOutOfRange`] outside 1…15.
    pub fn cie_general(number: u8) -> Result<Self, SkyError> {
        Ok(Self::CieGeneral(CieSkyType::new(number)?))
    }

    /// Relative luminance L/L_z in direction `dir_in_world` (unit, z up) for a sun in
    /// `sun_dir_in_world` (unit). 0 below the horizon. Models without sun dependence ignore it.
    #[must_use]
    pub fn relative_luminance(
        &self,
        dir_in_world: &Vector3<f64>,
        sun_dir_in_world: &Vector3<f64>,
    ) -> f64 {
        let cos_zenith = dir_in_world.z;
        if cos_zenith <= 0.0 {
            return 0.0;
        }
        match self {
            Self::Uniform => uniform::relative_luminance(cos_zenith),
            Self::CieOvercast => cie_overcast::relative_luminance(cos_zenith),
            Self::CieGeneral(t) => {
                let chi = dir_in_world.dot(sun_dir_in_world).clamp(-1.0, 1.0).acos();
                let sun_zenith = sun_dir_in_world.z.clamp(-1.0, 1.0).acos();
                t.parameters()
                    .relative_luminance(cos_zenith, chi, sun_zenith)
            }
            Self::Perez(p) => {
                let gamma = dir_in_world.dot(sun_dir_in_world).clamp(-1.0, 1.0).acos();
                p.relative_luminance(cos_zenith, gamma)
            }
        }
    }

    /// Illuminance on a plane with unit normal `normal_in_world` from the whole unobstructed sky,
    /// over the zenith luminance: ∫ (L/L_z)·max(0, n·l) dω, by the midpoint rule on
    /// `cells_per_quarter`×4 azimuth cells × `cells_per_quarter`×2 cells in cos Z.
    #[must_use]
    pub fn illuminance_over_zenith_luminance(
        &self,
        sun_dir_in_world: &Vector3<f64>,
        normal_in_world: &Vector3<f64>,
        cells_per_quarter: u32,
    ) -> f64 {
        let n_u = 2 * cells_per_quarter.max(1);
        let n_az = 4 * cells_per_quarter.max(1);
        let du = 1.0 / f64::from(n_u);
        let daz = 2.0 * PI / f64::from(n_az);
        let mut total = 0.0;
        for i in 0..n_u {
            let u = (f64::from(i) + 0.5) * du;
            let s = (1.0 - u * u).sqrt();
            let mut row = 0.0;
            for j in 0..n_az {
                let az = (f64::from(j) + 0.5) * daz;
                let dir = Vector3::new(az.sin() * s, az.cos() * s, u);
                let cos_incidence = dir.dot(normal_in_world);
                if cos_incidence > 0.0 {
                    row += self.relative_luminance(&dir, sun_dir_in_world) * cos_incidence;
                }
            }
            total += row;
        }
        total * du * daz
    }

    /// E_h/L_z: horizontal illuminance from the sky over the zenith luminance, at the default
    /// quadrature resolution (256 cells per quarter: 512 × 1024 cells).
    #[must_use]
    pub fn horizontal_illuminance_over_zenith_luminance(
        &self,
        sun_dir_in_world: &Vector3<f64>,
    ) -> f64 {
        match self {
            Self::Uniform => PI,
            Self::CieOvercast => cie_overcast::horizontal_illuminance_over_zenith_luminance(),
            _ => self.illuminance_over_zenith_luminance(
                sun_dir_in_world,
                &Vector3::z(),
                DEFAULT_CELLS_PER_QUARTER,
            ),
        }
    }
}

/// Default quadrature resolution of [`SkyModel::horizontal_illuminance_over_zenith_luminance`].
pub const DEFAULT_CELLS_PER_QUARTER: u32 = 256;

/// How to scale a relative sky to absolute luminance.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Normalisation {
    /// Zenith luminance, cd/m².
    ZenithLuminance(f64),
    /// Horizontal illuminance from the sky (no sun, no ground), lx.
    HorizontalIlluminance(f64),
}

/// A sky model with a sun direction and an absolute scale.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NormalisedSky {
    /// Relative distribution.
    pub model: SkyModel,
    /// Unit vector towards the sun (z up).
    pub sun_dir_in_world: Vector3<f64>,
    /// Zenith luminance L_z, cd/m².
    pub zenith_luminance_cd_m2: f64,
}

impl NormalisedSky {
    /// Scales `model` so that its zenith luminance or horizontal illuminance is as given.
    ///
    /// # Errors
    /// [`SkyError::InvalidNormalisation`] for a non-positive or non-finite target,
    /// [`SkyError::InvalidDirection`] for a sun direction that is not a unit vector.
    pub fn new(
        model: SkyModel,
        sun_dir_in_world: Vector3<f64>,
        normalisation: Normalisation,
    ) -> Result<Self, SkyError> {
        let norm = sun_dir_in_world.norm();
        // NaN fails this test too.
        if (norm - 1.0).abs() >= 1e-6 || norm.is_nan() {
            return Err(SkyError::InvalidDirection {
                reason: "sun direction must be a unit vector",
            });
        }
        let (value, zenith_luminance_cd_m2) = match normalisation {
            Normalisation::ZenithLuminance(l) => (l, l),
            Normalisation::HorizontalIlluminance(e) => (
                e,
                e / model.horizontal_illuminance_over_zenith_luminance(&sun_dir_in_world),
            ),
        };
        if !(value > 0.0 && value.is_finite() && zenith_luminance_cd_m2.is_finite()) {
            return Err(SkyError::InvalidNormalisation { value });
        }
        Ok(Self {
            model,
            sun_dir_in_world,
            zenith_luminance_cd_m2,
        })
    }

    /// Absolute luminance (cd/m²) in direction `dir_in_world` (unit, z up).
    #[must_use]
    pub fn luminance(&self, dir_in_world: &Vector3<f64>) -> f64 {
        self.zenith_luminance_cd_m2
            * self
                .model
                .relative_luminance(dir_in_world, &self.sun_dir_in_world)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The brief's and the reference table's agreement level for E_h/L_z.
    const CIE_TABLE_REL_TOL: f64 = 1e-3;
    /// Our quadrature against closed forms at the default resolution: midpoint error with
    /// 512 cells in cos Z is ~1/512² ≈ 4e-6 relative for smooth integrands.
    const QUADRATURE_REL_TOL: f64 = 2e-5;

    /// lighting.md §1.1: E_h/L_z by type (rows) at sun elevations 15/30/45/60/75° (columns).
    const E_H_TABLE: [[f64; 5]; 15] = [
        [2.4495, 2.4495, 2.4495, 2.4495, 2.4495],
        [2.6615, 2.5566, 2.3635, 2.0860, 1.7464],
        [2.7700, 2.7700, 2.7700, 2.7700, 2.7700],
        [3.0298, 2.8901, 2.6467, 2.3154, 1.9268],
        [PI, PI, PI, PI, PI],
        [3.4558, 3.2778, 2.9775, 2.5842, 2.1385],
        [3.9021, 3.6730, 3.1431, 2.4212, 1.6713],
        [4.4211, 4.1231, 3.3387, 2.3284, 1.4030],
        [4.8652, 4.5528, 4.0587, 3.4593, 2.8266],
        [5.5937, 5.1449, 4.2534, 3.1703, 2.1391],
        [6.4517, 5.8176, 4.4854, 2.9891, 1.7468],
        [7.2048, 6.3941, 4.8485, 3.1906, 1.8505],
        [8.0729, 6.9952, 4.9827, 3.0259, 1.6309],
        [9.1176, 7.7081, 5.3753, 3.2170, 1.7195],
        [10.3380, 8.1160, 5.2711, 3.0159, 1.5926],
    ];

    #[test]
    fn cie_general_horizontal_illuminance_matches_table() {
        for (t, row) in CieSkyType::all().zip(E_H_TABLE) {
            for (k, want) in row.into_iter().enumerate() {
                let elevation = (15.0 * (k as f64 + 1.0)).to_radians();
                let sun = direction_from_elevation_azimuth(elevation, 2.0);
                let got = SkyModel::CieGeneral(t).illuminance_over_zenith_luminance(
                    &sun,
                    &Vector3::z(),
                    128,
                );
                let rel = (got / want - 1.0).abs();
                assert!(
                    rel < CIE_TABLE_REL_TOL,
                    "type {} el {}: {got} vs {want} ({rel:e})",
                    t.number(),
                    15 * (k + 1)
                );
            }
        }
    }

    #[test]
    fn traditional_overcast_closed_forms() {
        let sun = direction_from_elevation_azimuth(0.5, 0.0);
        let e_h = SkyModel::CieOvercast.illuminance_over_zenith_luminance(&sun, &Vector3::z(), 256);
        let want_h = 7.0 * PI / 9.0;
        assert!((e_h / want_h - 1.0).abs() < QUADRATURE_REL_TOL, "{e_h}");
        // Vertical plane facing north (the azimuth grid has a cell edge at ±90°).
        let e_v = SkyModel::CieOvercast.illuminance_over_zenith_luminance(&sun, &Vector3::y(), 256);
        let want_v = PI / 6.0 + 4.0 / 9.0;
        assert!((e_v / want_v - 1.0).abs() < QUADRATURE_REL_TOL, "{e_v}");
        assert!((e_v / e_h - 0.39618).abs() < 0.39618 * 1e-3);
        // Uniform sky by quadrature: π.
        let e_u = SkyModel::Uniform.illuminance_over_zenith_luminance(&sun, &Vector3::z(), 256);
        assert!((e_u / PI - 1.0).abs() < QUADRATURE_REL_TOL);
    }

    #[test]
    fn normalisation_to_horizontal_illuminance() {
        let sun = direction_from_elevation_azimuth(0.6, 1.0);
        let sky = NormalisedSky::new(
            SkyModel::CieOvercast,
            sun,
            Normalisation::HorizontalIlluminance(10_000.0),
        )
        .expect("valid");
        // 10 000 lx / (7π/9) = 4092.5 cd/m² (Radiance example in lighting.md §3.1: 4091.9 from
        // its rounded 55.866 W/m² input).
        assert!((sky.zenith_luminance_cd_m2 - 10_000.0 / (7.0 * PI / 9.0)).abs() < 1e-9);
        assert!((sky.luminance(&Vector3::z()) - sky.zenith_luminance_cd_m2).abs() < 1e-9);
        assert!(
            NormalisedSky::new(
                SkyModel::Uniform,
                sun,
                Normalisation::HorizontalIlluminance(-1.0)
            )
            .is_err()
        );
        assert!(SkyModel::cie_general(16).is_err());
        assert!(SkyModel::cie_general(0).is_err());
    }
}
