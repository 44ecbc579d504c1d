//! Tregenza's 145-patch sky (Tregenza 1987, "Subdivision of the sky hemisphere for luminance
//! measurements", *Lighting Res. Technol.* 19(1):13–14; CIE 108-1994): seven 12° altitude bands
//! with 30, 30, 24, 24, 18, 12, 6 patches and a polar cap above 84°. Patch centres are at the
//! band's mid-altitude and at azimuths k·360°/n (first patch centred on north), as in Radiance's
//! `gendaylit` (`defangle_theta/phi`).
//!
//! Reinhart's subdivision MF (Radiance `reinhart.cal`, Reinhart & Walkenhorst 2001) splits every
//! band into MF bands and every patch into MF in azimuth: 144·MF² + 1 patches, band height
//! 90°/(7·MF + 0.5), the cap keeping half a band height (MF = 1 is Tregenza's sky).
//!
//! # Known limitations
//! Patch centres are the mid-altitude, not the solid-angle centroid (a standard convention; it
//! biases the centre-point rule slightly towards the horizon).

use super::{DomeError, SkyDome, SkyFacet, dir_from_elevation_azimuth};
use std::f64::consts::PI;

/// Patches per band of the Tregenza sky, horizon band first.
pub const TREGENZA_BAND_COUNTS: [u32; 7] = [30, 30, 24, 24, 18, 12, 6];

/// Largest accepted Reinhart subdivision.
pub const MAX_SUBDIVISION: u32 = 64;

/// Tregenza's 145 patches.
#[must_use]
pub fn tregenza_dome() -> SkyDome {
    // MF = 1 is always in range.
    reinhart_dome(1).unwrap_or(SkyDome { facets: Vec::new() })
}

/// Reinhart subdivision `mf` of the Tregenza sky: 144·mf² + 1 patches.
///
/// # Errors
/// [`DomeError::ResolutionOutOfRange`] for mf = 0 or above [`MAX_SUBDIVISION`].
pub fn reinhart_dome(mf: u32) -> Result<SkyDome, DomeError> {
    if mf == 0 || mf > MAX_SUBDIVISION {
        return Err(DomeError::ResolutionOutOfRange {
            name: "mf",
            value: u64::from(mf),
            max: u64::from(MAX_SUBDIVISION),
        });
    }
    let band_height = (90.0 / (7.0 * f64::from(mf) + 0.5)).to_radians();
    let mut facets = Vec::with_capacity((144 * mf * mf + 1) as usize);
    for (t, &count) in TREGENZA_BAND_COUNTS.iter().enumerate() {
        for sub in 0..mf {
            let row = t as u32 * mf + sub;
            let alt0 = f64::from(row) * band_height;
            let alt1 = alt0 + band_height;
            let n = count * mf;
            let solid_angle_sr = 2.0 * PI * (alt1.sin() - alt0.sin()) / f64::from(n);
            let elevation = 0.5 * (alt0 + alt1);
            for k in 0..n {
                let azimuth = f64::from(k) * 2.0 * PI / f64::from(n);
                facets.push(SkyFacet {
                    centre_dir_in_world: dir_from_elevation_azimuth(elevation, azimuth),
                    solid_angle_sr,
                });
            }
        }
    }
    let cap_from = 7.0 * f64::from(mf) * band_height;
    facets.push(SkyFacet {
        centre_dir_in_world: nalgebra::Vector3::z(),
        solid_angle_sr: 2.0 * PI * (1.0 - cap_from.sin()),
    });
    Ok(SkyDome { facets })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky_dome::{illuminance, test_support};

    /// Finest level MF = 8 (9 217 patches). The mid-altitude centres give an O(h²) error with
    /// h = 12°/MF (measured 4.4e-3, 1.2e-3, 3.1e-4, 7.8e-5 for MF 1, 2, 4, 8); 1.5e-4 bound.
    const OVERCAST_FINEST_REL_TOL: f64 = 1.5e-4;
    /// Clear sky type 12 at MF = 8 (measured 1.1e-4 against the 4-decimal table value, whose
    /// rounding alone is 1e-5); 3e-4 bound.
    const CLEAR_FINEST_REL_TOL: f64 = 3e-4;

    #[test]
    fn counts_and_total_solid_angle() {
        let t = tregenza_dome();
        assert_eq!(t.facets.len(), 145);
        assert!((t.total_solid_angle_sr() - 2.0 * PI).abs() < 1e-12);
        for (mf, n) in [(2, 577), (4, 2305)] {
            let d = reinhart_dome(mf).expect("valid");
            assert_eq!(d.facets.len(), n);
            assert!((d.total_solid_angle_sr() - 2.0 * PI).abs() < 1e-12);
        }
        assert!(reinhart_dome(0).is_err());
        // Tregenza cap: 2π(1 − sin 84°) = 0.034 37 sr.
        let cap = t.facets.last().map_or(0.0, |f| f.solid_angle_sr);
        assert!((cap - 2.0 * PI * (1.0 - 84_f64.to_radians().sin())).abs() < 1e-12);
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
            let errors: Vec<f64> = [1, 2, 4, 8]
                .iter()
                .map(|&mf| {
                    let dome = reinhart_dome(mf).expect("valid");
                    let e = illuminance(&dome.sources(&sky), &test_support::up());
                    (e / want - 1.0).abs()
                })
                .collect();
            test_support::assert_converges(module_path!(), &errors, tol);
        }
    }
}
