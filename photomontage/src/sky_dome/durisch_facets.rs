//! Durisch's sky facets (Durisch 1992 §3.3, eq. 5): the hemisphere is cut into m_h rings in the
//! polar direction × 4·m_h facets in azimuth, 4·m_h² facets of equal solid angle
//! Δω = 2π/(4·m_h²). Equal solid angle per ring means equal steps in cos Z: ring k spans
//! cos Z ∈ [1 − (k+1)/m_h, 1 − k/m_h]. The facet centre is the midpoint in cos Z and azimuth.
//!
//! # Known limitations
//! Rings are equal in cos Z, so facets are long and thin near the zenith for small m_h
//! (m_h = 1 gives 4 facets spanning the whole hemisphere, as in Durisch's courtyard example).

use super::{DomeError, SkyDome, SkyFacet, dir_from_elevation_azimuth};
use std::f64::consts::PI;

/// Largest accepted m_h (4·m_h² = 4 194 304 facets).
pub const MAX_M_H: u32 = 1024;

/// The 4·m_h² equal-solid-angle facets.
///
/// # Errors
/// [`DomeError::ResolutionOutOfRange`] for m_h = 0 or above [`MAX_M_H`].
pub fn durisch_dome(m_h: u32) -> Result<SkyDome, DomeError> {
    if m_h == 0 || m_h > MAX_M_H {
        return Err(DomeError::ResolutionOutOfRange {
            name: "m_h",
            value: u64::from(m_h),
            max: u64::from(MAX_M_H),
        });
    }
    let m = f64::from(m_h);
    let n_az = 4 * m_h;
    let solid_angle_sr = 2.0 * PI / (4.0 * m * m);
    let mut facets = Vec::with_capacity((n_az * m_h) as usize);
    for ring in 0..m_h {
        let cos_zenith = 1.0 - (f64::from(ring) + 0.5) / m;
        let elevation = cos_zenith.asin();
        for k in 0..n_az {
            let azimuth = (f64::from(k) + 0.5) * 2.0 * PI / f64::from(n_az);
            facets.push(SkyFacet {
                centre_dir_in_world: dir_from_elevation_azimuth(elevation, azimuth),
                solid_angle_sr,
            });
        }
    }
    Ok(SkyDome { facets })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky_dome::{illuminance, test_support};

    /// Overcast: the integrand (1 + 2u)u/3 is quadratic in u = cos Z, so the midpoint rule's error
    /// is exactly −h²/24·∫f'' · 2π = −(π/9)/m_h², i.e. −1/(7·m_h²) relative: 3.5e-5 at m_h = 64.
    const OVERCAST_FINEST_REL_TOL: f64 = 4e-5;
    /// Clear sky type 12: the reference is quoted to 4 decimals (1e-5 relative); measured errors
    /// 1.4e-1, 7.9e-3, 3.0e-3, 7.9e-4, 4.9e-5 for m_h 2, 4, 8, 16, 64; 1.5e-4 bound.
    const CLEAR_FINEST_REL_TOL: f64 = 1.5e-4;

    #[test]
    fn equal_solid_angles_sum_to_hemisphere() {
        for m_h in [1, 2, 5] {
            let dome = durisch_dome(m_h).expect("valid");
            assert_eq!(dome.facets.len(), (4 * m_h * m_h) as usize);
            assert!((dome.total_solid_angle_sr() - 2.0 * PI).abs() < 1e-12);
        }
        assert!(durisch_dome(0).is_err());
        assert!(durisch_dome(MAX_M_H + 1).is_err());
    }

    #[test]
    fn uniform_sky_is_exact() {
        // Σ cos Z_k Δω over rings is the midpoint rule of ∫u du: exact, π for L = 1.
        let dome = durisch_dome(3).expect("valid");
        let sum: f64 = dome
            .facets
            .iter()
            .map(|f| f.centre_dir_in_world.z * f.solid_angle_sr)
            .sum();
        assert!((sum - PI).abs() < 1e-12);
    }

    #[test]
    fn overcast_error_is_the_midpoint_rule_closed_form() {
        let (sky, want) = test_support::overcast();
        for m_h in [1, 3, 10] {
            let dome = durisch_dome(m_h).expect("valid");
            let rel = illuminance(&dome.sources(&sky), &test_support::up()) / want - 1.0;
            let expected = -1.0 / (7.0 * f64::from(m_h * m_h));
            assert!(
                (rel - expected).abs() < 1e-12,
                "m_h {m_h}: {rel} vs {expected}"
            );
        }
    }

    #[test]
    fn horizontal_illuminance_converges() {
        for (sky, want, tol) in [
            {
                let (s, w) = test_support::overcast();
                (s, w, OVERCAST_FINEST_REL_TOL)
            },
            {
                let (s, w) = test_support::clear_45();
                (s, w, CLEAR_FINEST_REL_TOL)
            },
        ] {
            let errors: Vec<f64> = [2, 4, 8, 16, 64]
                .iter()
                .map(|&m_h| {
                    let dome = durisch_dome(m_h).expect("valid");
                    let e = illuminance(&dome.sources(&sky), &test_support::up());
                    (e / want - 1.0).abs()
                })
                .collect();
            test_support::assert_converges(module_path!(), &errors, tol);
        }
    }
}
