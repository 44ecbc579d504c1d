//! The CIE 1931 2° standard colorimetric observer and CIE standard illuminant D65
//! (CIE 015:2018 *Colorimetry*, §7; ISO/CIE 11664-1 and -2), the colorimetry of Durisch 1992
//! Appendix A eq. 11–12.
//!
//! Tristimulus values follow CIE 015 §7.1: `X = k Σ S(λ) x̄(λ) Δλ` (and Y, Z alike), summed over
//! the 1 nm table from 360 nm to 830 nm. Functions that take a spectrum sampled at 1 nm use that
//! summation exactly; [`cmf`] and [`d65_relative`] interpolate linearly between table rows (the
//! interpolation CIE 015 prescribes for D65), and [`cmf_band_integral`] integrates the linear
//! interpolant exactly, for band-averaged spectral samples.
//!
//! # Known limitations
//! Only the 2° observer is tabulated (no CIE 1964 10° observer), so colours seen at large visual
//! angles are computed with the 2° functions. Outside 360–830 nm the colour-matching functions
//! are taken as zero, outside 300–830 nm D65 likewise.

use super::cie_tables::{
    CIE1931_2DEG_1NM, CMF_FIRST_NM, CMF_LAST_NM, D65_5NM, D65_FIRST_NM, D65_STEP_NM,
};

/// Maximum luminous efficacy of photopic vision `K_m`, lm/W, for use with the 1931 ȳ = V(λ)
/// table (CIE 015:2018 §7.1: `K_m = 683.002 lm/W`).
pub const MAX_LUMINOUS_EFFICACY_LM_PER_W: f64 = 683.002;

/// The CIE 1931 colour-matching functions `[x̄, ȳ, z̄]` at `wavelength_nm`, linearly interpolated
/// in the 1 nm table; zero outside 360–830 nm.
#[must_use]
pub fn cmf(wavelength_nm: f64) -> [f64; 3] {
    if !(CMF_FIRST_NM..=CMF_LAST_NM).contains(&wavelength_nm) {
        return [0.0; 3];
    }
    let t = wavelength_nm - CMF_FIRST_NM;
    let i = (t.floor() as usize).min(CIE1931_2DEG_1NM.len() - 1);
    let f = t - i as f64;
    let a = CIE1931_2DEG_1NM[i];
    let b = CIE1931_2DEG_1NM[(i + 1).min(CIE1931_2DEG_1NM.len() - 1)];
    [
        a[0] + f * (b[0] - a[0]),
        a[1] + f * (b[1] - a[1]),
        a[2] + f * (b[2] - a[2]),
    ]
}

/// Relative spectral power of illuminant D65 at `wavelength_nm` (S(560 nm) = 100), linearly
/// interpolated in the 5 nm table as CIE 015 prescribes; zero outside 300–830 nm.
#[must_use]
pub fn d65_relative(wavelength_nm: f64) -> f64 {
    let t = (wavelength_nm - D65_FIRST_NM) / D65_STEP_NM;
    let last = (D65_5NM.len() - 1) as f64;
    if !(0.0..=last).contains(&t) {
        return 0.0;
    }
    let i = (t.floor() as usize).min(D65_5NM.len() - 1);
    let f = t - i as f64;
    let a = D65_5NM[i];
    let b = D65_5NM[(i + 1).min(D65_5NM.len() - 1)];
    a + f * (b - a)
}

/// `∫ [x̄, ȳ, z̄] dλ` from `from_nm` to `to_nm` (nm·unit) of the linearly interpolated table.
/// Returns zeros when `to_nm <= from_nm`.
#[must_use]
pub fn cmf_band_integral(from_nm: f64, to_nm: f64) -> [f64; 3] {
    let lo = from_nm.max(CMF_FIRST_NM);
    let hi = to_nm.min(CMF_LAST_NM);
    let mut sum = [0.0; 3];
    if hi <= lo || !lo.is_finite() || !hi.is_finite() {
        return sum;
    }
    // Trapezoids between the band ends and every table knot inside: exact for the interpolant.
    let mut a_nm = lo;
    while a_nm < hi {
        let b_nm = (a_nm.floor() + 1.0).min(hi);
        let (fa, fb) = (cmf(a_nm), cmf(b_nm));
        for c in 0..3 {
            sum[c] += 0.5 * (fa[c] + fb[c]) * (b_nm - a_nm);
        }
        a_nm = b_nm;
    }
    sum
}

/// Unnormalised tristimulus sums `Σ S(λ) [x̄, ȳ, z̄](λ) Δλ` of a spectrum sampled every 1 nm
/// from `first_nm` (an integer wavelength; Δλ = 1 nm). Samples outside 360–830 nm add nothing.
#[must_use]
pub fn tristimulus_sums_1nm(first_nm: f64, samples: &[f64]) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for (k, &s) in samples.iter().enumerate() {
        let w = cmf(first_nm + k as f64);
        for c in 0..3 {
            sum[c] += s * w[c];
        }
    }
    sum
}

/// Photometric quantity (lux, cd/m², lm …) of a radiometric spectrum sampled every 1 nm from
/// `first_nm` in W·nm⁻¹ per unit (W/m²/nm gives lux): `K_m Σ S(λ) V(λ) Δλ` with V = ȳ.
#[must_use]
pub fn photometric_from_spectrum_1nm(first_nm: f64, samples: &[f64]) -> f64 {
    MAX_LUMINOUS_EFFICACY_LM_PER_W * tristimulus_sums_1nm(first_nm, samples)[1]
}

/// Chromaticity `(x, y)` of tristimulus values (Durisch eq. 12). `None` when X + Y + Z is not
/// positive (black or invalid).
#[must_use]
pub fn chromaticity(xyz: [f64; 3]) -> Option<[f64; 2]> {
    let s = xyz[0] + xyz[1] + xyz[2];
    (s > 0.0 && s.is_finite()).then(|| [xyz[0] / s, xyz[1] / s])
}

/// Tristimulus values with luminance `luminance_y` and chromaticity `xy` (`y > 0`).
#[must_use]
pub fn xyz_from_xy(xy: [f64; 2], luminance_y: f64) -> [f64; 3] {
    let [x, y] = xy;
    [
        x / y * luminance_y,
        luminance_y,
        (1.0 - x - y) / y * luminance_y,
    ]
}

/// Tristimulus values of D65 from the tables (1 nm summation, D65 interpolated), normalised to
/// Y = 1.
#[must_use]
pub fn d65_white_xyz() -> [f64; 3] {
    let spd: Vec<f64> = (0..CIE1931_2DEG_1NM.len())
        .map(|k| d65_relative(CMF_FIRST_NM + k as f64))
        .collect();
    let s = tristimulus_sums_1nm(CMF_FIRST_NM, &spd);
    [s[0] / s[1], 1.0, s[2] / s[1]]
}

/// Correlated colour temperature in kelvin from chromaticity by McCamy's cubic (McCamy 1992,
/// *Color Res. Appl.* 17:142): `n = (x − 0.3320)/(0.1858 − y)`,
/// `CCT = 449 n³ + 3525 n² + 6823.3 n + 5520.33`. Stated accuracy: within about 2 K for
/// 2856–6504 K on the Planckian locus; rougher away from it.
#[must_use]
pub fn cct_mccamy_k(xy: [f64; 2]) -> f64 {
    let n = (xy[0] - 0.3320) / (0.1858 - xy[1]);
    ((449.0 * n + 3525.0) * n + 6823.3) * n + 5520.33
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Published D65 chromaticity from the 1 nm tables is (0.31272, 0.32903) (CIE 015:2018
    /// table 3, 1 nm column): five decimals, so half a unit in the last place plus rounding.
    const D65_XY_TOL: f64 = 1e-5;
    /// CIE 015 D65 tristimulus values X = 95.047, Z = 108.883 (Y = 100): three decimals.
    const D65_XYZ_TOL: f64 = 1e-3;
    /// Equal-energy white E has x = y = 1/3 only to the accuracy of the normalisation of the 1931
    /// tables (their sums differ by ~3e-4 relative): 1e-4 in chromaticity.
    const EQUAL_ENERGY_XY_TOL: f64 = 1e-4;
    /// A typing slip changes one table entry; cubic interpolation from the two neighbours on each
    /// side predicts a smooth curve to better than 1.5 % of the local maximum (measured worst
    /// 0.9 %, at the z̄ peak near 445 nm), while a dropped or swapped digit is ≥ 10 %.
    const SMOOTHNESS_TOL: f64 = 0.015;

    #[test]
    fn d65_white_point_from_tables() {
        let xyz = d65_white_xyz();
        let xy = chromaticity(xyz).unwrap();
        assert!((xy[0] - 0.31272).abs() < D65_XY_TOL, "x = {}", xy[0]);
        assert!((xy[1] - 0.32903).abs() < D65_XY_TOL, "y = {}", xy[1]);
        assert!(
            (100.0 * xyz[0] - 95.047).abs() < D65_XYZ_TOL,
            "X = {}",
            xyz[0]
        );
        assert!(
            (100.0 * xyz[2] - 108.883).abs() < D65_XYZ_TOL,
            "Z = {}",
            xyz[2]
        );
    }

    #[test]
    fn equal_energy_sums_are_equal_and_white() {
        let ones = vec![1.0; CIE1931_2DEG_1NM.len()];
        let s = tristimulus_sums_1nm(CMF_FIRST_NM, &ones);
        let xy = chromaticity(s).unwrap();
        assert!((xy[0] - 1.0 / 3.0).abs() < EQUAL_ENERGY_XY_TOL, "{xy:?}");
        assert!((xy[1] - 1.0 / 3.0).abs() < EQUAL_ENERGY_XY_TOL, "{xy:?}");
        // Y of equal energy: ȳ peaks at exactly 1 at 555 nm and its sum is the well-known
        // 106.857 (CIE 015, 1 nm).
        assert!((s[1] - 106.857).abs() < 1e-3, "ΣY = {}", s[1]);
    }

    #[test]
    fn table_knots_and_peaks() {
        // ȳ(555) = 1 is the definition of the photopic peak; D65(560) = 100 is its normalisation.
        assert!((cmf(555.0)[1] - 1.0).abs() < 1e-12);
        assert!((d65_relative(560.0) - 100.0).abs() < 1e-12);
        // Interpolation halfway between two knots.
        let mid = cmf(555.5);
        assert!((mid[1] - 0.5 * (1.0 + 0.9998567)).abs() < 1e-12);
        assert!(
            cmf(359.0)
                .iter()
                .chain(&cmf(831.0))
                .all(|v| v.abs() < 1e-300)
        );
        // D65 at a 1 nm point between knots: the CIE 1 nm table gives 117.49 at 456 nm.
        assert!((d65_relative(456.0) - 117.49).abs() < 1e-3);
    }

    #[test]
    fn tables_are_smooth_no_typing_slips() {
        let n = CIE1931_2DEG_1NM.len();
        for i in 2..n - 2 {
            for c in 0..3 {
                let v = |k: usize| CIE1931_2DEG_1NM[k][c];
                // Cubic through i-2, i-1, i+1, i+2 evaluated at i.
                let predicted = (-v(i - 2) + 4.0 * v(i - 1) + 4.0 * v(i + 1) - v(i + 2)) / 6.0;
                let scale = (i - 2..=i + 2).map(v).fold(0.0_f64, f64::max);
                if scale < 1e-4 {
                    continue;
                }
                let err = (predicted - v(i)).abs() / scale;
                assert!(
                    err < SMOOTHNESS_TOL,
                    "row {} nm channel {c}: {err}",
                    360 + i
                );
            }
        }
    }

    #[test]
    fn band_integral_matches_trapezoid_on_knots() {
        // On integer ends the exact integral of the interpolant is the trapezoid rule.
        let direct = cmf_band_integral(500.0, 510.0);
        let mut trap = [0.0; 3];
        for k in 500..510 {
            let (a, b) = (cmf(f64::from(k)), cmf(f64::from(k + 1)));
            for c in 0..3 {
                trap[c] += 0.5 * (a[c] + b[c]);
            }
        }
        for c in 0..3 {
            assert!((direct[c] - trap[c]).abs() < 1e-12);
        }
        // Splitting a band anywhere adds up.
        let (l, r) = (
            cmf_band_integral(430.0, 487.3),
            cmf_band_integral(487.3, 612.9),
        );
        let whole = cmf_band_integral(430.0, 612.9);
        for c in 0..3 {
            assert!((l[c] + r[c] - whole[c]).abs() < 1e-12);
        }
        assert!(
            cmf_band_integral(600.0, 500.0)
                .iter()
                .all(|v| v.abs() < 1e-300)
        );
    }

    #[test]
    fn mccamy_reproduces_d65_cct() {
        // D65's correlated colour temperature is 6504 K; McCamy's cubic is stated to ±2 K there.
        let xy = chromaticity(d65_white_xyz()).unwrap();
        assert!(
            (cct_mccamy_k(xy) - 6504.0).abs() < 3.0,
            "{}",
            cct_mccamy_k(xy)
        );
    }
}
