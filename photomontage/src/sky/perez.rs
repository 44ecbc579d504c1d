//! Perez all-weather sky luminance model: Perez, Seals & Michalsky, "All-weather model for sky
//! luminance distribution — preliminary configuration and validation", *Solar Energy*
//! 50(3):235–245, 1993. The model's coefficient table (8 clearness bins × 5 parameters × 4) and
//! the sky-condition indices follow Radiance's `gendaylit.c` (`coeff_perez[]`,
//! `calc_rel_lum_perez`, `sky_clearness`, `sky_brightness`, `air_mass`, `get_eccentricity`),
//! as listed in `reference/lighting.md` §1.5:
//!
//! ```text
//! lv(ζ, γ) = [1 + a·exp(b/cos ζ)]·[1 + c·exp(d·γ) + e·cos²γ]
//! x = x1 + x2·Z + Δ·(x3 + x4·Z) for x ∈ {a, b, c, d, e}   (bin 1: special c and d)
//! ε = [(E_dh + E_bn)/E_dh + 1.041·Z³] / (1 + 1.041·Z³),  Δ = E_dh·m / E_0n
//! ```
//!
//! # Known limitations
//! - Only the relative distribution is modelled; absolute luminance comes from a normalisation
//!   to a measured or modelled illuminance ([`super::NormalisedSky`]); Perez's luminous-efficacy
//!   models are not implemented.
//! - As in gendaylit, ε is limited to 1…12.01 and Δ to 0.01…0.6, and Δ ≥ 0.2 is enforced for
//!   1.065 < ε < 2.8. cos ζ is bounded below by 0.01 so that a positive b cannot overflow at the
//!   horizon (for the usual b < 0 this changes nothing: exp(b/0.01) < 1e-30).

use super::SkyError;

/// Perez 1993 coefficients, bins 1…8 (ε upper edges 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2, ∞),
/// each a, b, c, d, e × (x1, x2, x3, x4), as in gendaylit's `coeff_perez[]`.
pub const PEREZ_COEFFICIENTS: [[[f64; 4]; 5]; 8] = [
    [
        [1.3525, -0.2576, -0.2690, -1.4366],
        [-0.7670, 0.0007, 1.2734, -0.1233],
        [2.8000, 0.6004, 1.2375, 1.0000],
        [1.8734, 0.6297, 0.9738, 0.2809],
        [0.0356, -0.1246, -0.5718, 0.9938],
    ],
    [
        [-1.2219, -0.7730, 1.4148, 1.1016],
        [-0.2054, 0.0367, -3.9128, 0.9156],
        [6.9750, 0.1774, 6.4477, -0.1239],
        [-1.5798, -0.5081, -1.7812, 0.1080],
        [0.2624, 0.0672, -0.2190, -0.4285],
    ],
    [
        [-1.1000, -0.2515, 0.8952, 0.0156],
        [0.2782, -0.1812, -4.5000, 1.1766],
        [24.7219, -13.0812, -37.7000, 34.8438],
        [-5.0000, 1.5218, 3.9229, -2.6204],
        [-0.0156, 0.1597, 0.4199, -0.5562],
    ],
    [
        [-0.5484, -0.6654, -0.2672, 0.7117],
        [0.7234, -0.6219, -5.6812, 2.6297],
        [33.3389, -18.3000, -62.2500, 52.0781],
        [-3.5000, 0.0016, 1.1477, 0.1062],
        [0.4659, -0.3296, -0.0876, -0.0329],
    ],
    [
        [-0.6000, -0.3566, -2.5000, 2.3250],
        [0.2937, 0.0496, -5.6812, 1.8415],
        [21.0000, -4.7656, -21.5906, 7.2492],
        [-3.5000, -0.1554, 1.4062, 0.3988],
        [0.0032, 0.0766, -0.0656, -0.1294],
    ],
    [
        [-1.0156, -0.3670, 1.0078, 1.4051],
        [0.2875, -0.5328, -3.8500, 3.3750],
        [14.0000, -0.9999, -7.1406, 7.5469],
        [-3.4000, -0.1078, -1.0750, 1.5702],
        [-0.0672, 0.4016, 0.3017, -0.4844],
    ],
    [
        [-1.0000, 0.0211, 0.5025, -0.5119],
        [-0.3000, 0.1922, 0.7023, -1.6317],
        [19.0000, -5.0000, 1.2438, -1.9094],
        [-4.0000, 0.0250, 0.3844, 0.2656],
        [1.0468, -0.3788, -2.4517, 1.4656],
    ],
    [
        [-1.0500, 0.0289, 0.4260, 0.3590],
        [-0.3250, 0.1156, 0.7781, 0.0025],
        [31.0625, -14.5000, -46.1148, 55.3750],
        [-7.2312, 0.4050, 13.3500, 0.6234],
        [1.5000, -0.6426, 1.8564, 0.5636],
    ],
];

/// Upper edges of the clearness bins 1…7 (bin 8 is open-ended).
const BIN_UPPER_EDGES: [f64; 7] = [1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200];

/// Solar constant used by gendaylit, W/m².
pub const SOLAR_CONSTANT_W_M2: f64 = 1367.0;

/// A Perez sky: its five distribution parameters plus the indices they came from.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PerezSky {
    /// Sky clearness ε (after the gendaylit limits).
    pub clearness: f64,
    /// Sky brightness Δ (after the gendaylit limits).
    pub brightness: f64,
    /// Solar zenith angle Z used for the coefficients, radians.
    pub sun_zenith: f64,
    /// Distribution parameters a, b, c, d, e.
    pub coefficients: [f64; 5],
}

/// Kasten (1966) relative optical air mass at solar zenith `zenith_deg`, as gendaylit `air_mass`.
#[must_use]
pub fn air_mass_kasten(zenith_deg: f64) -> f64 {
    let z = zenith_deg.min(90.0);
    1.0 / (z.to_radians().cos() + 0.15 * (93.885 - z).powf(-1.253))
}

/// Eccentricity correction (R0/R)² for day number 1…366 (Spencer 1971, as gendaylit).
#[must_use]
pub fn eccentricity_correction(day_of_year: u32) -> f64 {
    let day_angle = 2.0 * std::f64::consts::PI * (f64::from(day_of_year) - 1.0) / 365.0;
    1.00011
        + 0.034221 * day_angle.cos()
        + 0.00128 * day_angle.sin()
        + 0.000719 * (2.0 * day_angle).cos()
        + 0.000077 * (2.0 * day_angle).sin()
}

/// Sky clearness ε and brightness Δ from direct normal and diffuse horizontal irradiance
/// (W/m²), solar zenith (radians) and day of year, before any limiting.
///
/// # Errors
/// [`SkyError::InvalidIrradiance`] when the diffuse irradiance is not positive or the direct
/// one negative or either is not finite; [`SkyError::SunBelowHorizon`] for Z ≥ 90°.
pub fn clearness_and_brightness(
    direct_normal_w_m2: f64,
    diffuse_horizontal_w_m2: f64,
    sun_zenith: f64,
    day_of_year: u32,
) -> Result<(f64, f64), SkyError> {
    if !(diffuse_horizontal_w_m2 > 0.0
        && diffuse_horizontal_w_m2.is_finite()
        && direct_normal_w_m2 >= 0.0
        && direct_normal_w_m2.is_finite())
    {
        return Err(SkyError::InvalidIrradiance {
            direct_normal_w_m2,
            diffuse_horizontal_w_m2,
        });
    }
    if !(0.0..std::f64::consts::FRAC_PI_2).contains(&sun_zenith) {
        return Err(SkyError::SunBelowHorizon {
            elevation_deg: 90.0 - sun_zenith.to_degrees(),
        });
    }
    let z3 = 1.041 * sun_zenith.powi(3);
    let clearness = ((diffuse_horizontal_w_m2 + direct_normal_w_m2) / diffuse_horizontal_w_m2 + z3)
        / (1.0 + z3);
    let extraterrestrial = SOLAR_CONSTANT_W_M2 * eccentricity_correction(day_of_year);
    let brightness =
        diffuse_horizontal_w_m2 * air_mass_kasten(sun_zenith.to_degrees()) / extraterrestrial;
    Ok((clearness, brightness))
}

impl PerezSky {
    /// The sky for clearness ε, brightness Δ and solar zenith Z (radians), with gendaylit's limits.
    #[must_use]
    pub fn from_indices(clearness: f64, brightness: f64, sun_zenith: f64) -> Self {
        let eps = if clearness.is_nan() {
            1.0
        } else {
            clearness.clamp(1.0, 12.01 - 0.001)
        };
        let mut delta = if brightness.is_nan() {
            0.01
        } else {
            brightness.clamp(0.01, 0.6)
        };
        if eps > 1.065 && eps < 2.8 && delta < 0.2 {
            delta = 0.2;
        }
        let bin = BIN_UPPER_EDGES
            .iter()
            .position(|&edge| eps < edge)
            .unwrap_or(BIN_UPPER_EDGES.len());
        let x = &PEREZ_COEFFICIENTS[bin];
        let z = sun_zenith;
        let lin = |r: &[f64; 4]| r[0] + r[1] * z + delta * (r[2] + r[3] * z);
        let mut coefficients = [lin(&x[0]), lin(&x[1]), lin(&x[2]), lin(&x[3]), lin(&x[4])];
        if bin == 0 {
            coefficients[2] = (delta * (x[2][0] + x[2][1] * z)).powf(x[2][2]).exp() - x[2][3];
            coefficients[3] = -(delta * (x[3][0] + x[3][1] * z)).exp() + x[3][2] + delta * x[3][3];
        }
        Self {
            clearness: eps,
            brightness: delta,
            sun_zenith,
            coefficients,
        }
    }

    /// The sky from direct normal and diffuse horizontal irradiance (W/m²), the solar zenith
    /// (radians) and the day of the year.
    ///
    /// # Errors
    /// As [`clearness_and_brightness`].
    pub fn from_irradiance(
        direct_normal_w_m2: f64,
        diffuse_horizontal_w_m2: f64,
        sun_zenith: f64,
        day_of_year: u32,
    ) -> Result<Self, SkyError> {
        let (eps, delta) = clearness_and_brightness(
            direct_normal_w_m2,
            diffuse_horizontal_w_m2,
            sun_zenith,
            day_of_year,
        )?;
        Ok(Self::from_indices(eps, delta, sun_zenith))
    }

    /// Unnormalised lv(ζ, γ) for cos ζ = `cos_zenith` and angle to the sun `gamma` (radians).
    #[must_use]
    pub fn lv(&self, cos_zenith: f64, gamma: f64) -> f64 {
        let [a, b, c, d, e] = self.coefficients;
        let cos_g = gamma.cos();
        (1.0 + a * (b / cos_zenith.max(0.01)).exp())
            * (1.0 + c * (d * gamma).exp() + e * cos_g * cos_g)
    }

    /// L/L_z: lv at the element over lv at the zenith (whose angle to the sun is Z); 0 below the
    /// horizon.
    #[must_use]
    pub fn relative_luminance(&self, cos_zenith: f64, gamma: f64) -> f64 {
        if cos_zenith <= 0.0 {
            return 0.0;
        }
        self.lv(cos_zenith, gamma) / self.lv(1.0, self.sun_zenith)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficient_table_checksums_match_reference() {
        // lighting.md §1.5: bin 1, x1..x4 of a | b | c | d | e, and the array's last value.
        let bin1 = [
            1.3525, -0.2576, -0.2690, -1.4366, -0.7670, 0.0007, 1.2734, -0.1233, 2.8000, 0.6004,
            1.2375, 1.0000, 1.8734, 0.6297, 0.9738, 0.2809, 0.0356, -0.1246, -0.5718, 0.9938,
        ];
        let flat: Vec<f64> = PEREZ_COEFFICIENTS
            .iter()
            .flatten()
            .flatten()
            .copied()
            .collect();
        assert_eq!(flat.len(), 160);
        for (got, want) in flat.iter().zip(bin1) {
            assert!((got - want).abs() < 1e-12);
        }
        assert!((flat[159] - 0.5636).abs() < 1e-12);
    }

    #[test]
    fn gendaylit_clearness_and_brightness() {
        // Radiance `gendaylit 6 21 12 -a 47 -o -8 -m -15 -W 600 150` reports ε = 4.7065 and
        // Δ = 0.1243 (lighting.md §3.3). Its sun comes from Radiance `sun.c` (day 172, 12:00
        // standard time at 47°N, 8°E, meridian 15°E), reproduced here; the printed 4 decimals
        // bound the check.
        let jd = 172.0_f64;
        let pi = std::f64::consts::PI;
        let declination = 0.4093 * (2.0 * pi * (jd - 81.0) / 368.0).sin();
        let solar_time = 12.0 + 0.170 * (4.0 * pi * (jd - 80.0) / 373.0).sin()
            - 0.129 * (2.0 * pi * (jd - 8.0) / 355.0).sin()
            + 12.0 * (-15.0_f64 - -8.0).to_radians() / pi;
        let lat = 47.0_f64.to_radians();
        let altitude = (lat.sin() * declination.sin()
            - lat.cos() * declination.cos() * (solar_time * pi / 12.0).cos())
        .asin();
        let zenith = pi / 2.0 - altitude;
        let (eps, delta) = clearness_and_brightness(600.0, 150.0, zenith, 172).expect("valid");
        assert!((eps - 4.7065).abs() < 2e-3, "ε = {eps}");
        assert!((delta - 0.1243).abs() < 2e-4, "Δ = {delta}");
    }

    #[test]
    fn clear_sky_is_brighter_near_the_sun_than_opposite() {
        let z = 40.0_f64.to_radians();
        let sky = PerezSky::from_irradiance(800.0, 100.0, z, 172).expect("valid");
        assert!(sky.clearness > 6.2, "bin 8 expected, ε = {}", sky.clearness);
        let near = sky.relative_luminance((z + 0.1).cos(), 0.1);
        let opposite = sky.relative_luminance((z + 0.1).cos(), 2.0 * z + 0.1);
        assert!(near > 5.0 * opposite);
        // Zenith is 1 by construction.
        assert!((sky.relative_luminance(1.0, z) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn bad_irradiance_is_an_error() {
        assert!(PerezSky::from_irradiance(100.0, 0.0, 0.5, 1).is_err());
        assert!(PerezSky::from_irradiance(-1.0, 10.0, 0.5, 1).is_err());
        assert!(PerezSky::from_irradiance(100.0, 10.0, 1.7, 1).is_err());
    }
}
