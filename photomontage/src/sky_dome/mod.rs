//! Discretised sky domes: the sky hemisphere cut into facets that act as distant light sources
//! (Durisch 1992 §3.3 eq. 5: "each facet of the discretized sky hemisphere is treated as an
//! individual natural light source"; Tonn & Donath: the geometry is precomputed once, the sky's
//! luminance is applied afterwards, so a new sun or sky only re-weights the same sources).
//!
//! Three discretisations: [`durisch_facets`] (4·m_h² equal-solid-angle facets),
//! [`tregenza`] (the 145 patches daylighting users know, and Reinhart's subdivisions of them),
//! [`icosahedral`] (hierarchical geodesic dome with error-bounded clustering).
//!
//! A [`SkyDome`] holds geometry only: facet centre directions and solid angles. Applying a
//! [`NormalisedSky`] gives [`SkySource`]s whose `integrated_luminance` = L(centre)·Ω approximates
//! ∫_facet L dω (the point-source rule of eq. 5), so E = Σ integrated_luminance · max(0, n·d).
//!
//! # Known limitations
//! The centre-point rule is exact only for luminance that is linear over a facet; near the sun of
//! a clear sky it converges at the facet-size rate (see the tests). Visibility (δ_i of eq. 5) is
//! the renderer's business.

pub mod durisch_facets;
pub mod icosahedral;
pub mod tregenza;

use crate::sky::NormalisedSky;
use nalgebra::Vector3;

/// Errors of the dome constructors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DomeError {
    /// A resolution parameter outside the accepted range (zero, or so large it would allocate
    /// an unreasonable number of facets).
    #[error("{name} = {value} is outside 1…{max}")]
    ResolutionOutOfRange {
        /// Parameter name.
        name: &'static str,
        /// Value given.
        value: u64,
        /// Largest accepted value.
        max: u64,
    },
    /// A clustering tolerance must be finite and ≥ 0.
    #[error("tolerance {tolerance} must be finite and non-negative")]
    InvalidTolerance {
        /// Value given.
        tolerance: f64,
    },
    /// Per-leaf values must match the leaf count and be finite and non-negative.
    #[error("expected {expected} finite non-negative leaf values, got {found}")]
    LeafValues {
        /// Number of leaves.
        expected: usize,
        /// Number given, or the index of the first bad value.
        found: usize,
    },
}

/// Geometry of one facet: the direction to its centre and its solid angle.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SkyFacet {
    /// Unit vector to the facet centre (z up).
    pub centre_dir_in_world: Vector3<f64>,
    /// Solid angle Δω, steradians.
    pub solid_angle_sr: f64,
}

/// A facet as a distant light source for a given sky.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SkySource {
    /// Unit vector from the scene towards the source.
    pub dir_in_world: Vector3<f64>,
    /// Solid angle the source stands for, steradians.
    pub solid_angle_sr: f64,
    /// ∫ L dω over the source (cd·sr/m² = lm/m²): the illuminance it gives at normal incidence.
    pub integrated_luminance: f64,
}

/// A discretised sky hemisphere (geometry only).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SkyDome {
    /// The facets; their solid angles sum to 2π.
    pub facets: Vec<SkyFacet>,
}

impl SkyDome {
    /// The facets as light sources for `sky` (point rule: L at the centre × Ω).
    #[must_use]
    pub fn sources(&self, sky: &NormalisedSky) -> Vec<SkySource> {
        self.facets
            .iter()
            .map(|f| SkySource {
                dir_in_world: f.centre_dir_in_world,
                solid_angle_sr: f.solid_angle_sr,
                integrated_luminance: sky.luminance(&f.centre_dir_in_world) * f.solid_angle_sr,
            })
            .collect()
    }

    /// Total solid angle (2π for a complete hemisphere).
    #[must_use]
    pub fn total_solid_angle_sr(&self) -> f64 {
        self.facets.iter().map(|f| f.solid_angle_sr).sum()
    }
}

/// Illuminance (lx) on an unobstructed plane with unit normal `normal_in_world` from `sources`.
#[must_use]
pub fn illuminance(sources: &[SkySource], normal_in_world: &Vector3<f64>) -> f64 {
    sources
        .iter()
        .map(|s| s.integrated_luminance * s.dir_in_world.dot(normal_in_world).max(0.0))
        .sum()
}

/// Unit vector from an elevation (radians above the horizon) and an azimuth (radians east of
/// north).
pub(crate) fn dir_from_elevation_azimuth(elevation: f64, azimuth: f64) -> Vector3<f64> {
    crate::sky::direction_from_elevation_azimuth(elevation, azimuth)
}

#[cfg(test)]
pub(crate) mod test_support {
    use crate::sky::{
        Normalisation, NormalisedSky, SkyModel, cie_overcast, direction_from_elevation_azimuth,
    };
    use nalgebra::Vector3;

    /// Prints the relative errors of a refinement sequence, then asserts that they fall at every
    /// level and that the finest is below `tol`.
    pub fn assert_converges(label: &str, errors: &[f64], tol: f64) {
        let shown: Vec<String> = errors.iter().map(|e| format!("{e:.2e}")).collect();
        eprintln!("{label}: relative E_h errors by level {shown:?}");
        for w in errors.windows(2) {
            assert!(w[1] < w[0], "not decreasing: {errors:?}");
        }
        let finest = errors.last().copied().unwrap_or(f64::INFINITY);
        assert!(finest < tol, "{errors:?}");
    }

    /// CIE overcast sky with L_z = 1: analytic E_h = 7π/9.
    pub fn overcast() -> (NormalisedSky, f64) {
        let sky = NormalisedSky::new(
            SkyModel::CieOvercast,
            direction_from_elevation_azimuth(0.7, 0.3),
            Normalisation::ZenithLuminance(1.0),
        )
        .expect("valid");
        (
            sky,
            cie_overcast::horizontal_illuminance_over_zenith_luminance(),
        )
    }

    /// CIE clear sky (type 12), sun at 45° elevation, azimuth 200°, L_z = 1: E_h/L_z = 4.8485
    /// (lighting.md §1.1, 4 decimals).
    pub fn clear_45() -> (NormalisedSky, f64) {
        let sky = NormalisedSky::new(
            SkyModel::cie_general(12).expect("valid"),
            direction_from_elevation_azimuth(45_f64.to_radians(), 200_f64.to_radians()),
            Normalisation::ZenithLuminance(1.0),
        )
        .expect("valid");
        (sky, 4.8485)
    }

    pub fn up() -> Vector3<f64> {
        Vector3::z()
    }
}
